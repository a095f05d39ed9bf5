// `sph2d bench render`: per-stage milliseconds of the renderer and the PNG encoder
// on a synthetic dam-break tank. A benchmark, not a test.
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "cli.hpp"
#include "commands.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/render/frame_writer.hpp"
#include "sph2d/render/png_io.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/surface.hpp"
#include "sph2d/world.hpp"

namespace fs = std::filesystem;

namespace sph2d::cli {
namespace {

const char* kBenchHelp =
    "Usage: sph2d bench render [--particles N] [--size WxH] [--frames K] [--png-level L] [--save FILE] [render flags]\n"
    "\n"
    "Renders K frames (default 30) of N particles (default 20000: a collapsing water\n"
    "column in the dam-break tank) at WxH (default 960x540) and prints the mean and\n"
    "best milliseconds of each stage: upload (CPU packing, depth grid), splat,\n"
    "composite, solids, readback, overlay, PNG encode (level L, default 1) and write\n"
    "(a new file each frame, as `sph2d run` writes them), hash, the coders alone\n"
    "(level L's, libdeflate level 1, zlib through libpng) and the fluid's outline as\n"
    "curves (World::surfaceCurves' work, one thread).\n"
    "Stages are timed with glFinish between them; the 'render, no sync' row is the\n"
    "same frame without those fences, as `sph2d run` renders it; 'render | PNG' renders\n"
    "K more frames as `sph2d run` does, each PNG written on the frame writer's thread\n"
    "while the next frame renders (wall time per frame, first render to last file).\n"
    "In liquid mode the 'opaque water' rows render the same frames, alternately, with\n"
    "render.transmission 0 (nothing seen through the water): what the see-through costs;\n"
    "the 'splat (gl)' and 'splat (cpu)' rows render them, alike, with the liquid's field\n"
    "summed by the path not chosen (--splat): what the choice saves. The CPU rows are the\n"
    "process's CPU time (every thread: llvmpipe's too) per frame, which other processes\n"
    "on a shared machine disturb less than wall time. --save writes the frame.\n"
    "\n"
    "Render flags:\n";

struct Stat {
  std::vector<double> v;
  double mean() const {
    double s = 0;
    for (double x : v) s += x;
    return v.empty() ? 0 : s / double(v.size());
  }
  double best() const { return v.empty() ? 0 : *std::min_element(v.begin(), v.end()); }
};

/// CPU time of the whole process (all threads) [ms].
double processCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

}  // namespace

int cmdBench(const std::vector<std::string>& args) {
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    std::fputs(kBenchHelp, stdout);
    std::fputs(kRenderFlagsHelp, stdout);
    return args.empty() ? 2 : 0;
  }
  if (args[0] != "render")
    throw UsageError(
        "unknown benchmark '" + args[0] +
        "'; benchmarks: step, render, accuracy, effects (see sph2d bench step|render|accuracy|effects --help)");
  int particles = 20000, width = 960, height = 540, frames = 30, level = 1;
  std::string save;
  RenderOptions opt;
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  for (ArgReader in(rest, "bench"); in.next();) {
    if (in.help()) {
      std::fputs(kBenchHelp, stdout);
      std::fputs(kRenderFlagsHelp, stdout);
      return 0;
    }
    if (parseRenderFlag(in, opt)) continue;
    if (in.is("--particles"))
      particles = in.intValue(1, 4000000);
    else if (in.is("--frames"))
      frames = in.intValue(1, 100000);
    else if (in.is("--png-level"))
      level = in.intValue(0, 9);
    else if (in.is("--save"))
      save = in.value();
    else if (in.is("--size")) {
      const std::string v = in.value();
      const auto x = v.find('x');
      if (x == std::string::npos) throw UsageError("--size expects WxH, got '" + v + "'");
      width = parseInt("--size", v.substr(0, x), 16, 8192);
      height = parseInt("--size", v.substr(x + 1), 16, 8192);
    } else
      in.unknown();
  }

  // The dam-break tank (4 m × 3 m) and, on a square lattice, about N particles under a
  // collapsing-column profile h(x) = 1.2 (1 − x/3)^1.5 + 0.12 with a surge speed along x.
  auto profile = [](double x) { return 1.2 * std::pow(std::max(0.0, 1.0 - x / 3.0), 1.5) + 0.12; };
  const double area = 1.2 * 3.0 / 2.5 + 0.12 * 3.0;
  const double dx = std::sqrt(area / particles);
  SceneDef scene;
  scene.name = "bench";
  scene.solver = solverDefaults("muller2003");  // the step this benchmark has always timed
  scene.solver.spacing = dx;
  BodyDef tank;
  auto box = [](double cx, double cy, double hx, double hy) {
    ShapeDef s;
    s.type = ShapeDef::Type::Box;
    s.center = Vec2d(cx, cy);
    s.halfSize = Vec2d(hx, hy);
    return s;
  };
  tank.fixtures = {box(2.0, -0.1, 2.2, 0.1), box(-0.1, 1.5, 0.1, 1.7), box(4.1, 1.5, 0.1, 1.7),
                   box(2.0, 3.1, 2.2, 0.1)};
  scene.bodies.push_back(tank);
  scene.render.width = width;
  scene.render.height = height;
  scene.render.camera.automatic = false;
  scene.render.camera.min = Vec2d(-0.25, -0.25);
  scene.render.camera.max = Vec2d(4.25, 3.25);
  World world(scene, WorldOptions{1});
  world.takeWarnings();
  ParticleBuffer B;
  const Vec2d o = world.origin();
  std::uint32_t id = 0;
  for (double x = dx / 2; x < 3.0; x += dx)
    for (double y = dx / 2; y < profile(x); y += dx) {
      const double speed = 1.0 + 2.0 * x + 1.5 * y;
      B.push(Vec2(Real(x - o.x()), Real(y - o.y())), Vec2(Real(speed), Real(-0.3 * y)), id++, Real(1000));
    }
  const Particles P = B.view();
  RenderInput in;
  in.particles = P;
  in.origin = o;
  in.spacing = world.spacing();
  in.colliders = &world.colliders();
  in.gravity = 9.81;

  const std::string tmp = (fs::temp_directory_path() / ("sph2d-bench-" + std::to_string(::getpid()))).string();
  fs::create_directories(tmp);
  opt.profile = true;
  Renderer profiled(scene.render, opt);
  // The liquid's water without what is behind it (opaque: no backdrop sampled or mixed in), the
  // same frames in the same run: what seeing through the water costs.
  RenderDef opaqueDef = scene.render;
  opaqueDef.transmission = {0, 0, 0};
  opaqueDef.refraction = 0;
  const bool liquid = profiled.mode() == "liquid";
  std::optional<Renderer> opaqueProfiled;
  if (liquid) opaqueProfiled.emplace(opaqueDef, opt);
  Stat opaqueComposite, opaqueNosync;
  // The liquid's splat by the other path (CPU sums or GL point sprites, RenderOptions::splat),
  // the same frames in the same run: what the path chosen saves.
  RenderOptions otherOpt = opt;
  const std::string splatPath = profiled.splatPath();
  otherOpt.splat = splatPath == "cpu" ? SplatPath::Gl : SplatPath::Cpu;
  std::optional<Renderer> otherProfiled;
  if (liquid) otherProfiled.emplace(scene.render, otherOpt);
  const std::string otherPath = otherProfiled ? otherProfiled->splatPath() : std::string();
  Stat otherSplat, otherNosync;
  std::printf("bench render: %zu particles, %dx%d, %s mode, %d frames, PNG level %d\nrenderer: %s\n", P.size(), width,
              height, profiled.mode().c_str(), frames, level, profiled.rendererString().c_str());
  Stat upload, splat, composite, solids, readback, overlay, png, hash, total, nosync, pngBytes, cpuRender, cpuPng;
  Stat pipelined, cpuPipelined;  // render here, PNG on the writer's thread (one value: the run's mean)
  // Level L's coder against libdeflate level 1 and zlib (libpng) with level L's filter.
  Stat encodeOwn, encodeLibdeflate, encodeZlib, bytesOwn, bytesLibdeflate, bytesZlib;
  {
    const Frame& first = profiled.render(in);  // warm-up: shader compilation, first-use costs
    if (!save.empty()) writePngAtomic(save, first.width, first.height, first.rgba.data(), level);
    if (opaqueProfiled) opaqueProfiled->render(in);
    if (otherProfiled) otherProfiled->render(in);
  }
  // A comparison renderer (opaque water, the other splat path), when it exists, renders the
  // frame too and records one of its stages.
  auto alongside = [&](std::optional<Renderer>& r, Stat& s, double RenderTimings::*stage) {
    if (!r) return;
    r->render(in);
    s.v.push_back(r->lastTimings().*stage);
  };
  for (int k = 0; k < frames; ++k) {
    alongside(opaqueProfiled, opaqueComposite, &RenderTimings::composite);
    alongside(otherProfiled, otherSplat, &RenderTimings::splat);
    const Frame& fr = profiled.render(in);
    const RenderTimings t = profiled.lastTimings();
    upload.v.push_back(t.upload);
    splat.v.push_back(t.splat);
    composite.v.push_back(t.composite);
    solids.v.push_back(t.solids);
    readback.v.push_back(t.readback);
    overlay.v.push_back(t.overlay);
    total.v.push_back(t.total);
    auto t0 = std::chrono::steady_clock::now();
    volatile std::uint64_t h = xxh64(fr.rgba.data(), fr.rgba.size());
    (void)h;
    hash.v.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    // A new name per frame, as `sph2d run` writes them (renaming over the last frame's file
    // costs ext4 about 0.3 ms more: the old file's blocks freed).
    char name[32];
    std::snprintf(name, sizeof name, "/frame_%05d.png", k);
    const std::string path = tmp + name;
    t0 = std::chrono::steady_clock::now();
    const double c0 = processCpuMs();
    writePngAtomic(path, fr.width, fr.height, fr.rgba.data(), level);
    cpuPng.v.push_back(processCpuMs() - c0);
    png.v.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    pngBytes.v.push_back(double(fs::file_size(path)));
    // Encoding alone (no file), this level's coder and then zlib through libpng.
    thread_local std::vector<std::uint8_t> encoded;
    PngSettings settings = pngSettings(level);
    t0 = std::chrono::steady_clock::now();
    encodePng(fr.width, fr.height, fr.rgba.data(), settings, encoded);
    encodeOwn.v.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    bytesOwn.v.push_back(double(encoded.size()));
    // libdeflate at level 1 (filter NONE): the default coder before the run coder.
    PngSettings libdeflate = settings;
    libdeflate.deflater = PngSettings::Deflater::Libdeflate;
    libdeflate.level = 1;
    t0 = std::chrono::steady_clock::now();
    encodePng(fr.width, fr.height, fr.rgba.data(), libdeflate, encoded);
    encodeLibdeflate.v.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    bytesLibdeflate.v.push_back(double(encoded.size()));
    settings.deflater = PngSettings::Deflater::Zlib;
    t0 = std::chrono::steady_clock::now();
    encodePng(fr.width, fr.height, fr.rgba.data(), settings, encoded);
    encodeZlib.v.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    bytesZlib.v.push_back(double(encoded.size()));
  }
  opt.profile = false;
  otherOpt.profile = false;
  {
    Renderer plain(scene.render, opt);
    plain.render(in);
    std::optional<Renderer> opaque, other;
    if (liquid) {
      opaque.emplace(opaqueDef, opt);
      opaque->render(in);
      other.emplace(scene.render, otherOpt);
      other->render(in);
    }
    for (int k = 0; k < frames; ++k) {
      const double c0 = processCpuMs();
      plain.render(in);
      cpuRender.v.push_back(processCpuMs() - c0);
      nosync.v.push_back(plain.lastTimings().total);
      alongside(opaque, opaqueNosync, &RenderTimings::total);
      alongside(other, otherNosync, &RenderTimings::total);
    }
    // As `sph2d run` and the demo draw: the PNG on the FrameWriter's thread (its bounded
    // queue) while this thread renders the next frame. Wall time from the first render to
    // the last file written, per frame: the frame pipeline's throughput on two cores.
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = processCpuMs();
    {
      FrameWriter writer(tmp, level);
      for (int k = 0; k < frames; ++k) {
        const Frame& fr = plain.render(in);
        writer.push(frames + k, fr.width, fr.height, fr.rgba);
      }
      writer.finish();
    }
    pipelined.v.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() /
                          frames);
    cpuPipelined.v.push_back((processCpuMs() - c0) / frames);
  }
  fs::remove_all(tmp);
  // The fluid's outline as curves (sph2d/surface.hpp), on this thread alone: what a game pays
  // for World::surfaceCurves without the renderer.
  Stat surface;
  std::size_t curves = 0;
  {
    std::vector<Vec2d> points;
    points.reserve(P.size());
    for (std::size_t i = 0; i < P.size(); ++i) points.push_back(o + P.x[i].cast<double>());
    for (int k = 0; k < frames; ++k) {
      const auto t0 = std::chrono::steady_clock::now();
      curves = surfaceCurves(points, double(world.spacing())).size();
      surface.v.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
  }
  std::printf("%-22s %9s %9s\n", "stage", "mean ms", "best ms");
  auto row = [](const char* name, const Stat& s) { std::printf("%-22s %9.2f %9.2f\n", name, s.mean(), s.best()); };
  row("upload (CPU, grid)", upload);
  const std::string splatRow = "splat (" + splatPath + ")", otherRow = "splat (" + otherPath + ")";
  row(liquid ? splatRow.c_str() : "discs", splat);
  if (liquid) row(otherRow.c_str(), otherSplat);
  if (liquid) row("composite", composite);
  if (liquid) row("composite, opaque water", opaqueComposite);
  row("solids", solids);
  row("readback", readback);
  row("overlay (CPU)", overlay);
  row("render, synced", total);
  row("render, no sync", nosync);
  if (liquid) row("same, opaque water", opaqueNosync);
  const std::string otherSame = "same, splat (" + otherPath + ")";
  if (liquid) row(otherSame.c_str(), otherNosync);
  row("PNG encode", png);
  row("XXH64 of pixels", hash);
  row("PNG, coder only", encodeOwn);
  row("PNG, libdeflate 1", encodeLibdeflate);
  row("PNG, zlib (libpng)", encodeZlib);
  Stat sum;
  for (std::size_t k = 0; k < nosync.v.size(); ++k) sum.v.push_back(nosync.v[k] + png.v[k]);
  row("render + PNG", sum);
  row("render | PNG, threaded", pipelined);
  Stat cpuSum;
  for (std::size_t k = 0; k < cpuRender.v.size(); ++k) cpuSum.v.push_back(cpuRender.v[k] + cpuPng.v[k]);
  row("CPU: render, no sync", cpuRender);
  row("CPU: PNG encode", cpuPng);
  row("CPU: render + PNG", cpuSum);
  row("CPU: render | PNG", cpuPipelined);
  row("surface curves (CPU)", surface);
  std::printf("surface: %zu curves\n", curves);
  const PngSettings::Deflater coder = pngSettings(level).deflater;
  std::printf(
      "PNG level %d: %s, %.0f KB; libdeflate level 1 %.0f KB, %.2fx the coder's time; zlib through libpng with its "
      "settings %.0f KB, %.2fx\n",
      level,
      coder == PngSettings::Deflater::Runs         ? "run coder"
      : coder == PngSettings::Deflater::Libdeflate ? "libdeflate"
                                                   : "zlib",
      bytesOwn.mean() / 1024.0, bytesLibdeflate.mean() / 1024.0,
      encodeLibdeflate.mean() / std::max(encodeOwn.mean(), 1e-9), bytesZlib.mean() / 1024.0,
      encodeZlib.mean() / std::max(encodeOwn.mean(), 1e-9));
  std::printf("PNG size %.0f KB; sprites as %s\n", pngBytes.mean() / 1024.0,
              profiled.usedQuads() ? "instanced quads" : "points");
  return 0;
}

}  // namespace sph2d::cli
