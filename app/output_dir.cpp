// app/output_dir.cpp — the output directory's lock and clean-up; see output_dir.hpp.
#include "output_dir.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <regex>

#include "cli.hpp"

namespace fs = std::filesystem;

namespace sph2d::cli {

void makeOutputDir(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) throw UsageError("cannot create the output directory '" + dir + "': " + ec.message());
  if (::access(dir.c_str(), W_OK) != 0) throw UsageError("the output directory '" + dir + "' is not writable");
}

OutputLock::OutputLock(const std::string& dir) {
  const std::string path = dir + "/.sph2d.lock";
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw UsageError("cannot open the lock file '" + path + "': " + std::strerror(errno));
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    char holder[64] = {0};
    const ssize_t n = ::pread(fd_, holder, sizeof holder - 1, 0);
    std::string who = n > 0 ? std::string(holder, std::size_t(n)) : std::string("an unknown process");
    while (!who.empty() && (who.back() == '\n' || who.back() == '\r')) who.pop_back();
    ::close(fd_);
    fd_ = -1;
    throw UsageError("the output directory '" + dir + "' is in use by another sph2d run (" + who +
                     "); wait for it to end or choose another --out");
  }
  const std::string me = "pid " + std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd_, 0) == 0) {
    const ssize_t w = ::pwrite(fd_, me.data(), me.size(), 0);
    (void)w;  // the name is a courtesy to the next run; the lock holds without it
  }
}

OutputLock::~OutputLock() {
  if (fd_ >= 0) ::close(fd_);  // closing releases the lock; the file stays (unlinking it would race)
}

int removeEarlierRun(const std::string& dir) {
  static const std::regex mine(R"((frame_\d{5,}\.(png|csv|vtk)|bodies_\d{5,}\.csv|manifest\.json)(\.tmp\d+)?)");
  int removed = 0;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (!entry.is_regular_file(ec) || !std::regex_match(name, mine)) continue;
    if (fs::remove(entry.path(), ec)) ++removed;
  }
  return removed;
}

}  // namespace sph2d::cli
