// Output folders: a command never removes or overwrites a file it did not write. `sph2d run
// --out`, `check --out`, `bench accuracy --out`, --record and --video, run as real processes
// against folders holding other people's files, symbolic links and edited frames.
#include <doctest/doctest.h>

#include <sys/stat.h>

#include <algorithm>

#include <map>

#include <nlohmann/json.hpp>

#include "app_util.hpp"
#include "sph2d/render/png_io.hpp"

using namespace sph2d;
using namespace sph2d::apptest;
using nlohmann::json;

namespace {

const std::string kSmall = asset("scenes/tests/small_dam_break.json");

/// Every entry of `dir`: a file's bytes, a link's target ("-> target"), a folder's "<dir>"
/// (the lock file's presence only).
std::map<std::string, std::string> snapshot(const std::string& dir) {
  std::map<std::string, std::string> s;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (e.is_symlink())
      s[name] = "-> " + fs::read_symlink(e.path()).string();
    else if (name == ".sph2d.lock")
      s[name] = "<lock>";  // sph2d's own: the pid of whichever run held it last
    else if (e.is_directory())
      s[name] = "<dir>";
    else
      s[name] = readText(e.path().string());
  }
  return s;
}

void write(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

std::string fileXxh64(const std::string& path) {
  const std::string bytes = readText(path);
  return hex64(xxh64(bytes.data(), bytes.size()));
}

json manifestOf(const std::string& dir) { return json::parse(readText(dir + "/manifest.json")); }

/// The manifest's "files" as name -> XXH64.
std::map<std::string, std::string> listedFiles(const json& m) {
  std::map<std::string, std::string> out;
  for (const json& f : m.at("files")) out[f.at("file").get<std::string>()] = f.at("xxh64").get<std::string>();
  return out;
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST_CASE(
    "output folder: run refuses frame and manifest files it did not write, exit 2 naming the first, and changes nothing") {
  // Before: into this folder a 3-frame run exited 0, deleted frame_00005.png and overwrote manifest.json.
  const std::string dir = freshDir("of_foreign");
  write(dir + "/frame_00005.png", "someone's picture, not a PNG sph2d wrote\n");
  write(dir + "/manifest.json", "{\"name\": \"my web app\", \"icons\": []}\n");
  write(dir + "/holiday.png", "holiday photo");
  write(dir + "/notes.txt", "notes");
  const auto before = snapshot(dir);
  Result r = run("run " + q(kSmall) + " --frames 3 --quiet --out " + q(dir));
  INFO(r.out);
  CHECK(r.code == 2);
  CHECK(has(r.out, "the output directory '" + dir +
                       "' holds frame_00005.png, which sph2d cannot prove it wrote (no "
                       "manifest.json or journal of an earlier sph2d run there lists it)"));
  CHECK(has(r.out, "choose another --out, or move or remove " + dir + "/frame_00005.png yourself"));
  CHECK(has(r.out, "also in the way: 1 file (manifest.json)"));
  CHECK(snapshot(dir) == before);

  // --out through a symbolic link to the folder: the same.
  const std::string link = dir + "_link";
  fs::remove(link);
  fs::create_directory_symlink(dir, link);
  r = run("run " + q(kSmall) + " --frames 3 --quiet --out " + q(link));
  INFO(r.out);
  CHECK(r.code == 2);
  CHECK(has(r.out, "the output directory '" + link + "' holds frame_00005.png"));
  CHECK(snapshot(dir) == before);

  // The manifest alone is in the way too: sph2d cannot read it back as its own.
  fs::remove(dir + "/frame_00005.png");
  r = run("run " + q(kSmall) + " --frames 3 --quiet --out " + q(link));
  INFO(r.out);
  CHECK(r.code == 2);
  CHECK(has(r.out, "holds manifest.json, which sph2d cannot prove it wrote (not a manifest sph2d wrote"));
  CHECK(readText(dir + "/manifest.json") == before.at("manifest.json"));

  // Once the user moved it away, the run goes ahead; the files of other names were never in the way.
  fs::remove(dir + "/manifest.json");
  r = run("run " + q(kSmall) + " --frames 3 --quiet --out " + q(link));
  INFO(r.out);
  CHECK(r.code == 0);
  CHECK(filesEnding(dir, ".png") ==
        std::vector<std::string>{"frame_00000.png", "frame_00001.png", "frame_00002.png", "holiday.png"});
  CHECK(readText(dir + "/holiday.png") == "holiday photo");
  CHECK(readText(dir + "/notes.txt") == "notes");
  CHECK_FALSE(has(r.out, "removed"));
  fs::remove(link);
}

TEST_CASE(
    "output folder: a rerun removes only what the earlier run's manifest lists with matching hashes, and says so") {
  const std::string dir = freshDir("of_rerun");
  Result r = run("run " + q(kSmall) + " --frames 6 --quiet --export csv --out " + q(dir));
  REQUIRE(r.code == 0);
  // The manifest lists every file the run wrote with the XXH64 of its bytes.
  const auto listed = listedFiles(manifestOf(dir));
  CHECK(listed.size() == 12);
  for (int k = 0; k < 6; ++k)
    for (const char* ext : {".png", ".csv"}) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%05d%s", k, ext);
      INFO(name);
      REQUIRE(listed.count(name));
      CHECK(listed.at(name) == fileXxh64(dir + "/" + name));
    }
  write(dir + "/holiday.png", "holiday photo");

  // A shorter rerun: the earlier frames and exports go (no stale frame 3..5), --quiet or not it says so.
  r = run("run " + q(kSmall) + " --frames 3 --quiet --out " + q(dir));
  INFO(r.out);
  CHECK(r.code == 0);
  CHECK(has(r.out,
            "sph2d: removed 13 files (frame_00000.csv, frame_00000.png, frame_00001.csv, ...) that an earlier sph2d "
            "run wrote in " +
                dir));
  CHECK(filesEnding(dir, ".png") ==
        std::vector<std::string>{"frame_00000.png", "frame_00001.png", "frame_00002.png", "holiday.png"});
  CHECK(filesEnding(dir, ".csv").empty());
  CHECK(readText(dir + "/holiday.png") == "holiday photo");

  // A listed frame edited since: someone's edit, refused by name, and nothing changes.
  write(dir + "/frame_00001.png", readText(dir + "/frame_00001.png") + "an edit");
  const auto before = snapshot(dir);
  r = run("run " + q(kSmall) + " --frames 2 --quiet --out " + q(dir));
  INFO(r.out);
  CHECK(r.code == 2);
  CHECK(has(r.out,
            "holds frame_00001.png, which sph2d cannot prove it wrote (it changed since sph2d wrote it (its XXH64 is " +
                fileXxh64(dir + "/frame_00001.png")));
  CHECK(snapshot(dir) == before);
}

TEST_CASE("output folder: symbolic links are never written through: a frame or lock file that is a link is refused") {
  // Before: a frame_00001.png link was replaced by the run's frame and the run exited 0; a
  // .sph2d.lock link had its target truncated to the run's pid.
  const std::string dir = freshDir("of_links"), elsewhere = freshDir("of_links_elsewhere");
  write(elsewhere + "/victim.png", "precious");
  fs::create_symlink(elsewhere + "/victim.png", dir + "/frame_00001.png");
  Result r = run("run " + q(kSmall) + " --frames 3 --quiet --out " + q(dir));
  INFO(r.out);
  CHECK(r.code == 2);
  CHECK(has(
      r.out,
      "holds frame_00001.png, which sph2d cannot prove it wrote (a symbolic link: sph2d never writes through one)"));
  CHECK(fs::is_symlink(dir + "/frame_00001.png"));
  CHECK(readText(elsewhere + "/victim.png") == "precious");
  CHECK_FALSE(fs::exists(dir + "/frame_00000.png"));

  fs::remove(dir + "/frame_00001.png");
  write(elsewhere + "/lock_victim.txt", "my diary");
  fs::create_symlink(elsewhere + "/lock_victim.txt", dir + "/.sph2d.lock");
  r = run("run " + q(kSmall) + " --frames 3 --quiet --out " + q(dir));
  INFO(r.out);
  CHECK(r.code == 2);
  CHECK(has(r.out, "holds .sph2d.lock, which sph2d cannot take as its lock file (a symbolic link)"));
  CHECK(readText(elsewhere + "/lock_victim.txt") == "my diary");
  CHECK(fs::is_symlink(dir + "/.sph2d.lock"));
}

TEST_CASE(
    "output folder: --record and --video replace no file sph2d did not write, and in the run's folder its own are replaced") {
  const std::string dir = freshDir("of_record"), elsewhere = freshDir("of_record_elsewhere");
  // Outside any output folder, an existing record file has no record that could vouch for it.
  write(elsewhere + "/mine.jsonl", "my own notes\n");
  Result r = run("run " + q(kSmall) + " --frames 2 --no-images --record " + q(elsewhere + "/mine.jsonl"));
  INFO(r.out);
  CHECK(r.code == 2);
  CHECK(has(r.out, "--record " + elsewhere +
                       "/mine.jsonl: the file exists, and sph2d never overwrites a file it cannot prove it wrote"));
  CHECK(readText(elsewhere + "/mine.jsonl") == "my own notes\n");

  // In the run's folder: the manifest lists the record with its hash, and a rerun replaces it.
  const std::string events = elsewhere + "/events.jsonl";
  write(events, "{\"frame\": 1, \"type\": \"drop\", \"center\": [2, 2.5], \"radius\": 0.15}\n");
  for (int k = 0; k < 2; ++k) {
    r = run("run " + q(kSmall) + " --frames 3 --quiet --input " + q(events) + " --record " + q(dir + "/run.jsonl") +
            " --out " + q(dir));
    INFO(k, r.out);
    CHECK(r.code == 0);
    CHECK(listedFiles(manifestOf(dir)).at("run.jsonl") == fileXxh64(dir + "/run.jsonl"));
    CHECK(has(readText(dir + "/run.jsonl"), "\"type\":\"drop\""));
  }
  // A record file in the folder that sph2d did not write is refused by name.
  write(dir + "/theirs.jsonl", "their notes\n");
  r = run("run " + q(kSmall) + " --frames 3 --quiet --record " + q(dir + "/theirs.jsonl") + " --out " + q(dir));
  INFO(r.out);
  CHECK(r.code == 2);
  CHECK(has(r.out, "holds theirs.jsonl, which sph2d cannot prove it wrote"));
  CHECK(readText(dir + "/theirs.jsonl") == "their notes\n");

  // --video, with a stand-in ffmpeg that stores its standard input in its last argument.
  const std::string bin = freshDir("of_fakebin");
  write(bin + "/ffmpeg", "#!/bin/sh\nfor a in \"$@\"; do out=\"$a\"; done\ncat > \"$out\"\n");
  ::chmod((bin + "/ffmpeg").c_str(), 0755);
  const std::string path = "PATH=" + bin + ":/usr/bin:/bin";
  write(dir + "/film.raw", "their film");
  r = run("run " + q(kSmall) + " --frames 2 --quiet --video " + q(dir + "/film.raw") + " --out " + q(dir), path);
  INFO(r.out);
  CHECK(r.code == 2);
  CHECK(has(r.out, "holds film.raw, which sph2d cannot prove it wrote"));
  CHECK(readText(dir + "/film.raw") == "their film");
  write(elsewhere + "/film.raw", "their film");
  r = run("run " + q(kSmall) + " --frames 2 --quiet --video " + q(elsewhere + "/film.raw") + " --out " + q(dir), path);
  INFO(r.out);
  CHECK(r.code == 2);
  CHECK(has(r.out, "--video " + elsewhere + "/film.raw: the file exists"));
  CHECK(readText(elsewhere + "/film.raw") == "their film");
  fs::remove(dir + "/film.raw");
  for (int k = 0; k < 2; ++k) {
    r = run("run " + q(kSmall) + " --frames 2 --quiet --video " + q(dir + "/film.raw") + " --out " + q(dir), path);
    INFO(k, r.out);
    CHECK(r.code == 0);
    CHECK(fs::file_size(dir + "/film.raw") == 2u * 192u * 144u * 4u);
    CHECK(listedFiles(manifestOf(dir)).at("film.raw") == fileXxh64(dir + "/film.raw"));
    CHECK_FALSE(anyTemporary(dir));
  }
}

TEST_CASE("output folder: sph2d check --out replaces only the images an earlier check wrote") {
  const std::string ref = freshDir("of_check_ref"), out = freshDir("of_check_out");
  REQUIRE(run("run " + q(kSmall) + " --frames 4 --every 2 --quiet --out " + q(ref)).code == 0);
  json m = manifestOf(ref);
  m["frames"][1]["rgba_xxh64"] = "0123456789abcdef";  // frame 2 will differ: check writes its images
  write(ref + "/manifest.json", m.dump(1));
  write(out + "/frame_00002.png", "their frame");
  write(out + "/diff_00002.png", "their diff");
  const auto before = snapshot(out);
  Result r = run("check " + q(kSmall) + " --against " + q(ref + "/manifest.json") + " --out " + q(out));
  INFO(r.out);
  CHECK(r.code == 2);
  CHECK(has(r.out, "the output directory '" + out + "' holds diff_00002.png, which sph2d cannot prove it wrote"));
  CHECK(has(r.out, "also in the way: 1 file (frame_00002.png)"));
  CHECK_FALSE(has(r.out, "rerunning"));  // refused before the rerun
  CHECK(snapshot(out) == before);

  fs::remove(out + "/frame_00002.png");
  fs::remove(out + "/diff_00002.png");
  for (int k = 0; k < 2; ++k) {
    r = run("check " + q(kSmall) + " --against " + q(ref + "/manifest.json") + " --out " + q(out));
    INFO(k, r.out);
    CHECK(r.code == 1);
    CHECK(has(r.out, "frame 2 differs"));
    CHECK(has(r.out, "removed") == (k == 1));
    CHECK(filesEnding(out, ".png") == std::vector<std::string>{"diff_00002.png", "frame_00002.png"});
  }
  // A check into the run's own folder would replace its reference frames: refused, untouched.
  const auto refBefore = snapshot(ref);
  r = run("check " + q(kSmall) + " --against " + q(ref + "/manifest.json") + " --out " + q(ref));
  INFO(r.out);
  CHECK(r.code == 2);
  CHECK(has(
      r.out,
      "holds .sph2d.journal, which sph2d cannot prove it wrote (it is the journal of `sph2d run`, not of `sph2d check`"));
  CHECK(snapshot(ref) == refBefore);
}

TEST_CASE("output folder: bench accuracy --out replaces only the files an earlier bench accuracy wrote") {
  const std::string dir = freshDir("of_accuracy"), in = freshDir("of_accuracy_in");
  write(in + "/runs.csv", readText(std::string(SPH2D_SOURCE_DIR) + "/docs/accuracy/accuracy.csv"));
  const std::string args =
      "bench accuracy --from-csv " + q(in + "/runs.csv") + " --assets " + q(SPH2D_ASSETS) + " --out " + q(dir);
  write(dir + "/accuracy.md", "my own table");
  Result r = run(args);
  INFO(r.out);
  CHECK(r.code == 2);
  CHECK(has(
      r.out,
      "holds accuracy.md, which sph2d cannot prove it wrote (no journal of an earlier sph2d bench accuracy there lists it)"));
  CHECK(readText(dir + "/accuracy.md") == "my own table");
  CHECK_FALSE(fs::exists(dir + "/accuracy.csv"));
  fs::remove(dir + "/accuracy.md");
  // The runs' CSV from before run ids is redrawn in today's columns, the same bytes each time.
  const std::string legacy = readText(in + "/runs.csv");
  std::string first;
  for (int k = 0; k < 2; ++k) {
    r = run(args);
    INFO(k, r.out);
    CHECK(r.code == 0);
    const std::string csv = readText(dir + "/accuracy.csv");
    CHECK(std::count(csv.begin(), csv.end(), '\n') == std::count(legacy.begin(), legacy.end(), '\n'));
    CHECK(has(csv,
              "\nhydrostatic-muller2003-800-cfl1,hydrostatic,muller2003,,800,0.25,pressure_profile_max_rel,0.21387,"));
    if (k == 0)
      first = csv;
    else
      CHECK(csv == first);
  }
}

TEST_CASE("output folder: a run made before manifests listed files is rerun into, its frames proven by their pixels") {
  const std::string dir = freshDir("of_old_manifest");
  for (const auto& e : fs::directory_iterator(std::string(SPH2D_SOURCE_DIR) + "/tests/golden/shapes_overlay"))
    fs::copy_file(e.path(), dir + "/" + e.path().filename().string());
  REQUIRE_FALSE(manifestOf(dir).contains("files"));
  // A frame whose pixels changed since is refused.
  const std::string frame = dir + "/frame_00005.png";
  const std::string original = readText(frame);
  int w = 0, h = 0;
  std::vector<std::uint8_t> rgba;
  readPng(frame, w, h, rgba);
  rgba[0] = std::uint8_t(rgba[0] ^ 0x40);
  writePngAtomic(frame, w, h, rgba.data(), 1);
  const std::string args = "run " + q(dir + "/scene.json") + " --frames 6 --every 5 --overlay --quiet --out " + q(dir);
  Result r = run(args);
  INFO(r.out);
  CHECK(r.code == 2);
  CHECK(has(r.out, "holds frame_00005.png, which sph2d cannot prove it wrote (it changed since sph2d wrote it"));
  write(frame, original);
  r = run(args);
  INFO(r.out);
  CHECK(r.code == 0);
  CHECK(has(r.out, "removed 3 files (frame_00000.png, frame_00005.png, manifest.json)"));
  CHECK(manifestOf(dir).contains("files"));
  CHECK(fs::exists(dir + "/scene.json"));
}
