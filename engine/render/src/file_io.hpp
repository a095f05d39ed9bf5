// file_io.hpp (internal) — writing a file's bytes where the path is not a regular file.
// The writers replace regular files atomically (a temporary file renamed over the
// target), but renaming over a device, a FIFO or a socket would replace the node itself
// (as root, `--out /dev/full` turned the device into a PNG file): such a target is
// written in place instead, and its errors (ENOSPC on /dev/full) reported. A temporary
// file is created new (O_EXCL, O_NOFOLLOW): an existing file or symbolic link of that name
// is never written through.
#pragma once

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

namespace sph2d {

/// Appends printf-style text (at most 255 characters a call) to `out`: the exports' lines.
inline void appendf(std::string& out, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
inline void appendf(std::string& out, const char* fmt, ...) {
  char buf[256];
  va_list ap;
  va_start(ap, fmt);
  const int n = std::vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  if (n > 0) out.append(buf, std::size_t(n < int(sizeof buf) ? n : int(sizeof buf) - 1));
}

/// True when `path` exists and is not a regular file (after symlinks).
inline bool isSpecialFile(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode);
}

/// Creates the temporary file `tmp` for writing; it must not exist (a file or a symbolic link
/// already there is left alone). Throws std::runtime_error naming it and the system's reason.
inline FILE* createTempFile(const std::string& tmp) {
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error("cannot create " + tmp + ": " + std::strerror(errno));
  FILE* f = ::fdopen(fd, "wb");
  if (!f) {
    const int err = errno;
    ::close(fd);
    ::unlink(tmp.c_str());
    throw std::runtime_error("cannot create " + tmp + ": " + std::strerror(err));
  }
  return f;
}

/// Writes `size` bytes to `path` in place. Throws std::runtime_error naming the path and
/// the system's reason.
inline void writeInPlace(const std::string& path, const void* data, std::size_t size) {
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw std::runtime_error("cannot open " + path + ": " + std::strerror(errno));
  bool ok = std::fwrite(data, 1, size, f) == size;
  ok = std::fflush(f) == 0 && ok;
  std::string why = ok ? "" : std::strerror(errno);
  if (std::fclose(f) != 0 && ok) {
    ok = false;
    why = std::strerror(errno);
  }
  if (!ok) throw std::runtime_error("cannot write " + path + ": " + why);
}

}  // namespace sph2d
