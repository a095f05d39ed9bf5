// app/output_dir.hpp — the output directory of `sph2d run`: made writable, held by one run
// at a time (a lock), and cleared of what an earlier run into it left (its frames, exports
// and temporary files), so that the directory's frames are always this run's.
#pragma once

#include <string>

namespace sph2d::cli {

/// Creates `dir` (and parents) and checks it is writable. Throws UsageError.
void makeOutputDir(const std::string& dir);

/// An exclusive lock on an output directory (flock on DIR/.sph2d.lock, which names the
/// holder's pid), held until destruction or the process's end, however it ends (the
/// kernel drops it on SIGKILL). A second run into the directory is refused.
class OutputLock {
 public:
  /// Takes the lock. Throws UsageError naming the holder when another process has it.
  explicit OutputLock(const std::string& dir);
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

 private:
  int fd_ = -1;
};

/// Removes what a run leaves in an output directory: frame_NNNNN.png, .csv and .vtk,
/// manifest.json, and the temporary files of atomic writes (NAME.tmpPID) of those. Other
/// files are left alone. Returns how many files were removed.
int removeEarlierRun(const std::string& dir);

}  // namespace sph2d::cli
