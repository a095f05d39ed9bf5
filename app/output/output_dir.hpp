// app/output/output_dir.hpp — output folders: made, held by one command at a time (a lock), and
// written only where sph2d can prove that what is there is its own.
//
// The rule: a command never removes or overwrites a file it did not write. A file in an
// output folder is sph2d's own when a record sph2d keeps there lists it with the XXH64 of
// its bytes and the file still holds those bytes: the manifest.json of `sph2d run` (its
// "files"; a manifest without that list, made before it existed, vouches for its frames by
// their pixel hashes), or the folder's journal, .sph2d.journal, where a command notes each
// file (its name, the hash of its bytes, its temporary name) before writing it, so that the
// files of a killed run are known too. Before a command writes into a folder it scans it
// (scanOutputFolder): every name it would write that is there must be its own, a regular
// file and not a symbolic link; else it refuses (exit 2) naming the first foreign one. Other
// names (holiday.png, notes.txt) are neither touched nor in the way.
#pragma once

#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace sph2d::cli {

/// Creates `dir` (and parents) and checks it is writable. Throws UsageError.
void makeOutputDir(const std::string& dir);

/// An exclusive lock on an output directory (flock on DIR/.sph2d.lock, which names the
/// holder's pid), held until destruction or the process's end, however it ends (the
/// kernel drops it on SIGKILL). A second command into the directory is refused, and so is a
/// .sph2d.lock that is a symbolic link or holds anything but a holder's pid.
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

/// True when DIR/.sph2d.lock is there (in any form): a command takes the lock before scanning
/// such a folder, so that one another command holds is named as in use.
bool holdsLockFile(const std::string& dir);

/// A file sph2d wrote into a folder: its name there and the XXH64 of its bytes (16 hex digits).
struct OwnedFile {
  std::string name, xxh64;
};

/// A name a command would write that is taken by a file it cannot prove it wrote, and why.
struct ForeignFile {
  std::string name, why;
};

/// What a command writes into its output folder.
struct FolderSpec {
  std::string command;                             ///< "run", "check", "bench accuracy": whose journal it keeps
  std::function<bool(const std::string&)> writes;  ///< the file names it writes (manifest.json apart)
  bool manifest = false;                           ///< run: manifest.json is its own when sph2d can read it back
  std::string flag = "--out";                      ///< the option that named the folder, for messages
};

/// What a command found in its output folder before writing there.
struct FolderScan {
  std::vector<OwnedFile> own;         ///< names it writes, proven its own (sorted): it may replace or remove them
  std::vector<std::string> ownTemps;  ///< temporary files of unfinished writes that its journal names
  std::vector<ForeignFile> foreign;   ///< names it writes taken by files it cannot prove it wrote (sorted)
  std::vector<std::string>
      strayTemps;  ///< names like an unfinished write's temporary file that no record names: left alone
};

/// The names `sph2d run` writes into its folder besides manifest.json: frame_NNNNN.png,
/// frame_NNNNN.csv, frame_NNNNN.vtk and bodies_NNNNN.csv.
bool isRunFileName(const std::string& name);

/// Scans `dir` (which may be missing: nothing there) for a command that writes `spec`.
/// Reads only; hashes the files that a record lists.
FolderScan scanOutputFolder(const std::string& dir, const FolderSpec& spec);

/// Throws UsageError (exit 2) when `scan` found foreign files: names the folder, the first one
/// and why, how many more, and what to do (another --out, or remove the file).
void refuseForeignFiles(const std::string& dir, const FolderScan& scan, const FolderSpec& spec);

/// Removes the own files of `scan` that `which` accepts and every own temporary file; returns
/// the names removed. Throws std::runtime_error when one cannot be removed.
std::vector<std::string> removeOwnFiles(const std::string& dir, const FolderScan& scan,
                                        const std::function<bool(const std::string&)>& which);

/// "N files (a, b, c, ...)": a count and the first few names, for messages.
std::string describeFiles(const std::vector<std::string>& names);

/// Refuses (UsageError, exit 2) to write `path`, the file of option `flag`, when something is
/// there that is not a device, FIFO or socket (those are written in place): a file elsewhere
/// than an output folder has no record that could prove sph2d wrote it.
void refuseExistingFile(const std::string& path, const std::string& flag);

/// True when `path`'s folder is `dir` (the same directory, however spelled).
bool isInFolder(const std::string& path, const std::string& dir);

/// XXH64 of a file's bytes, read in pieces; nullopt when it cannot be read.
std::optional<std::uint64_t> hashFile(const std::string& path);

/// DIR/.sph2d.journal of one command: each file it writes there is noted, with the hash of
/// the bytes it will hold and its temporary name, before it is written. Thread-safe.
class OutputJournal {
 public:
  /// Starts the journal of `command` afresh (written whole), listing `kept`: the own files of
  /// earlier commands that stay. Throws std::runtime_error.
  OutputJournal(const std::string& dir, const std::string& command, const std::vector<OwnedFile>& kept);
  ~OutputJournal();
  OutputJournal(const OutputJournal&) = delete;
  OutputJournal& operator=(const OutputJournal&) = delete;
  /// Notes that `name` will be written through the temporary file `temp` ("": written in
  /// place) and hold bytes of XXH64 `xxh64` (nullopt: known once written; noted again then).
  /// Throws std::runtime_error when the journal cannot be written.
  void note(const std::string& name, const std::string& temp, std::optional<std::uint64_t> xxh64);
  /// The files this command noted with a hash, the last hash of each, in the order first noted.
  std::vector<OwnedFile> files() const;

 private:
  std::string path_;
  int fd_ = -1;
  mutable std::mutex mutex_;
  std::vector<OwnedFile> files_;
};

}  // namespace sph2d::cli
