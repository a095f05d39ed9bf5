// app/run/run_args.hpp — the command line of `sph2d run`: its options and its help text.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "sph2d/render/particle_export.hpp"
#include "sph2d/render/renderer.hpp"

namespace sph2d::cli {

/// The options of one `sph2d run`.
struct RunArgs {
  std::string scene;                         ///< the scene file
  std::string out;                           ///< --out ("" : out/<scene name>)
  std::string video;                         ///< --video FILE ("" : none)
  int frames = -1;                           ///< --frames (−1: the scene's duration × fps)
  int threads = 0;                           ///< --threads (0: all cores)
  int every = 1;                             ///< --every
  int pngLevel = 1;                          ///< --png-level
  double maxMemory = 0;                      ///< --max-memory [bytes] (0: the memory available)
  std::optional<ExportFormat> exportFormat;  ///< --export
  RenderOptions render;                      ///< the render flags
  bool images = true;                        ///< false with --no-images
  bool stateHash = false;                    ///< --state-hash
  bool profile = false;                      ///< --profile
  bool quiet = false;                        ///< --quiet
  bool realtime = false;                     ///< --realtime
  int catchUp = 4;                           ///< --catch-up
  std::vector<std::string> inputs;           ///< --input: events files, "-" for standard input
  std::string record;                        ///< --record FILE ("" : none)
  std::size_t maxEventParticles = 0;         ///< --max-event-particles (0: the scene's default)
  std::size_t maxParticlesPerSecond = 0;     ///< --max-particles-per-second (0: the scene's default)
  std::size_t maxParticles = 0;              ///< --max-particles (0: the scene's default)
};

/// True when `args` asks for help (--help or -h anywhere).
bool wantsRunHelp(const std::vector<std::string>& args);
/// Prints `sph2d run --help`.
void printRunHelp();
/// Parses the arguments after `run`. Throws UsageError naming the flag and what it allows.
RunArgs parseRunArgs(const std::vector<std::string>& args);

}  // namespace sph2d::cli
