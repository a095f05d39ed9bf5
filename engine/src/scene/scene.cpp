// Scene loading: a file's bytes → JSON with positions (json_reader.cpp) → one
// reader per section (scene_sections.hpp) → SceneDef. Every key is checked
// against what is allowed; errors name file, line, column, key path and the
// allowed values (scene_reader.hpp).
//
// Besides types and ranges, the loader refuses what Box2D 2.4.1 would assert
// on (Debian builds it with assertions on: a bad polygon or chain would abort
// the process), what would exhaust memory (particles and boundary samples
// beyond max_particles) and what can only be a mistake (a fluid block holding
// no particle, a degenerate camera, an absurd number of frames): the checks
// of scene_checks.hpp.
#include "sph2d/scene.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "scene/json_reader.hpp"
#include "scene/scene_checks.hpp"
#include "scene/scene_reader.hpp"
#include "scene/scene_sections.hpp"

namespace sph2d {
namespace {

constexpr std::size_t kMaxSceneBytes = 64u << 20;  ///< scene file size

}  // namespace

SceneDef parseScene(const std::string& text, const std::string& file) {
  const JsonDoc doc = parseJsonWithPositions(text, file);
  const Reader r(doc, file);
  const nlohmann::json& root = doc.root;
  r.requireObject(root, "");
  r.checkKeys(root, "",
              {"name", "gravity", "fps", "duration", "max_particles", "solver", "boundaries", "fluid", "periodic",
               "effects", "render", "events", "materials", "groups"});
  SceneDef s;
  s.path = file;
  // In this order: each section may check what it reads against those before it.
  readTopLevel(r, root, s);
  readSolver(r, root, s);
  readRender(r, root, s);     // before the materials: the render's water colours the first
  readMaterials(r, root, s);  // against the solver; before everything that names a material
  readBoundaries(r, root, s);
  readFluid(r, root, s);     // blocks against the spacing and the solids
  readGroups(r, root, s);    // the groups' regions, likewise
  readPeriodic(r, root, s);  // periods against the support radius
  readEffects(r, root, s);
  readEvents(r, root, s);  // the timeline last: against the emitters, effects and gravity
  for (const MaterialDef& m : s.materials)
    if (m.density != s.materials.front().density) {
      const std::string problem = densityContrastProblem(s);
      if (!problem.empty()) r.fail(problem.substr(0, problem.find(' ')), problem);
      break;
    }
  checkParticleBudget(r, s);
  return s;
}

SceneDef loadScene(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw SceneError(path, 0, 0, "", "is a directory, not a scene file");
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    throw SceneError(path, 0, 0, "",
                     std::string("cannot open the scene file") + (err ? std::string(": ") + std::strerror(err) : ""));
  }
  std::string text;
  char buf[65536];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxSceneBytes)
      throw SceneError(path, 0, 0, "",
                       "the file is larger than " + std::to_string(kMaxSceneBytes >> 20) + " MiB; is it a scene file?");
  }
  if (in.bad()) throw SceneError(path, 0, 0, "", "cannot read the scene file");
  return parseScene(text, path);
}

}  // namespace sph2d
