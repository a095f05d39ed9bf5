// sph2d/render/particle_export.hpp — particles of one frame as CSV or legacy VTK.
//
// Design: a ParticleSnapshot is a copy, in id order and world coordinates, of
// what an export needs (id, position, velocity, density, pressure, optional age);
// taking it is cheap enough for the frame loop, and writing it happens on the
// FrameWriter's thread. Files are written whole or not at all (temporary name,
// then rename). VTK is the legacy "vtk DataFile Version 3.0" POLYDATA format
// that ParaView and VisIt open: POINTS (double, world coordinates), one VERTEX
// cell per particle, and POINT_DATA arrays id, velocity, density, pressure,
// age, material, color and group (each of the last four only when the World has it: ages, more
// than one material, particles' own colours, particle groups); binary files are big-endian, as the format
// requires. readParticlesCsv() reads our own CSV back, so frames can be re-rendered without re-simulating.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sph2d/math.hpp"
#include "sph2d/surface.hpp"

namespace sph2d {

class World;

/// One frame's particles, sorted by id, positions in world coordinates.
/// A kinematic or dynamic Box2D body in a snapshot (world coordinates).
struct BodySnapshot {
  int body = 0;  ///< its index among all bodies of the b2World in creation order (a scene's: boundaries[] index)
  double x = 0, y = 0, angle = 0;    ///< the body origin [m] and angle [rad]
  double vx = 0, vy = 0, omega = 0;  ///< velocity of its origin [m/s] (of x, y), angular velocity [rad/s]
};

struct ParticleSnapshot {
  std::uint64_t frame = 0;              ///< frames stepped
  double time = 0;                      ///< simulated time [s]
  std::vector<std::uint32_t> id;        ///< stable ids, ascending
  std::vector<double> x, y;             ///< world position [m]
  std::vector<float> vx, vy;            ///< velocity [m/s]
  std::vector<float> rho, p;            ///< density [kg/m³], pressure [Pa]
  std::vector<float> age;               ///< age [s]; empty when the particles have no age
  std::vector<std::uint32_t> material;  ///< material index (World::materials()); empty with one material
  std::vector<std::uint32_t> color;     ///< each particle's own colour 0xRRGGBB (0: none); empty when none has one
  std::vector<std::uint32_t> group;     ///< 1 + its particle group's index (0: none); empty without groups
  std::vector<BodySnapshot> bodies;     ///< the non-static bodies, in creation (scene) order
  /// The fluid's outlines (World::surfaceCurves), taken for an export in format Surface only.
  std::vector<SurfaceCurve> surface;
  /// Number of particles.
  std::size_t size() const { return id.size(); }
};

/// Copies the particles of `world` (and `age`, one per slot, when given) in id order.
ParticleSnapshot snapshotOf(const World& world, const Real* age = nullptr);

/// File formats of particle exports.
/// Surface: the fluid's outlines of the frame, as JSON (encodeSurfaceJson) and SVG (encodeSurfaceSvg).
enum class ExportFormat { Csv, VtkBinary, VtkAscii, Surface };

/// Parses "csv", "vtk" (binary), "vtk-ascii" or "surface"; false for anything else.
bool parseExportFormat(const std::string& s, ExportFormat& out);
/// File extension without the dot: "csv", "vtk" or (surface) "json".
std::string exportExtension(ExportFormat f);

/// Writes the bodies of `s` as CSV (`body,x,y,angle,vx,vy,omega`, one row per non-static body)
/// to `path`, atomically. Throws std::runtime_error naming the path.
void writeBodiesCsvAtomic(const std::string& path, const ParticleSnapshot& s);

/// Writes `s` to `path` in format `f`, atomically. Throws std::runtime_error naming the path.
void writeParticlesAtomic(const std::string& path, const ParticleSnapshot& s, ExportFormat f);
/// The bytes writeParticlesAtomic writes (for Surface: encodeSurfaceJson).
std::string encodeParticles(const ParticleSnapshot& s, ExportFormat f);
/// The outlines of `s` as JSON: {"format": "sph2d-surface", "frame", "time", "curves": [{"area",
/// "hole", "points": [[x, y], ...]}, ...]}, world coordinates in metres, each curve closed (its
/// last point joins its first), the fluid on its left (holes clockwise, negative area).
std::string encodeSurfaceJson(const ParticleSnapshot& s);
/// The outlines of `s` as an SVG drawing (world coordinates, y up, one path, even-odd fill so
/// that holes stay open), framed on the curves with a margin.
std::string encodeSurfaceSvg(const ParticleSnapshot& s);
/// The bytes writeBodiesCsvAtomic writes.
std::string encodeBodiesCsv(const ParticleSnapshot& s);

/// Reads a CSV written by writeParticlesAtomic. Throws std::runtime_error with the line.
ParticleSnapshot readParticlesCsv(const std::string& path);

/// The temporary name a file is written under before its rename: PATH.tmpPID.
std::string tempPathFor(const std::string& path);

/// Writes `bytes` to `path` through a temporary file (tempPathFor(path), created new: an
/// existing file or link of that name is refused) and a rename. A device or FIFO at `path`
/// is written in place. Throws std::runtime_error.
void writeFileAtomic(const std::string& path, const std::string& bytes);

}  // namespace sph2d
