// sph2d-png-settings — measures libpng's settings (zlib strategy and level, PNG filters, memory
// level, buffer size, how rows are handed over) on real frames: CPU time per frame and file size.
// Used to choose PNG level 1's settings (docs/RENDERING.md "PNG settings"); every encoding goes
// through sph2d::encodePng, the code writePngAtomic uses.
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "sph2d/render/png_io.hpp"

using namespace sph2d;

namespace {

const char* kHelp =
    "Usage: sph2d-png-settings [--reps N] [--only K] FRAME.png...\n"
    "\n"
    "Reads the frames and encodes each N times (default 5) with every setting of the table,\n"
    "in memory, interleaving the settings. Prints a Markdown table: per setting, the CPU time\n"
    "per frame (every thread of the process: the run coder codes on two; the best of the N encodings\n"
    "of a frame, averaged over the frames)\n"
    "and the mean size, also relative to the files given. --only K measures the table's\n"
    "K-th row alone (from 1; for a profiler).\n";

/// CPU time of the process, every thread [ms] (the run coder's helper thread counts).
double processCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

struct Row {
  std::string name;
  PngSettings s;
};

/// The settings measured: level 1 with Z_RLE and the SUB filter (libpng's level 1 before and
/// after), then one change at a time, then combinations, then references.
std::vector<Row> settingsTable() {
  using In = PngSettings::Input;
  auto make = [](int level, int strategy, int filters) {
    PngSettings s;
    s.level = level;
    s.strategy = strategy;
    s.filters = filters;
    return s;
  };
  const int RLE = 3, FILTERED = 1, HUFFMAN = 2, FIXED = 4, DEFAULT = 0;
  const int NONE = 0x08, SUB = 0x10, UP = 0x20, ALL = 0xf8;
  std::vector<Row> t;
  t.push_back({"level 1, Z_RLE, SUB (libpng's level 1 before png_fast)", make(1, RLE, SUB)});
  t.push_back({"level 1, default strategy, SUB", make(1, DEFAULT, SUB)});
  t.push_back({"level 1, Z_FILTERED, SUB", make(1, FILTERED, SUB)});
  t.push_back({"level 1, Z_FIXED, SUB", make(1, FIXED, SUB)});
  t.push_back({"level 1, Z_HUFFMAN_ONLY, SUB", make(1, HUFFMAN, SUB)});
  t.push_back({"level 1, Z_RLE, NONE", make(1, RLE, NONE)});
  t.push_back({"level 1, Z_RLE, UP", make(1, RLE, UP)});
  t.push_back({"level 1, Z_RLE, SUB or UP per row (libpng's choice)", make(1, RLE, SUB | UP)});
  t.push_back({"level 1, default strategy, NONE", make(1, DEFAULT, NONE)});
  Row r{"level 1, Z_RLE, SUB, memory level 9", make(1, RLE, SUB)};
  r.s.memLevel = 9;
  t.push_back(r);
  r = {"level 1, Z_RLE, SUB, memory level 4", make(1, RLE, SUB)};
  r.s.memLevel = 4;
  t.push_back(r);
  r = {"level 1, Z_RLE, SUB, buffer 64 KiB", make(1, RLE, SUB)};
  r.s.bufferSize = 65536;
  t.push_back(r);
  r = {"level 1, Z_RLE, SUB, buffer 1 MiB", make(1, RLE, SUB)};
  r.s.bufferSize = 1 << 20;
  t.push_back(r);
  r = {"level 1, Z_RLE, SUB, one png_write_image", make(1, RLE, SUB)};
  r.s.wholeImage = true;
  t.push_back(r);
  r = {"level 1, Z_RLE, SUB, RGB packed by sph2d", make(1, RLE, SUB)};
  r.s.input = In::PackedRgb;
  t.push_back(r);
  r = {"level 1, Z_RLE, SUB, RGBA file (alpha kept)", make(1, RLE, SUB)};
  r.s.input = In::Rgba;
  t.push_back(r);
  r = {"level 1, Z_RLE, SUB, memory level 9, buffer 1 MiB", make(1, RLE, SUB)};
  r.s.memLevel = 9;
  r.s.bufferSize = 1 << 20;
  t.push_back(r);
  r = {"level 1, Z_RLE, SUB, memory level 9, buffer 1 MiB, packed, one call", make(1, RLE, SUB)};
  r.s.memLevel = 9;
  r.s.bufferSize = 1 << 20;
  r.s.input = In::PackedRgb;
  r.s.wholeImage = true;
  t.push_back(r);
  // Without a filter, level 1's hash matching (deflate_fast) finds the background's repeated
  // pixels at distance 3: the fastest family found, measured further.
  t.push_back({"level 1, Z_FIXED, NONE", make(1, FIXED, NONE)});
  t.push_back({"level 2, default strategy, NONE", make(2, DEFAULT, NONE)});
  t.push_back({"level 1, default strategy, UP", make(1, DEFAULT, UP)});
  for (int m : {1, 2, 4, 9}) {
    r = {"level 1, default strategy, NONE, memory level " + std::to_string(m), make(1, DEFAULT, NONE)};
    r.s.memLevel = m;
    t.push_back(r);
  }
  r = {"level 1, default strategy, NONE, window 2^12", make(1, DEFAULT, NONE)};
  r.s.windowBits = 12;
  t.push_back(r);
  r = {"level 1, default strategy, NONE, RGB packed by sph2d", make(1, DEFAULT, NONE)};
  r.s.input = In::PackedRgb;
  t.push_back(r);
  r = {"level 1, default strategy, NONE, RGBA file (alpha kept)", make(1, DEFAULT, NONE)};
  r.s.input = In::Rgba;
  t.push_back(r);
  r = {"level 1, default strategy, NONE, buffer 1 MiB, one call", make(1, DEFAULT, NONE)};
  r.s.bufferSize = 1 << 20;
  r.s.wholeImage = true;
  t.push_back(r);
  // The coders outside libpng: libdeflate at its levels 1 and 2 (filter NONE), and the run
  // coder (SUB, runs of the pixel to the left and the row above: level 1's now).
  for (int level : {1, 2}) {
    r = {"libdeflate level " + std::to_string(level) + ", NONE", make(level, DEFAULT, NONE)};
    r.s.deflater = PngSettings::Deflater::Libdeflate;
    t.push_back(r);
  }
  r = {"run coder, SUB (level 1's)", make(1, DEFAULT, SUB)};
  r.s.deflater = PngSettings::Deflater::Runs;
  t.push_back(r);
  t.push_back({"level 0 (stored), NONE", make(0, DEFAULT, NONE)});
  t.push_back({"level 6, every filter (zlib's default level)", make(6, DEFAULT, ALL)});
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 5;
  std::size_t only = 0;
  std::vector<std::string> inputs;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::fputs(kHelp, stdout);
      return 0;
    }
    if (a == "--reps" && i + 1 < argc) {
      reps = std::max(1, std::atoi(argv[++i]));
      continue;
    }
    if (a == "--only" && i + 1 < argc) {
      only = std::size_t(std::max(0, std::atoi(argv[++i])));
      continue;
    }
    if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "sph2d-png-settings: unknown option '%s'\n%s", a.c_str(), kHelp);
      return 2;
    }
    inputs.push_back(a);
  }
  if (inputs.empty()) {
    std::fputs(kHelp, stderr);
    return 2;
  }
  try {
    struct Image {
      int w = 0, h = 0;
      std::vector<std::uint8_t> rgba;
      double bytes = 0;
    };
    std::vector<Image> images(inputs.size());
    double inputBytes = 0;
    for (std::size_t k = 0; k < inputs.size(); ++k) {
      readPng(inputs[k], images[k].w, images[k].h, images[k].rgba);
      if (FILE* f = std::fopen(inputs[k].c_str(), "rb")) {
        std::fseek(f, 0, SEEK_END);
        inputBytes += double(std::ftell(f));
        std::fclose(f);
      }
    }
    inputBytes /= double(inputs.size());
    std::vector<Row> table = settingsTable();
    if (only > 0 && only <= table.size()) table = {table[only - 1]};
    // best[setting][frame]: the least CPU time of the reps; bytes[setting]: the mean size.
    std::vector<std::vector<double>> best(table.size(), std::vector<double>(images.size(), 1e30));
    std::vector<double> bytes(table.size(), 0);
    std::vector<std::uint8_t> out;
    for (int r = 0; r < reps; ++r)
      for (std::size_t s = 0; s < table.size(); ++s)
        for (std::size_t k = 0; k < images.size(); ++k) {
          const Image& im = images[k];
          const double t0 = processCpuMs();
          encodePng(im.w, im.h, im.rgba.data(), table[s].s, out);
          best[s][k] = std::min(best[s][k], processCpuMs() - t0);
          if (r == 0) bytes[s] += double(out.size()) / double(images.size());
        }
    std::printf("%zu frames of %dx%d, best of %d encodings each; files given: %.1f KB per frame\n\n", images.size(),
                images[0].w, images[0].h, reps, inputBytes / 1024.0);
    std::printf("| setting | CPU ms per frame | KB per frame | size / files given |\n|---|---|---|---|\n");
    for (std::size_t s = 0; s < table.size(); ++s) {
      double ms = 0;
      for (double b : best[s]) ms += b / double(images.size());
      std::printf("| %s | %.2f | %.1f | %.2f |\n", table[s].name.c_str(), ms, bytes[s] / 1024.0, bytes[s] / inputBytes);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sph2d-png-settings: %s\n", e.what());
    return 1;
  }
  return 0;
}
