// `sph2d render`: re-render particles exported by `sph2d run --export csv` with the
// scene's camera, solids and colours, without simulating again.
#include <cmath>
#include <cstdio>

#include "cli.hpp"
#include "commands.hpp"
#include "sph2d/render/particle_export.hpp"
#include "sph2d/render/png_io.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace sph2d::cli {
namespace {

const char* kRenderHelp =
    "Usage: sph2d render SCENE.json --particles FRAME.csv --out IMAGE.png [render flags]\n"
    "\n"
    "Draws the particles of FRAME.csv (written by `sph2d run --export csv`) with SCENE's\n"
    "camera, solids, size and colours into IMAGE.png. Useful to try another mode, colour\n"
    "field or palette on frames already simulated.\n"
    "\n"
    "Render flags:\n";

}  // namespace

int cmdRender(const std::vector<std::string>& args) {
  std::string scenePath, csv, out;
  RenderOptions opt;
  for (ArgReader in(args, "render"); in.next();) {
    const std::string s = in.arg();
    if (in.help()) {
      std::fputs(kRenderHelp, stdout);
      std::fputs(kRenderFlagsHelp, stdout);
      return 0;
    }
    if (parseRenderFlag(in, opt)) continue;
    if (in.is("--particles"))
      csv = in.value();
    else if (in.is("--out"))
      out = in.value();
    else if (in.option())
      in.unknown();
    else if (scenePath.empty())
      scenePath = s;
    else
      in.unexpected();
  }
  if (scenePath.empty() || csv.empty() || out.empty())
    throw UsageError("sph2d render needs SCENE.json, --particles FRAME.csv and --out IMAGE.png");
  const SceneDef scene = loadScene(scenePath);
  ParticleSnapshot snap;
  try {
    snap = readParticlesCsv(csv);
  } catch (const std::exception& e) {
    throw UsageError(e.what());
  }
  World world(scene, WorldOptions{1});  // for its solids, spacing and local origin
  world.takeWarnings();
  const Vec2d o = world.origin();
  ParticleBuffer B;
  for (std::size_t k = 0; k < snap.size(); ++k) {
    B.push(Vec2(Real(snap.x[k] - o.x()), Real(snap.y[k] - o.y())), Vec2(snap.vx[k], snap.vy[k]), snap.id[k],
           snap.rho[k]);
    B.p.back() = snap.p[k];
  }
  if (!snap.material.empty())
    B.material = snap.material;  // the scene's materials colour them (an index
                                 // it has not is drawn in the fluid's colour)
  B.color = snap.color;          // the particles' own colours, and their groups (drawn as blobs)
  B.group = snap.group;
  const Particles P = B.view();
  if (opt.colorBy == ColorField::Age && snap.age.empty() &&
      (opt.mode == "particles" || (opt.mode.empty() && scene.render.mode == "particles")))
    throw UsageError(csv + " has no age column, so --color-by age cannot be shown");
  RenderInput in;
  in.particles = P;
  in.origin = o;
  in.spacing = world.spacing();
  in.colliders = &world.colliders();
  in.age = snap.age.empty() ? nullptr : snap.age.data();
  in.materialColors = materialColors(world);
  in.materialGranular = materialGranular(world);
  in.materialTransmission = materialTransmission(world);
  in.gravity = scene.gravity.norm();
  in.frame = snap.frame;
  in.time = snap.time;
  Renderer renderer(scene.render, opt);
  const Frame& fr = renderer.render(in);
  writePngAtomic(out, fr.width, fr.height, fr.rgba.data(), 1);
  std::printf("sph2d: %zu particles of frame %llu drawn into %s (%dx%d, %s mode)\n", snap.size(),
              static_cast<unsigned long long>(snap.frame), out.c_str(), fr.width, fr.height, renderer.mode().c_str());
  return 0;
}

}  // namespace sph2d::cli
