// sph2d/render/video.hpp — frames piped to an ffmpeg child process.
//
// Design: ffmpeg is found on PATH (never installed by sph2d) and started with
// posix_spawnp, its standard input a pipe that receives raw RGBA frames. The
// child gets its own process group, so a Ctrl-C in the terminal reaches only
// sph2d, which then closes the pipe: ffmpeg sees the end of its input and
// finishes the file properly. Writes retry on EINTR; a closed pipe (EPIPE, with
// SIGPIPE ignored by the caller) is an error naming ffmpeg. The video is written to a
// temporary name and renamed when ffmpeg has finished it, so it is whole or absent.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <string>
#include <vector>

namespace sph2d {

/// The first executable regular file named `name` in PATH's folders, or "" when there is none.
std::string findProgram(const std::string& name);
/// The path of `ffmpeg` on PATH, or "" when it is not installed.
std::string findFfmpeg();

/// The temporary file ffmpeg writes before the video is renamed to `path`: the name with
/// ".tmpPID" before its extension (out.mp4 -> out.tmp1234.mp4: ffmpeg picks the container by it).
std::string videoTempPath(const std::string& path);

/// An ffmpeg process encoding the RGBA frames written to it into a video file.
class VideoPipe {
 public:
  /// Starts ffmpeg writing `path` (its extension picks the container) from frames of
  /// width × height at `fps`: into videoTempPath(path), renamed to `path` by close() once
  /// ffmpeg succeeded (a device or FIFO at `path` is written in place). Throws
  /// std::runtime_error when ffmpeg is missing or fails to start, or the temporary file exists.
  VideoPipe(const std::string& path, int width, int height, double fps);
  /// Closes the pipe and waits for ffmpeg (errors are swallowed; call close() to see them).
  ~VideoPipe();
  VideoPipe(const VideoPipe&) = delete;
  VideoPipe& operator=(const VideoPipe&) = delete;
  /// Writes one frame (width × height × 4 bytes, rows top-down). Throws std::runtime_error.
  void write(const std::uint8_t* rgba);
  /// Closes the pipe, waits for ffmpeg and throws std::runtime_error if it failed.
  void close();
  /// Frames written so far.
  int frames() const { return frames_; }
  /// The ffmpeg command line, for messages.
  std::string commandLine() const { return command_; }

 private:
  int fd_ = -1;
  pid_t pid_ = -1;
  std::size_t frameBytes_ = 0;
  int frames_ = 0;
  std::string path_, temp_, command_;
};

}  // namespace sph2d
