// app_runner.hpp — runs the sph2d executable for the app tests and captures
// its exit code and output (stdout and stderr, interleaved).
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace sph2d::apptest {

/// Exit code (-1 when killed by a signal) and everything the command printed.
struct Result {
  int code;
  std::string out;
};

/// Per-process scratch directory under the test build tree (CTest runs test cases in parallel processes).
inline std::string scratch(const std::string& name) {
  const std::string dir = std::string(SPH2D_TEST_TMP) + "/" + name + "_" + std::to_string(::getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// Runs a shell command line, capturing its exit code and output.
inline Result runShell(const std::string& command) {
  static int calls = 0;
  std::filesystem::create_directories(SPH2D_TEST_TMP);
  const std::string log =
      std::string(SPH2D_TEST_TMP) + "/cmd_" + std::to_string(::getpid()) + "_" + std::to_string(++calls) + ".log";
  const int status = std::system(("{ " + command + " ; } > \"" + log + "\" 2>&1").c_str());
  std::ifstream in(log);
  std::stringstream ss;
  ss << in.rdbuf();
  in.close();
  std::filesystem::remove(log);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ss.str()};
}

/// Runs `prefix sph2d args` (prefix: environment assignments or a wrapper).
inline Result runSph2d(const std::string& args, const std::string& prefix = "") {
  return runShell(prefix + " \"" + SPH2D_EXE + "\" " + args);
}

/// Starts `sph2d args` as a child process without a shell, its stdout and stderr into
/// `log`; with `ignoreSigint` the child starts with SIGINT ignored, as a background job
/// of a script does. Returns the pid (the caller signals and waits for it).
inline pid_t spawnSph2d(const std::vector<std::string>& args, const std::string& log, bool ignoreSigint = false) {
  const pid_t pid = fork();
  if (pid != 0) return pid;
  const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  ::dup2(fd, 1);
  ::dup2(fd, 2);
  if (ignoreSigint) signal(SIGINT, SIG_IGN);
  std::vector<char*> argv{const_cast<char*>(SPH2D_EXE)};
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  execv(SPH2D_EXE, argv.data());
  _exit(127);
}

/// Shell-quotes a path (single quotes).
inline std::string q(const std::string& s) {
  std::string o = "'";
  for (char c : s) o += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return o + "'";
}

/// Absolute path of a file under assets/.
inline std::string asset(const std::string& rel) { return std::string(SPH2D_ASSETS) + "/" + rel; }

}  // namespace sph2d::apptest
