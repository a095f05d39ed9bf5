// app/cli.hpp — what the sph2d commands share: usage errors, flag parsing,
// the stage profile table and the stop flag set by SIGINT/SIGTERM.
#pragma once

#include <atomic>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sph2d/render/renderer.hpp"

namespace sph2d {
class World;
}

namespace sph2d::cli {

/// A command-line mistake: exit code 2 with this message.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Parses an integer flag value in [lo, hi] or throws UsageError naming the flag.
int parseInt(const std::string& flag, const std::string& v, int lo, int hi);
/// Parses a comma-separated list of integers in [lo, hi].
std::vector<int> parseIntList(const std::string& flag, const std::string& v, int lo, int hi);
/// Splits a comma-separated list (empty items dropped).
std::vector<std::string> splitList(const std::string& s);
/// Prints each stage's calls, seconds, ms per call and share.
void printProfile(const World& w);
/// Set by SIGINT/SIGTERM once installStopHandler() ran.
extern std::atomic<bool> stopRequested;
/// Makes SIGINT/SIGTERM set stopRequested instead of killing the process.
void installStopHandler();

/// Parses the render flag at args[i] (--mode, --color-by, --range, --overlay, --foam-speed,
/// --depth-scale), advancing i past its value; false when args[i] is not a render flag.
bool parseRenderFlag(const std::vector<std::string>& args, std::size_t& i, RenderOptions& o);
/// The help lines of the render flags.
extern const char* kRenderFlagsHelp;
/// The render options as recorded in a manifest.
nlohmann::ordered_json renderOptionsJson(const RenderOptions& o);
/// The render options a manifest recorded. Throws UsageError on a malformed entry.
RenderOptions renderOptionsFromJson(const nlohmann::ordered_json& j);
/// XXH64 of a file's bytes as 16 hex digits. Throws UsageError when it cannot be read.
std::string fileHash(const std::string& path);
/// The llvmpipe environment as recorded in a manifest (pins it first).
nlohmann::ordered_json environmentJson();

/// `sph2d run`.
int cmdRun(const std::vector<std::string>& args);
/// `sph2d check`.
int cmdCheck(const std::vector<std::string>& args);
/// `sph2d render`.
int cmdRender(const std::vector<std::string>& args);
/// `sph2d bench`.
int cmdBench(const std::vector<std::string>& args);
/// `sph2d info`.
int cmdInfo(const std::vector<std::string>& args);
/// `sph2d bench step`.
int cmdBenchStep(const std::vector<std::string>& args);
/// `sph2d bench accuracy`.
int cmdBenchAccuracy(const std::vector<std::string>& args);
/// `sph2d bench effects`.
int cmdBenchEffects(const std::vector<std::string>& args);

}  // namespace sph2d::cli
