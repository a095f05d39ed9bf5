// app/cli.hpp — command-line helpers the sph2d commands share: usage errors, number
// and list flags, the render flags, and the stop flag set by SIGINT/SIGTERM.
// (The commands themselves are declared in commands.hpp.)
#pragma once

#include <atomic>
#include <stdexcept>
#include <string>
#include <vector>

#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"

namespace sph2d::cli {

/// A command-line mistake: exit code 2 with this message.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A command's arguments read one at a time: the loop every command shares, with its errors
/// ("--x needs a value", "unknown option '--y' (see sph2d CMD --help)"):
///
///     for (ArgReader a(args, "bench step"); a.next();) {
///       if (a.help()) return printHelp();
///       else if (a.is("--steps")) steps = a.intValue(1, 1000000);
///       else a.unknown();
///     }
class ArgReader {
 public:
  /// `command` names the command in the errors ("bench step").
  ArgReader(const std::vector<std::string>& args, std::string command);
  /// Refused: the reader keeps a reference to the arguments, which must outlive it.
  ArgReader(std::vector<std::string>&& args, std::string command) = delete;
  /// Moves to the next argument; false after the last.
  bool next();
  /// The current argument.
  const std::string& arg() const { return args_[i_]; }
  /// True when the current argument is `flag`.
  bool is(const char* flag) const { return arg() == flag; }
  /// True for --help or -h.
  bool help() const { return is("--help") || is("-h"); }
  /// True when the current argument starts with '-' (an option, not a file).
  bool option() const { return !arg().empty() && arg()[0] == '-'; }
  /// The value after the current flag (consumed), or UsageError "<flag> needs a value".
  std::string value();
  /// The value after the current flag when one follows (an argument not starting with "--"),
  /// consumed; else `otherwise` (a flag whose value is optional).
  std::string valueOr(std::string otherwise);
  /// The value as an integer in [lo, hi] (parseInt).
  int intValue(int lo, int hi);
  /// The value as a finite number (parseNumber).
  double numberValue();
  /// The value as a size in bytes (parseBytes).
  double bytesValue();
  /// The value as a comma-separated list of integers in [lo, hi] (parseIntList).
  std::vector<int> intListValue(int lo, int hi);
  /// The value as a comma-separated list (splitList).
  std::vector<std::string> listValue();
  /// Throws UsageError for the current argument as an unknown option.
  [[noreturn]] void unknown() const;
  /// Throws UsageError for the current argument as one too many.
  [[noreturn]] void unexpected() const;

 private:
  const std::vector<std::string>& args_;
  std::string command_, flag_;
  std::size_t i_ = std::size_t(-1);
};

/// Parses an integer flag value in [lo, hi] or throws UsageError naming the flag.
int parseInt(const std::string& flag, const std::string& v, int lo, int hi);
/// Parses a finite number or throws UsageError naming the flag.
double parseNumber(const std::string& flag, const std::string& v);
/// A size in bytes: a number with an optional K, M or G (powers of 1000, "B" allowed:
/// "512M", "1.5GB", "2000000"). Throws UsageError naming `flag`.
double parseBytes(const std::string& flag, const std::string& v);

/// Memory this process may still take [bytes]: MemAvailable of /proc/meminfo, or the
/// cgroup's memory.max less its usage when lower; 0 when neither can be read.
double availableMemoryBytes();

/// The peak a run of `scene` will hold: estimateWorldBytes plus, when rendering, the
/// renderer's context and images (`width` × `height`).
double estimateRunBytes(const SceneDef& scene, bool images);

/// Refuses (UsageError, exit 2) a run whose estimated peak exceeds `limit` bytes
/// (--max-memory), or the memory available when `limit` is 0, before anything is
/// allocated: the message gives the estimate, its parts and the limit.
void checkMemory(const SceneDef& scene, bool images, double limit);
/// Parses a comma-separated list of integers in [lo, hi].
std::vector<int> parseIntList(const std::string& flag, const std::string& v, int lo, int hi);
/// Splits a comma-separated list (empty items dropped).
std::vector<std::string> splitList(const std::string& s);
/// Set by SIGINT/SIGTERM once installStopHandler() ran (and by serve's reset). The commands
/// give it to their World as its stop flag (WorldOptions::stop), so a step stops within
/// milliseconds, not at the end of the frame.
extern std::atomic<bool> stopRequested;
/// Set by SIGINT/SIGTERM alone once installStopHandler() ran.
extern std::atomic<bool> signalReceived;
/// Seconds after SIGINT/SIGTERM at which the process ends with exit 130 whatever it is doing
/// (the watchdog of installStopHandler): the loop normally ends long before, with its files
/// finished; whatever is still being written then is left as it was, and every file the
/// commands write is whole (written under a temporary name and renamed).
constexpr double kStopGraceSeconds = 0.8;
/// Makes SIGINT/SIGTERM set stopRequested and signalReceived instead of killing the process
/// (the loop then stops, the World within its step, and the files are finished). A watchdog
/// thread ends the process with exit 130 kStopGraceSeconds after the signal if it is still
/// running then, and a second signal ends it at once: a signal always ends the process within
/// a second.
void installStopHandler();
/// Makes SIGINT/SIGTERM end the process at once with exit 130 and one line on stderr,
/// even where the parent ignored them (a background job of a script): set-up (reading
/// a scene, sampling a long chain, info's estimates) writes nothing that could be left
/// half done, so it need not finish. main() calls it first.
void installExitHandler();

/// Parses the render flag at the reader's argument (--mode, --color-by, --range, --overlay,
/// --foam-speed, --depth-scale), consuming its value; false when it is not a render flag.
bool parseRenderFlag(ArgReader& a, RenderOptions& o);
/// The help lines of the render flags.
extern const char* kRenderFlagsHelp;

}  // namespace sph2d::cli
