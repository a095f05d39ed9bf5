// Command-line misuse and output failures of `sph2d run`:
// - a mistake on the command line (unknown flag, missing value, number out of
//   range, an output directory that cannot be created or written) exits 2
//   with a message naming the flag or the path, before any work;
// - a write that fails during the run (full disk) stops the run with exit 1
//   and a message naming the file; every PNG already written decodes whole
//   and no temporary file is left.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "app_runner.hpp"
#include "sph2d/render/png_io.hpp"

namespace fs = std::filesystem;
using namespace sph2d::apptest;

namespace {

const std::string kScene = asset("scenes/tests/small_dam_break.json");

/// Files in `dir` (names), sorted.
std::vector<std::string> listDir(const std::string& dir) {
  std::vector<std::string> names;
  if (!fs::exists(dir)) return names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

/// Checks that `dir` holds exactly frame_00000.png … frame_{n-1}.png, each a
/// whole 192x144 PNG, and nothing else but the run's manifest.json, the directory's
/// lock file .sph2d.lock and its journal .sph2d.journal (no temporary file).
void expectWholeFrames(const std::string& dir, int n) {
  std::vector<std::string> names = listDir(dir);
  for (const char* own : {"manifest.json", ".sph2d.lock", ".sph2d.journal"})
    names.erase(std::remove(names.begin(), names.end(), std::string(own)), names.end());
  REQUIRE(names.size() == std::size_t(n));
  for (int f = 0; f < n; ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05d.png", f);
    CHECK(names[std::size_t(f)] == name);
    int w = 0, h = 0;
    std::vector<std::uint8_t> rgba;
    REQUIRE_NOTHROW(sph2d::readPng(dir + "/" + name, w, h, rgba));
    CHECK(w == 192);
    CHECK(h == 144);
    CHECK(rgba.size() == std::size_t(192 * 144 * 4));
  }
}

}  // namespace

TEST_CASE("cli misuse: an unknown flag exits 2 naming it") {
  for (const char* flag : {"--framez", "-f", "--out=dir", "--"}) {
    INFO(flag);
    const Result r = runSph2d("run " + q(kScene) + " " + flag + " 3");
    CHECK(r.code == 2);
    CHECK(r.out.find(std::string("sph2d: unknown option '") + flag + "' (see sph2d run --help)") != std::string::npos);
  }
  const Result r = runSph2d("frobnicate");
  CHECK(r.code == 2);
  CHECK(r.out.find("sph2d: unknown command 'frobnicate'; commands: run, info, check, render, bench") !=
        std::string::npos);
}

TEST_CASE("cli misuse: a flag without its value exits 2 naming the flag") {
  for (const char* flag : {"--out", "--frames", "--threads"}) {
    INFO(flag);
    const Result r = runSph2d("run " + q(kScene) + " " + flag);
    CHECK(r.code == 2);
    CHECK(r.out.find(std::string("sph2d: ") + flag + " needs a value") != std::string::npos);
  }
  Result r = runSph2d("run");
  CHECK(r.code == 2);
  CHECK(r.out.find("sph2d: missing the scene file (see sph2d run --help)") != std::string::npos);
  r = runSph2d("run " + q(kScene) + " " + q(kScene));
  CHECK(r.code == 2);
  CHECK(r.out.find("unexpected argument '" + kScene + "' (one scene per run)") != std::string::npos);
  r = runSph2d("");
  CHECK(r.code == 2);
  CHECK(r.out.find("Usage:") != std::string::npos);
}

TEST_CASE("cli misuse: numbers out of range or not numbers exit 2 with the allowed range") {
  struct Case {
    const char* flag;
    const char* value;
    const char* range;
  };
  const Case cases[] = {
      {"--frames", "0", "1 to 10000000"},        {"--frames", "-3", "1 to 10000000"},
      {"--frames", "10000001", "1 to 10000000"}, {"--frames", "99999999999999999999", "1 to 10000000"},
      {"--frames", "3x", "1 to 10000000"},       {"--frames", "2.5", "1 to 10000000"},
      {"--frames", "", "1 to 10000000"},         {"--threads", "0", "1 to 256"},
      {"--threads", "257", "1 to 256"},          {"--threads", "all", "1 to 256"},
  };
  for (const Case& c : cases) {
    INFO(c.flag << " " << c.value);
    const Result r = runSph2d("run " + q(kScene) + " " + c.flag + " " + q(c.value));
    CHECK(r.code == 2);
    CHECK(r.out.find(std::string("sph2d: ") + c.flag + " expects an integer from " + c.range + ", got '" + c.value +
                     "'") != std::string::npos);
  }
}

TEST_CASE("cli misuse: an output directory that cannot be created exits 2 naming it, before any work") {
  const std::string dir = scratch("cli_outdir");
  // Under a regular file: no user can create it, root included.
  std::ofstream(dir + "/file") << "x";
  for (const std::string& out : {std::string("/dev/null/frames"), dir + "/file/frames", dir + "/file"}) {
    INFO(out);
    const Result r = runSph2d("run " + q(kScene) + " --frames 2 --out " + q(out));
    CHECK(r.code == 2);
    CHECK(r.out.find("sph2d: cannot create the output directory '" + out + "'") != std::string::npos);
    CHECK(r.out.find("frames,") == std::string::npos);  // no summary: nothing ran
  }
  // --no-images needs no directory.
  const Result r = runSph2d("run " + q(kScene) + " --frames 2 --no-images --out /dev/null/frames");
  CHECK(r.code == 0);
  CHECK(r.out.find("sph2d: 2 frames") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("cli misuse: a write failing mid-run (test hook) exits 1 naming the file, earlier PNGs whole, no temp file") {
  // SPH2D_TEST_FAIL_WRITE_AFTER=N: the first N PNG writes succeed, the next fails as on a full disk.
  const std::string dir = scratch("cli_failwrite");
  const std::string out = dir + "/frames";
  const Result r =
      runSph2d("run " + q(kScene) + " --frames 30 --threads 2 --out " + q(out), "SPH2D_TEST_FAIL_WRITE_AFTER=5");
  INFO(r.out);
  CHECK(r.code == 1);
  CHECK(r.out.find("cannot write " + out + "/frame_00005.png: No space left on device") != std::string::npos);
  expectWholeFrames(out, 5);
  fs::remove_all(dir);
}

TEST_CASE("cli misuse: a full disk (a 200 KiB tmpfs) exits 1 naming the file, earlier PNGs whole, no temp file") {
  // A private mount namespace (unshare) holds the tmpfs: nothing is mounted
  // outside this test. What the run left is copied out before the namespace ends.
  if (std::system("unshare -rm true >/dev/null 2>&1") != 0) {
    MESSAGE("skipped: unshare -rm is not available here (the SPH2D_TEST_FAIL_WRITE_AFTER test covers the same path)");
    return;
  }
  const std::string dir = scratch("cli_diskfull");
  const std::string mnt = dir + "/mnt", copy = dir + "/copy";
  fs::create_directories(mnt);
  fs::create_directories(copy);
  const std::string script = "mount -t tmpfs -o size=200k tmpfs " + q(mnt) + " || exit 97; \"" + SPH2D_EXE + "\" run " +
                             q(kScene) + " --frames 200 --quiet --out " + q(mnt) + "; rc=$?; cp -a " + q(mnt) + "/. " +
                             q(copy) + "/; exit $rc";
  const Result r = runShell("unshare -rm sh -c " + q(script));
  INFO(r.out);
  if (r.code == 97) {
    MESSAGE("skipped: cannot mount a tmpfs in a user namespace here");
    fs::remove_all(dir);
    return;
  }
  CHECK(r.code == 1);
  // The write that finds the disk full is a frame's, or the line the run notes in the
  // folder's journal before writing one.
  CHECK((r.out.find("cannot write " + mnt + "/frame_") != std::string::npos ||
         r.out.find("cannot write " + mnt + "/.sph2d.journal") != std::string::npos));
  CHECK(r.out.find("No space left on device") != std::string::npos);
  std::vector<std::string> names = listDir(copy);
  // The manifest is written when the run stops, if the disk still has room for it; the
  // directory's lock file and journal are the run's too.
  for (const char* own : {"manifest.json", ".sph2d.lock", ".sph2d.journal"})
    names.erase(std::remove(names.begin(), names.end(), std::string(own)), names.end());
  MESSAGE(names.size() << " whole frames fit in 200 KiB");
  CHECK(names.size() >= 3);
  CHECK(names.size() < 200);
  expectWholeFrames(copy, int(names.size()));
  fs::remove_all(dir);
}
