// app/output/output_dir.cpp — output folders: the lock, the scan that proves which files are
// sph2d's own, and the journal; see output_dir.hpp.
#include "output/output_dir.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "output/manifest_reader.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/render/particle_export.hpp"
#include "sph2d/render/png_io.hpp"

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

namespace sph2d::cli {
namespace {

const char* kJournal = ".sph2d.journal";
const char* kLock = ".sph2d.lock";
const char* kManifest = "manifest.json";

bool plainName(const std::string& n) {
  return !n.empty() && n.size() <= 255 && n != "." && n != ".." && n.find('/') == std::string::npos &&
         n.find('\0') == std::string::npos;
}

bool hex16(const std::string& h) {
  return h.size() == 16 &&
         std::all_of(h.begin(), h.end(), [](char c) { return std::isxdigit(static_cast<unsigned char>(c)); });
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

/// The whole text of a regular file (nullopt when it cannot be read).
std::optional<std::string> readWhole(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) return std::nullopt;
  return ss.str();
}

/// What the records in a folder vouch for: per name the hashes its bytes may have, per frame
/// PNG of a manifest without "files" the hash of its pixels, and the temporary names.
struct Records {
  std::map<std::string, std::set<std::string>> hashes;
  std::map<std::string, std::string> pixelHashes;
  std::set<std::string> temps;
};

/// Reads DIR/.sph2d.journal into `r`; returns why it is not a journal of `command` ("" when it is).
std::string readJournal(const std::string& path, const std::string& command, Records& r) {
  const auto text = readWhole(path);
  if (!text) return "it cannot be read";
  std::istringstream in(*text);
  std::string line;
  int number = 0;
  Records mine;
  std::string owner;
  // A last line without its newline is a note cut short by a kill: it vouches for nothing.
  while (std::getline(in, line)) {
    if (in.eof()) break;
    ++number;
    json j;
    try {
      j = json::parse(line);
    } catch (const json::exception&) {
      return "not a journal sph2d wrote (line " + std::to_string(number) + " is not JSON)";
    }
    if (number == 1) {
      if (!j.is_object() || j.value("format", json()) != "sph2d-journal" || !j.contains("command") ||
          !j["command"].is_string())
        return "not a journal sph2d wrote (its first line is not {\"format\": \"sph2d-journal\", ...})";
      owner = j["command"].get<std::string>();
      continue;
    }
    const bool ok = j.is_object() && j.contains("file") && j["file"].is_string() &&
                    plainName(j["file"].get<std::string>()) &&
                    (!j.contains("xxh64") || (j["xxh64"].is_string() && hex16(j["xxh64"].get<std::string>()))) &&
                    (!j.contains("temp") || (j["temp"].is_string() && plainName(j["temp"].get<std::string>())));
    if (!ok) return "not a journal sph2d wrote (line " + std::to_string(number) + " is not a file entry)";
    const std::string name = j["file"].get<std::string>();
    if (j.contains("xxh64")) mine.hashes[name].insert(lower(j["xxh64"].get<std::string>()));
    if (j.contains("temp")) mine.temps.insert(j["temp"].get<std::string>());
  }
  if (number == 0) return "not a journal sph2d wrote (it is empty)";
  if (owner != command)
    return "it is the journal of `sph2d " + owner + "`, not of `sph2d " + command +
           "`: the folder holds another command's outputs";
  for (auto& [name, set] : mine.hashes) r.hashes[name].insert(set.begin(), set.end());
  r.temps.insert(mine.temps.begin(), mine.temps.end());
  return "";
}

/// Reads DIR/manifest.json into `r`; returns why it is not a manifest sph2d wrote ("" when it is).
std::string readRunManifest(const std::string& path, Records& r) {
  const auto text = readWhole(path);
  if (!text) return "it cannot be read";
  ManifestView v;
  try {
    v = parseManifest(*text, kManifest);
  } catch (const UsageError& e) {
    return std::string("not a manifest sph2d wrote (") + e.what() + ")";
  }
  const json& m = v.json;
  if (m.contains("files")) {
    const json& files = m["files"];
    if (!files.is_array()) return "not a manifest sph2d wrote (its \"files\" is not an array)";
    for (std::size_t k = 0; k < files.size(); ++k) {
      const json& f = files[k];
      if (!f.is_object() || !f.contains("file") || !f["file"].is_string() || !plainName(f["file"].get<std::string>()) ||
          !f.contains("xxh64") || !f["xxh64"].is_string() || !hex16(f["xxh64"].get<std::string>()))
        return "not a manifest sph2d wrote (files[" + std::to_string(k) + "] is not a file name and a 16-digit XXH64)";
      r.hashes[f["file"].get<std::string>()].insert(lower(f["xxh64"].get<std::string>()));
    }
  } else {
    // A manifest from before the "files" list vouches for its frame PNGs by their pixels.
    for (const auto& [frame, entry] : v.expected)
      r.pixelHashes[frameFileName(frame)] = lower(entry.value("rgba_xxh64", ""));
  }
  return "";
}

/// "X.tmpDIGITS" → X and the digits; "STEM.tmpDIGITS.EXT" (a video's) → STEM.EXT. False otherwise.
bool splitTempName(const std::string& name, std::string& target, std::string& pid) {
  static const std::regex plain(R"((.+)\.tmp(\d+))"), video(R"((.+)\.tmp(\d+)(\.[^./]+))");
  std::smatch m;
  if (std::regex_match(name, m, plain)) {
    target = m[1];
    pid = m[2];
    return true;
  }
  if (std::regex_match(name, m, video)) {
    target = std::string(m[1]) + std::string(m[3]);
    pid = m[2];
    return true;
  }
  return false;
}

}  // namespace

void makeOutputDir(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw UsageError("cannot create the output directory '" + dir + "': " + ec.message());
  if (::access(dir.c_str(), W_OK) != 0) throw UsageError("the output directory '" + dir + "' is not writable");
}

OutputLock::OutputLock(const std::string& dir) {
  const std::string path = dir + "/" + kLock;
  auto refuse = [&](const std::string& why) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    throw UsageError(
        "the output directory '" + dir + "' holds " + kLock + ", which sph2d cannot take as its lock file (" + why +
        "); sph2d never overwrites a file it did not write: choose another --out, or remove " + path + " yourself");
  };
  // O_NOFOLLOW: a symbolic link planted as the lock file is never followed (and its target never truncated).
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd_ < 0 && errno == ELOOP) refuse("a symbolic link");
  if (fd_ < 0) throw UsageError("cannot open the lock file '" + path + "': " + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) refuse("not a regular file");
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
  // An earlier holder wrote "pid N"; anything else is not sph2d's and stays as it is.
  char text[64] = {0};
  const ssize_t n = st.st_size < 64 ? ::pread(fd_, text, sizeof text - 1, 0) : -1;
  if (n < 0 || !std::regex_match(std::string(text, std::size_t(n)), std::regex(R"((pid \d+\n?)?)")))
    refuse("it holds something other than the pid of the sph2d run that last held it");
  const std::string me = "pid " + std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd_, 0) == 0) {
    const ssize_t w = ::pwrite(fd_, me.data(), me.size(), 0);
    (void)w;  // the name is a courtesy to the next run; the lock holds without it
  }
}

bool holdsLockFile(const std::string& dir) {
  std::error_code ec;
  return fs::exists(fs::symlink_status(fs::path(dir) / kLock, ec));
}

OutputLock::~OutputLock() {
  if (fd_ >= 0) ::close(fd_);  // closing releases the lock; the file stays (unlinking it would race)
}

bool isRunFileName(const std::string& name) {
  static const std::regex mine(R"(frame_\d{5,}\.(png|csv|vtk|json|svg)|bodies_\d{5,}\.csv)");
  return std::regex_match(name, mine);
}

std::optional<std::uint64_t> hashFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  Xxh64 h;
  std::vector<char> buf(1 << 16);
  while (in) {
    in.read(buf.data(), std::streamsize(buf.size()));
    if (in.gcount() > 0) h.update(buf.data(), std::size_t(in.gcount()));
  }
  if (in.bad()) return std::nullopt;
  return h.digest();
}

FolderScan scanOutputFolder(const std::string& dir, const FolderSpec& spec) {
  FolderScan scan;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return scan;  // nothing there yet (or not a folder: makeOutputDir says so)
  Records records;
  // The records first: a record sph2d cannot read back is itself in the way (the command
  // would replace it) and vouches for nothing.
  auto recordFile = [&](const char* name, auto read) {
    const fs::path p = fs::path(dir) / name;
    const fs::file_status st = fs::symlink_status(p, ec);
    if (!fs::exists(st)) return;
    if (fs::is_symlink(st)) return scan.foreign.push_back({name, "a symbolic link: sph2d never writes through one"});
    if (!fs::is_regular_file(st)) return scan.foreign.push_back({name, "not a regular file"});
    const std::string why = read(p.string());
    if (!why.empty()) return scan.foreign.push_back({name, why});
    if (std::string(name) == kManifest) {
      const auto h = hashFile(p.string());
      scan.own.push_back({name, h ? hex64(*h) : std::string()});
    }
  };
  recordFile(kJournal, [&](const std::string& p) { return readJournal(p, spec.command, records); });
  if (spec.manifest) recordFile(kManifest, [&](const std::string& p) { return readRunManifest(p, records); });

  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir, ec)) names.push_back(entry.path().filename().string());
  if (ec) throw UsageError("cannot list the output directory '" + dir + "': " + ec.message());
  std::sort(names.begin(), names.end());
  const std::string myPid = std::to_string(::getpid());
  for (const std::string& name : names) {
    if (name == kJournal || name == kLock || (spec.manifest && name == kManifest)) continue;
    const fs::path p = fs::path(dir) / name;
    const fs::file_status st = fs::symlink_status(p, ec);
    std::string target, pid;
    if (spec.writes(name)) {
      if (fs::is_symlink(st)) {
        scan.foreign.push_back({name, "a symbolic link: sph2d never writes through one"});
        continue;
      }
      if (!fs::is_regular_file(st)) {
        scan.foreign.push_back({name, "not a regular file"});
        continue;
      }
      const auto listed = records.hashes.find(name);
      const auto pixels = records.pixelHashes.find(name);
      if (listed == records.hashes.end() && pixels == records.pixelHashes.end()) {
        scan.foreign.push_back({name, spec.manifest
                                          ? "no manifest.json or journal of an earlier sph2d run there lists it"
                                          : "no journal of an earlier sph2d " + spec.command + " there lists it"});
        continue;
      }
      const auto h = hashFile(p.string());
      if (!h) {
        scan.foreign.push_back({name, "it cannot be read"});
        continue;
      }
      const std::string got = hex64(*h);
      bool proven = listed != records.hashes.end() && listed->second.count(got);
      std::string want = listed != records.hashes.end() ? *listed->second.begin() : std::string();
      if (!proven && pixels != records.pixelHashes.end()) {
        // A manifest from before "files": the frame must decode to the pixels it lists.
        int w = 0, hgt = 0;
        std::vector<std::uint8_t> rgba;
        try {
          readPng(p.string(), w, hgt, rgba);
          proven = hex64(xxh64(rgba.data(), rgba.size())) == pixels->second;
        } catch (const std::exception&) {
        }
        if (want.empty()) want = "pixels of XXH64 " + pixels->second;
      }
      if (proven)
        scan.own.push_back({name, got});
      else
        scan.foreign.push_back(
            {name, "it changed since sph2d wrote it (its XXH64 is " + got + ", the record says " + want + ")"});
    } else if (records.temps.count(name) && fs::is_regular_file(st)) {
      scan.ownTemps.push_back(name);
    } else if (splitTempName(name, target, pid) && (spec.writes(target) || (spec.manifest && target == kManifest))) {
      if (pid == myPid)
        scan.foreign.push_back({name, "the temporary name this run would write through"});
      else
        scan.strayTemps.push_back(name);
    }
  }
  std::sort(scan.own.begin(), scan.own.end(), [](const OwnedFile& a, const OwnedFile& b) { return a.name < b.name; });
  std::sort(scan.foreign.begin(), scan.foreign.end(),
            [](const ForeignFile& a, const ForeignFile& b) { return a.name < b.name; });
  return scan;
}

void refuseForeignFiles(const std::string& dir, const FolderScan& scan, const FolderSpec& spec) {
  if (scan.foreign.empty()) return;
  const ForeignFile& first = scan.foreign.front();
  std::string more;
  if (scan.foreign.size() > 1) {
    std::vector<std::string> rest;
    for (std::size_t k = 1; k < scan.foreign.size(); ++k) rest.push_back(scan.foreign[k].name);
    more = "; also in the way: " + describeFiles(rest);
  }
  throw UsageError("the output directory '" + dir + "' holds " + first.name + ", which sph2d cannot prove it wrote (" +
                   first.why + "); sph2d " + spec.command +
                   " never removes or overwrites a file it did not write: choose another " + spec.flag +
                   ", or move or remove " + (fs::path(dir) / first.name).string() + " yourself" + more);
}

std::vector<std::string> removeOwnFiles(const std::string& dir, const FolderScan& scan,
                                        const std::function<bool(const std::string&)>& which) {
  std::vector<std::string> removed;
  auto remove = [&](const std::string& name) {
    const std::string p = (fs::path(dir) / name).string();
    if (::unlink(p.c_str()) == 0)
      removed.push_back(name);
    else if (errno != ENOENT)
      throw std::runtime_error("cannot remove " + p + ": " + std::strerror(errno));
  };
  for (const OwnedFile& f : scan.own)
    if (which(f.name)) remove(f.name);
  for (const std::string& t : scan.ownTemps) remove(t);
  return removed;
}

std::string describeFiles(const std::vector<std::string>& names) {
  std::string s = std::to_string(names.size()) + (names.size() == 1 ? " file (" : " files (");
  for (std::size_t k = 0; k < names.size() && k < 3; ++k) s += (k ? ", " : "") + names[k];
  return s + (names.size() > 3 ? ", ...)" : ")");
}

void refuseExistingFile(const std::string& path, const std::string& flag) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) return;
  struct stat target {};
  if (::stat(path.c_str(), &target) == 0 &&
      (S_ISCHR(target.st_mode) || S_ISBLK(target.st_mode) || S_ISFIFO(target.st_mode) || S_ISSOCK(target.st_mode)))
    return;
  throw UsageError(flag + " " + path +
                   ": the file exists, and sph2d never overwrites a file it cannot prove it wrote; " +
                   "choose another name, or remove " + path + " yourself");
}

bool isInFolder(const std::string& path, const std::string& dir) {
  fs::path parent = fs::path(path).parent_path();
  if (parent.empty()) parent = ".";
  std::error_code ec;
  if (fs::equivalent(parent, dir, ec)) return true;
  // A folder not made yet: the same path once links and dots are resolved.
  auto resolved = [&](const fs::path& p) {
    fs::path r = fs::weakly_canonical(fs::absolute(p, ec), ec);
    return r.filename().empty() ? r.parent_path() : r;  // "out/x/" is "out/x"
  };
  const fs::path a = resolved(parent), b = resolved(dir);
  return !ec && a == b;
}

OutputJournal::OutputJournal(const std::string& dir, const std::string& command, const std::vector<OwnedFile>& kept)
    : path_(dir + "/" + kJournal) {
  json head;
  head["format"] = "sph2d-journal";
  head["format_version"] = 1;
  head["command"] = command;
  std::string text = head.dump() + "\n";
  for (const OwnedFile& f : kept) text += json{{"file", f.name}, {"xxh64", f.xxh64}}.dump() + "\n";
  writeFileAtomic(path_, text);
  fd_ = ::open(path_.c_str(), O_WRONLY | O_APPEND | O_NOFOLLOW | O_CLOEXEC);
  if (fd_ < 0) throw std::runtime_error("cannot open " + path_ + ": " + std::strerror(errno));
}

OutputJournal::~OutputJournal() {
  if (fd_ >= 0) ::close(fd_);
}

void OutputJournal::note(const std::string& name, const std::string& temp, std::optional<std::uint64_t> xxh64) {
  json j;
  j["file"] = name;
  if (xxh64) j["xxh64"] = hex64(*xxh64);
  if (!temp.empty()) j["temp"] = temp;
  const std::string line = j.dump() + "\n";
  std::lock_guard<std::mutex> lock(mutex_);
  // One write per line (O_APPEND): a note is in the journal whole before its file is written.
  if (::write(fd_, line.data(), line.size()) != ssize_t(line.size()))
    throw std::runtime_error("cannot write " + path_ + ": " + std::strerror(errno));
  if (!xxh64) return;
  for (OwnedFile& f : files_)
    if (f.name == name) {
      f.xxh64 = hex64(*xxh64);
      return;
    }
  files_.push_back({name, hex64(*xxh64)});
}

std::vector<OwnedFile> OutputJournal::files() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return files_;
}

}  // namespace sph2d::cli
