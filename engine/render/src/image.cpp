#include "sph2d/render/image.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

namespace sph2d {
namespace {

/// One glyph: 7 rows of 5 bits, bit 4 is the leftmost column.
struct Glyph {
  char c;
  std::uint8_t rows[7];
};

// Our own 5×7 table. Rows are written as binary literals left to right.
constexpr Glyph kGlyphs[] = {
    {'0', {0b01110, 0b10001, 0b10011, 0b10101, 0b11001, 0b10001, 0b01110}},
    {'1', {0b00100, 0b01100, 0b00100, 0b00100, 0b00100, 0b00100, 0b01110}},
    {'2', {0b01110, 0b10001, 0b00001, 0b00010, 0b00100, 0b01000, 0b11111}},
    {'3', {0b11111, 0b00010, 0b00100, 0b00010, 0b00001, 0b10001, 0b01110}},
    {'4', {0b00010, 0b00110, 0b01010, 0b10010, 0b11111, 0b00010, 0b00010}},
    {'5', {0b11111, 0b10000, 0b11110, 0b00001, 0b00001, 0b10001, 0b01110}},
    {'6', {0b00110, 0b01000, 0b10000, 0b11110, 0b10001, 0b10001, 0b01110}},
    {'7', {0b11111, 0b00001, 0b00010, 0b00100, 0b01000, 0b01000, 0b01000}},
    {'8', {0b01110, 0b10001, 0b10001, 0b01110, 0b10001, 0b10001, 0b01110}},
    {'9', {0b01110, 0b10001, 0b10001, 0b01111, 0b00001, 0b00010, 0b01100}},
    {'A', {0b01110, 0b10001, 0b10001, 0b10001, 0b11111, 0b10001, 0b10001}},
    {'B', {0b11110, 0b10001, 0b10001, 0b11110, 0b10001, 0b10001, 0b11110}},
    {'C', {0b01110, 0b10001, 0b10000, 0b10000, 0b10000, 0b10001, 0b01110}},
    {'D', {0b11100, 0b10010, 0b10001, 0b10001, 0b10001, 0b10010, 0b11100}},
    {'E', {0b11111, 0b10000, 0b10000, 0b11110, 0b10000, 0b10000, 0b11111}},
    {'F', {0b11111, 0b10000, 0b10000, 0b11110, 0b10000, 0b10000, 0b10000}},
    {'G', {0b01110, 0b10001, 0b10000, 0b10111, 0b10001, 0b10001, 0b01111}},
    {'H', {0b10001, 0b10001, 0b10001, 0b11111, 0b10001, 0b10001, 0b10001}},
    {'I', {0b01110, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b01110}},
    {'J', {0b00111, 0b00010, 0b00010, 0b00010, 0b00010, 0b10010, 0b01100}},
    {'K', {0b10001, 0b10010, 0b10100, 0b11000, 0b10100, 0b10010, 0b10001}},
    {'L', {0b10000, 0b10000, 0b10000, 0b10000, 0b10000, 0b10000, 0b11111}},
    {'M', {0b10001, 0b11011, 0b10101, 0b10101, 0b10001, 0b10001, 0b10001}},
    {'N', {0b10001, 0b10001, 0b11001, 0b10101, 0b10011, 0b10001, 0b10001}},
    {'O', {0b01110, 0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b01110}},
    {'P', {0b11110, 0b10001, 0b10001, 0b11110, 0b10000, 0b10000, 0b10000}},
    {'Q', {0b01110, 0b10001, 0b10001, 0b10001, 0b10101, 0b10010, 0b01101}},
    {'R', {0b11110, 0b10001, 0b10001, 0b11110, 0b10100, 0b10010, 0b10001}},
    {'S', {0b01111, 0b10000, 0b10000, 0b01110, 0b00001, 0b00001, 0b11110}},
    {'T', {0b11111, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100}},
    {'U', {0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b01110}},
    {'V', {0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b01010, 0b00100}},
    {'W', {0b10001, 0b10001, 0b10001, 0b10101, 0b10101, 0b10101, 0b01010}},
    {'X', {0b10001, 0b10001, 0b01010, 0b00100, 0b01010, 0b10001, 0b10001}},
    {'Y', {0b10001, 0b10001, 0b10001, 0b01010, 0b00100, 0b00100, 0b00100}},
    {'Z', {0b11111, 0b00001, 0b00010, 0b00100, 0b01000, 0b10000, 0b11111}},
    {' ', {0, 0, 0, 0, 0, 0, 0}},
    {'.', {0, 0, 0, 0, 0, 0b01100, 0b01100}},
    {',', {0, 0, 0, 0, 0b01100, 0b00100, 0b01000}},
    {'-', {0, 0, 0, 0b11111, 0, 0, 0}},
    {'+', {0, 0b00100, 0b00100, 0b11111, 0b00100, 0b00100, 0}},
    {':', {0, 0b01100, 0b01100, 0, 0b01100, 0b01100, 0}},
    {'/', {0, 0b00001, 0b00010, 0b00100, 0b01000, 0b10000, 0}},
    {'=', {0, 0, 0b11111, 0, 0b11111, 0, 0}},
    {'%', {0b11000, 0b11001, 0b00010, 0b00100, 0b01000, 0b10011, 0b00011}},
    {'(', {0b00010, 0b00100, 0b01000, 0b01000, 0b01000, 0b00100, 0b00010}},
    {')', {0b01000, 0b00100, 0b00010, 0b00010, 0b00010, 0b00100, 0b01000}},
    {'_', {0, 0, 0, 0, 0, 0, 0b11111}},
    {'#', {0b01010, 0b01010, 0b11111, 0b01010, 0b11111, 0b01010, 0b01010}},
    {'<', {0b00010, 0b00100, 0b01000, 0b10000, 0b01000, 0b00100, 0b00010}},
    {'>', {0b01000, 0b00100, 0b00010, 0b00001, 0b00010, 0b00100, 0b01000}},
    {'?', {0b01110, 0b10001, 0b00001, 0b00010, 0b00100, 0, 0b00100}},
    {'\'', {0b00100, 0b00100, 0b01000, 0, 0, 0, 0}},
};
constexpr Glyph kMissing = {'?', {0b11111, 0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b11111}};

const Glyph& glyphOf(char c) {
  const char u = char(std::toupper(static_cast<unsigned char>(c)));
  for (const Glyph& g : kGlyphs)
    if (g.c == u) return g;
  return kMissing;
}

void blendPixel(Frame& img, int x, int y, Rgba8 c) {
  if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
  std::uint8_t* p = &img.rgba[(std::size_t(y) * std::size_t(img.width) + std::size_t(x)) * 4];
  const unsigned a = c.a, ia = 255u - a;
  p[0] = std::uint8_t((c.r * a + p[0] * ia + 127u) / 255u);
  p[1] = std::uint8_t((c.g * a + p[1] * ia + 127u) / 255u);
  p[2] = std::uint8_t((c.b * a + p[2] * ia + 127u) / 255u);
  p[3] = 255;
}

}  // namespace

Rgba8 toRgba8(const std::array<double, 3>& c) {
  auto q = [](double v) { return std::uint8_t(std::lround(std::min(1.0, std::max(0.0, v)) * 255.0)); };
  return Rgba8{q(c[0]), q(c[1]), q(c[2]), 255};
}

bool hasGlyph(char c) { return &glyphOf(c) != &kMissing; }

int textWidth(const std::string& text, int scale) {
  if (text.empty()) return 0;
  return (int(text.size()) * 6 - 1) * scale;
}

int textHeight(int scale) { return 7 * scale; }

void drawText(Frame& img, int x, int y, const std::string& text, int scale, Rgba8 color) {
  for (std::size_t k = 0; k < text.size(); ++k) {
    const Glyph& g = glyphOf(text[k]);
    const int gx = x + int(k) * 6 * scale;
    for (int row = 0; row < 7; ++row)
      for (int col = 0; col < 5; ++col)
        if (g.rows[row] & (0x10 >> col))
          for (int sy = 0; sy < scale; ++sy)
            for (int sx = 0; sx < scale; ++sx) blendPixel(img, gx + col * scale + sx, y + row * scale + sy, color);
  }
}

void fillRect(Frame& img, int x0, int y0, int x1, int y1, Rgba8 color) {
  x0 = std::max(x0, 0);
  y0 = std::max(y0, 0);
  x1 = std::min(x1, img.width);
  y1 = std::min(y1, img.height);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) blendPixel(img, x, y, color);
}

std::array<float, 3> colorRamp(float t) {
  t = std::min(1.0f, std::max(0.0f, t));
  auto ch = [](float v) { return std::min(1.0f, std::max(0.0f, v)); };
  return {ch(1.5f - std::fabs(4.0f * t - 3.0f)), ch(1.5f - std::fabs(4.0f * t - 2.0f)),
          ch(1.5f - std::fabs(4.0f * t - 1.0f))};
}

std::string formatLabel(double v) {
  char buf[32];
  const double a = std::fabs(v);
  if (v == 0) return "0";
  if (a >= 1e4 || a < 1e-3)
    std::snprintf(buf, sizeof buf, "%.2E", v);
  else if (a >= 100)
    std::snprintf(buf, sizeof buf, "%.0f", v);
  else if (a >= 10)
    std::snprintf(buf, sizeof buf, "%.1f", v);
  else if (a >= 1)
    std::snprintf(buf, sizeof buf, "%.2f", v);
  else
    std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

int drawColorBar(Frame& img, double lo, double hi, const std::string& title, int scale) {
  const int margin = 6 * scale;
  const int barW = 6 * scale;
  const int barH = std::max(20, img.height / 2);
  const std::string top = formatLabel(hi), bottom = formatLabel(lo);
  const int labelW = std::max(textWidth(top, scale), textWidth(bottom, scale));
  const int titleW = textWidth(title, scale);
  const int th = textHeight(scale);
  const int boxW = std::max(titleW, barW + 2 * scale + labelW) + 2 * scale * 2;
  const int boxH = barH + 2 * th + 8 * scale;
  // Where it hides the least: of the right and left edges at the middle, top and bottom (in
  // that order of preference), the place with the fewest drawn pixels under it (solids and
  // fluid are brighter than the dark background: a channel above 60).
  const int xs[2] = {img.width - margin - boxW, margin};
  const int ys[3] = {(img.height - barH) / 2 - th - 3 * scale, margin, img.height - margin - boxH};
  int x0 = xs[0], y0 = ys[0];
  long best = -1;
  for (const int yc : ys)
    for (const int xc : xs) {
      long busy = 0;
      for (int y = std::max(0, yc); y < std::min(img.height, yc + boxH); ++y)
        for (int x = std::max(0, xc); x < std::min(img.width, xc + boxW); ++x) {
          const std::uint8_t* q = &img.rgba[(std::size_t(y) * std::size_t(img.width) + std::size_t(x)) * 4];
          busy += std::max({q[0], q[1], q[2]}) > 60;
        }
      if (best < 0 || busy < best) best = busy, x0 = xc, y0 = yc;
    }
  fillRect(img, x0, y0, x0 + boxW, y0 + boxH, Rgba8{0, 0, 0, 140});
  const Rgba8 white{235, 235, 235, 255};
  drawText(img, x0 + 2 * scale, y0 + 2 * scale, title, scale, white);
  const int bx = x0 + 2 * scale, by = y0 + th + 5 * scale;
  for (int y = 0; y < barH; ++y) {
    const float t = barH > 1 ? 1.0f - float(y) / float(barH - 1) : 0.5f;
    const auto c = colorRamp(t);
    const Rgba8 col{std::uint8_t(std::lround(c[0] * 255.0f)), std::uint8_t(std::lround(c[1] * 255.0f)),
                    std::uint8_t(std::lround(c[2] * 255.0f)), 255};
    fillRect(img, bx, by + y, bx + barW, by + y + 1, col);
  }
  drawText(img, bx + barW + 2 * scale, by, top, scale, white);
  drawText(img, bx + barW + 2 * scale, by + barH - th, bottom, scale, white);
  return x0;
}

void blitShrunk(Frame& dst, int x, int y, const Frame& src, int shrink) {
  shrink = std::max(1, shrink);
  const int w = src.width / shrink, h = src.height / shrink;
  const unsigned n = unsigned(shrink * shrink);
  for (int j = 0; j < h; ++j) {
    const int dy = y + j;
    if (dy < 0 || dy >= dst.height) continue;
    for (int i = 0; i < w; ++i) {
      const int dx = x + i;
      if (dx < 0 || dx >= dst.width) continue;
      unsigned sum[4] = {0, 0, 0, 0};
      for (int sy = 0; sy < shrink; ++sy)
        for (int sx = 0; sx < shrink; ++sx) {
          const std::uint8_t* p =
              &src.rgba[(std::size_t(j * shrink + sy) * std::size_t(src.width) + std::size_t(i * shrink + sx)) * 4];
          for (int c = 0; c < 4; ++c) sum[c] += p[c];
        }
      std::uint8_t* q = &dst.rgba[(std::size_t(dy) * std::size_t(dst.width) + std::size_t(dx)) * 4];
      for (int c = 0; c < 4; ++c) q[c] = std::uint8_t((sum[c] + n / 2) / n);
    }
  }
}

}  // namespace sph2d
