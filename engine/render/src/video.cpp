#include "sph2d/render/video.hpp"

#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <stdexcept>

extern char** environ;

namespace sph2d {

std::string findFfmpeg() { return findProgram("ffmpeg"); }

std::string findProgram(const std::string& name) {
  const char* path = std::getenv("PATH");
  if (!path) return "";
  std::stringstream ss(path);
  std::string dir;
  while (std::getline(ss, dir, ':')) {
    if (dir.empty()) dir = ".";
    const std::string p = dir + "/" + name;
    struct stat st;
    if (::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(p.c_str(), X_OK) == 0) return p;
  }
  return "";
}

std::string videoTempPath(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  const std::size_t dot = path.find_last_of('.');
  const std::string tag = ".tmp" + std::to_string(::getpid());
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash) || dot == slash + 1) return path + tag;
  return path.substr(0, dot) + tag + path.substr(dot);
}

VideoPipe::VideoPipe(const std::string& path, int width, int height, double fps)
    : frameBytes_(std::size_t(width) * std::size_t(height) * 4), path_(path) {
  const std::string exe = findFfmpeg();
  if (exe.empty()) throw std::runtime_error("ffmpeg is not installed (not found on PATH)");
  // ffmpeg writes a temporary file, renamed to `path` once it is whole; a device or a FIFO
  // is written in place.
  struct stat st {};
  const bool special = ::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode);
  std::string target = path;
  if (!special) {
    temp_ = videoTempPath(path);
    if (::lstat(temp_.c_str(), &st) == 0)
      throw std::runtime_error("cannot create " + temp_ + ": " + std::strerror(EEXIST));
    target = temp_;
  }
  char size[32], rate[32];
  std::snprintf(size, sizeof size, "%dx%d", width, height);
  std::snprintf(rate, sizeof rate, "%.9g", fps);
  std::vector<std::string> args = {exe,
                                   "-hide_banner",
                                   "-loglevel",
                                   "error",
                                   "-y",
                                   "-f",
                                   "rawvideo",
                                   "-pixel_format",
                                   "rgba",
                                   "-video_size",
                                   size,
                                   "-framerate",
                                   rate,
                                   "-i",
                                   "pipe:0",
                                   "-vf",
                                   "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                                   "-pix_fmt",
                                   "yuv420p",
                                   target};
  for (const auto& a : args) command_ += (command_.empty() ? "" : " ") + a;
  int fds[2];
  if (::pipe(fds) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[0], STDIN_FILENO);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  posix_spawn_file_actions_addclose(&actions, fds[1]);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attr, 0);  // own process group: a terminal Ctrl-C reaches only sph2d
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const int rc = posix_spawnp(&pid_, exe.c_str(), &actions, &attr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  ::close(fds[0]);
  if (rc != 0) {
    ::close(fds[1]);
    pid_ = -1;
    throw std::runtime_error("cannot start " + exe + ": " + std::strerror(rc));
  }
  fd_ = fds[1];
}

VideoPipe::~VideoPipe() {
  try {
    close();
  } catch (...) {
  }
}

void VideoPipe::write(const std::uint8_t* rgba) {
  if (fd_ < 0) throw std::runtime_error("the video pipe to ffmpeg is closed");
  std::size_t done = 0;
  while (done < frameBytes_) {
    const ssize_t n = ::write(fd_, rgba + done, frameBytes_ - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error("ffmpeg stopped reading frames for " + path_ + " (" + std::strerror(errno) + ")");
    }
    done += std::size_t(n);
  }
  ++frames_;
}

void VideoPipe::close() {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
  if (pid_ > 0) {
    int status = 0;
    pid_t r;
    do r = ::waitpid(pid_, &status, 0);
    while (r < 0 && errno == EINTR);
    pid_ = -1;
    if (r < 0) throw std::runtime_error(std::string("waitpid(ffmpeg): ") + std::strerror(errno));
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      if (!temp_.empty()) ::unlink(temp_.c_str());
      throw std::runtime_error("ffmpeg failed writing " + path_ + " (exit status " +
                               std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + "): " + command_);
    }
    if (!temp_.empty() && std::rename(temp_.c_str(), path_.c_str()) != 0) {
      const std::string why = std::strerror(errno);
      ::unlink(temp_.c_str());
      throw std::runtime_error("cannot rename " + temp_ + " to " + path_ + ": " + why);
    }
  }
}

}  // namespace sph2d
