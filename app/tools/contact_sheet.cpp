// sph2d-contact-sheet — a grid of PNG frames in one image, each labelled with its
// frame number (and time with --fps), shrunk by an integer factor. Used to make
// the contact sheets under docs/images/.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "sph2d/render/image.hpp"
#include "sph2d/render/png_io.hpp"

using namespace sph2d;

namespace {

const char* kHelp =
    "Usage: sph2d-contact-sheet --out SHEET.png [--cols N] [--shrink S] [--fps F] IMAGE.png...\n"
    "\n"
    "Lays the images out left to right, top to bottom, N per row (default 4), each shrunk\n"
    "S times (box filter, default 2), with a 4 px gap, and labels each with the frame\n"
    "number of its name (frame_00120.png -> FRAME 120) and, with --fps, its time.\n";

/// The frame number in a name like ".../frame_00120.png", or -1.
int frameNumber(const std::string& path) {
  const auto slash = path.find_last_of('/');
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  int f = -1;
  return std::sscanf(name.c_str(), "frame_%d.png", &f) == 1 ? f : -1;
}

}  // namespace

int main(int argc, char** argv) {
  std::string out;
  int cols = 4, shrink = 2;
  double fps = 0;
  std::vector<std::string> inputs;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "sph2d-contact-sheet: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      std::fputs(kHelp, stdout);
      return 0;
    }
    if (a == "--out")
      out = value();
    else if (a == "--cols")
      cols = std::max(1, std::atoi(value().c_str()));
    else if (a == "--shrink")
      shrink = std::max(1, std::atoi(value().c_str()));
    else if (a == "--fps")
      fps = std::atof(value().c_str());
    else
      inputs.push_back(a);
  }
  if (out.empty() || inputs.empty()) {
    std::fputs(kHelp, stderr);
    return 2;
  }
  try {
    std::vector<Frame> frames;
    for (const auto& p : inputs) {
      Frame f;
      readPng(p, f.width, f.height, f.rgba);
      frames.push_back(std::move(f));
    }
    const int tw = frames[0].width / shrink, th = frames[0].height / shrink, gap = 4;
    const int n = int(frames.size()), rows = (n + cols - 1) / cols, c = std::min(cols, n);
    Frame sheet;
    sheet.width = c * tw + (c + 1) * gap;
    sheet.height = rows * th + (rows + 1) * gap;
    sheet.rgba.assign(std::size_t(sheet.width) * std::size_t(sheet.height) * 4, 0);
    for (std::size_t p = 0; p < sheet.rgba.size(); p += 4) {
      sheet.rgba[p] = sheet.rgba[p + 1] = sheet.rgba[p + 2] = 24;
      sheet.rgba[p + 3] = 255;
    }
    for (int k = 0; k < n; ++k) {
      const int x = gap + (k % cols) * (tw + gap), y = gap + (k / cols) * (th + gap);
      blitShrunk(sheet, x, y, frames[std::size_t(k)], shrink);
      const int f = frameNumber(inputs[std::size_t(k)]);
      if (f >= 0) {
        char label[64];
        if (fps > 0)
          std::snprintf(label, sizeof label, "%d  T %.2f S", f, f / fps);
        else
          std::snprintf(label, sizeof label, "FRAME %d", f);
        fillRect(sheet, x, y, x + textWidth(label, 1) + 4, y + textHeight(1) + 4, Rgba8{0, 0, 0, 150});
        drawText(sheet, x + 2, y + 2, label, 1, Rgba8{230, 230, 230, 255});
      }
    }
    writePngAtomic(out, sheet.width, sheet.height, sheet.rgba.data(), 9);
    std::printf("sph2d-contact-sheet: %d images, %dx%d, in %s\n", n, sheet.width, sheet.height, out.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sph2d-contact-sheet: %s\n", e.what());
    return 1;
  }
  return 0;
}
