// app/cli.hpp — what the sph2d commands share: usage errors, flag parsing,
// the stage profile table and the stop flag set by SIGINT/SIGTERM.
#pragma once

#include <atomic>
#include <stdexcept>
#include <string>
#include <vector>

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
/// Prints each stage's calls, seconds, ms per call and share.
void printProfile(const World& w);
/// Set by SIGINT/SIGTERM once installStopHandler() ran.
extern std::atomic<bool> stopRequested;
/// Makes SIGINT/SIGTERM set stopRequested instead of killing the process.
void installStopHandler();

/// `sph2d run`.
int cmdRun(const std::vector<std::string>& args);
/// `sph2d info`.
int cmdInfo(const std::vector<std::string>& args);
/// `sph2d bench step`.
int cmdBenchStep(const std::vector<std::string>& args);

}  // namespace sph2d::cli
