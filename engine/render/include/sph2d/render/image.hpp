// sph2d/render/image.hpp — RGBA8 images and the few 2D drawing operations the
// renderer and the tools share: a 5×7 bitmap font, filled and blended
// rectangles, the colour ramp of the particles mode and a colour bar.
//
// Design: everything here runs on the CPU over an RGBA8 buffer whose rows run
// top-down, after glReadPixels. Integer pixel arithmetic only (plus the ramp,
// evaluated in float), so text and bars are bit-identical on every machine and
// never depend on the GL driver. The glyph table is our own (digits, A–Z and
// the punctuation that numbers and units need); lower-case letters are drawn
// as upper-case.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace sph2d {

/// An RGBA8 image, rows top-down.
struct Frame {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;
};

/// An 8-bit colour with alpha (a = 255 opaque).
struct Rgba8 {
  std::uint8_t r = 0, g = 0, b = 0, a = 255;
};

/// Converts a colour in 0..1 (clamped) to 8 bits, alpha opaque.
Rgba8 toRgba8(const std::array<double, 3>& c);

/// Width in pixels of `text` drawn at `scale` (6·scale per character, minus the last gap).
int textWidth(const std::string& text, int scale);
/// Height in pixels of a line of text at `scale` (7·scale).
int textHeight(int scale);
/// Draws `text` with its top-left corner at (x, y); each font pixel becomes a scale×scale block.
/// Characters without a glyph draw as a box; pixels outside the image are skipped.
void drawText(Frame& img, int x, int y, const std::string& text, int scale, Rgba8 color);
/// Blends `color` over the rectangle [x0, x1) × [y0, y1) with weight alpha/255 (clipped to the image).
void fillRect(Frame& img, int x0, int y0, int x1, int y1, Rgba8 color);
/// True when `c` has a glyph in the font (after upper-casing).
bool hasGlyph(char c);

/// The blue → cyan → green → yellow → red ramp of the particles mode, t in 0..1 (clamped).
/// Same formula as shaders/particles.frag.
std::array<float, 3> colorRamp(float t);

/// Formats a value for a label with 3 significant digits ("0.00452", "12.3", "1.01E+03").
std::string formatLabel(double v);

/// Draws a vertical colour bar (ramp from `lo` at the bottom to `hi` at the top) with its
/// numeric range and `title` (e.g. "SPEED M/S") at the right or left edge of `img`, at
/// the middle, top or bottom: where it covers the fewest drawn (solid or fluid) pixels,
/// the right middle when that is clear. Returns the left x of what it drew.
int drawColorBar(Frame& img, double lo, double hi, const std::string& title, int scale);

/// Copies `src` into `dst` with its top-left corner at (x, y), shrunk by an integer
/// factor `shrink` (box filter); pixels outside `dst` are skipped.
void blitShrunk(Frame& dst, int x, int y, const Frame& src, int shrink);

}  // namespace sph2d
