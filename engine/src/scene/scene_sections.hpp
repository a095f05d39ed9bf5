// scene_sections.hpp (internal) — one reader per section of a scene file, each
// filling its part of a SceneDef from the top-level object `root`, listed in
// the order parseScene (scene.cpp) calls them. A reader whose key is absent
// leaves the defaults (readSolver still fills the solver's own parameters);
// the later ones check what they read against the earlier sections (blocks
// against the spacing and the solids, periods against the support radius,
// events against the emitters, effects and gravity). All fail through the
// Reader with the position of the offending key.
#pragma once

#include <nlohmann/json.hpp>

#include "scene/scene_reader.hpp"
#include "sph2d/scene.hpp"

namespace sph2d {

/// The top-level values: name, gravity, fps, duration, max_particles.
void readTopLevel(const Reader& r, const nlohmann::json& root, SceneDef& s);

/// `solver`: the solver type (or quality preset), the shared keys, and every
/// parameter the solver declares (solverParams), with its default when absent.
void readSolver(const Reader& r, const nlohmann::json& root, SceneDef& s);

/// `materials`: the scene's materials (materialProblem's rule for each); the first is the
/// solver's fluid, whose density and viscosity become the solver's rest density and viscosity.
void readMaterials(const Reader& r, const nlohmann::json& root, SceneDef& s);

/// `j`'s "material" key as an index in sceneMaterials(s) (0 when absent); fails naming them.
std::uint32_t readMaterialName(const Reader& r, const nlohmann::json& j, const std::string& path, const SceneDef& s);

/// `boundaries`: static bodies and their fixtures (box, polygon, circle, edge, chain).
void readBoundaries(const Reader& r, const nlohmann::json& root, SceneDef& s);

/// `fluid`: blocks of fluid with their velocities and velocity fields; each must
/// hold a particle at the solver's spacing outside the solids read before.
void readFluid(const Reader& r, const nlohmann::json& root, SceneDef& s);
/// `groups`: regions (as `fluid` blocks) made into rigid or elastic particle groups.
void readGroups(const Reader& r, const nlohmann::json& root, SceneDef& s);

/// `periodic`: the wrapping axes and their ranges (at least 3 support radii long).
void readPeriodic(const Reader& r, const nlohmann::json& root, SceneDef& s);

/// `effects`: shifting, XSPH, force fields, surface tension, lifetime, sinks,
/// emitters and the particle budget.
void readEffects(const Reader& r, const nlohmann::json& root, SceneDef& s);

/// `render`: image size, mode, colours, splat radius and camera.
void readRender(const Reader& r, const nlohmann::json& root, SceneDef& s);

/// `events`: the timeline, each entry read as parseEvent reads one event (a stamp
/// required, no "source"). Defined in events.cpp, with the event reader it uses.
void readEvents(const Reader& r, const nlohmann::json& root, SceneDef& s);

}  // namespace sph2d
