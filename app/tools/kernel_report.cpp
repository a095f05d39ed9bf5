// sph2d_kernel_report — redraws docs/images/kernels.png (W, dW/dr and ∇²W of
// every kernel against r/R) and prints the field-operator convergence tables of
// docs/KERNELS.md as Markdown. The tables come from tests/support/field_study.hpp,
// the same code the tests assert on.
//
//   sph2d_kernel_report [--png PATH | --no-png]      (default PATH: docs/images/kernels.png)
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "core/kernels.hpp"
#include "sph2d/render/png_io.hpp"
#include "support/field_study.hpp"

namespace {

using namespace sph2d;

struct Rgb {
  std::uint8_t r, g, b;
};

// The kernels in plot and table order, with their plot colours (docs/KERNELS.md lists them).
constexpr Rgb kPoly6{31, 119, 180}, kSpiky{255, 127, 14}, kVisc{44, 160, 44}, kCubic{214, 39, 40},
    kWendland{148, 103, 189};

/// An RGBA8 image, rows top-down, with clipped drawing.
struct Canvas {
  int w, h;
  std::vector<std::uint8_t> px;
  int cx0 = 0, cy0 = 0, cx1 = 0, cy1 = 0;  // clip rectangle, inclusive

  /// A white canvas of w × h pixels.
  Canvas(int width, int height) : w(width), h(height), px(std::size_t(width) * height * 4, 255) { clipAll(); }
  /// Clips drawing to the whole canvas.
  void clipAll() { clip(0, 0, w - 1, h - 1); }
  /// Clips drawing to [x0, x1] × [y0, y1].
  void clip(int x0, int y0, int x1, int y1) {
    cx0 = std::max(0, x0);
    cy0 = std::max(0, y0);
    cx1 = std::min(w - 1, x1);
    cy1 = std::min(h - 1, y1);
  }
  /// Sets one pixel (ignored outside the clip rectangle).
  void set(int x, int y, Rgb c) {
    if (x < cx0 || x > cx1 || y < cy0 || y > cy1) return;
    std::uint8_t* p = &px[(std::size_t(y) * w + x) * 4];
    p[0] = c.r;
    p[1] = c.g;
    p[2] = c.b;
    p[3] = 255;
  }
  /// Fills [x0, x1] × [y0, y1].
  void fill(int x0, int y0, int x1, int y1, Rgb c) {
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) set(x, y, c);
  }
  /// A line of the given thickness (a square brush), dashed when dash > 0 (pixels on, pixels off).
  void line(double x0, double y0, double x1, double y1, Rgb c, int thick = 1, int dash = 0) {
    const int steps = int(std::ceil(std::max(std::fabs(x1 - x0), std::fabs(y1 - y0)))) + 1;
    for (int s = 0; s <= steps; ++s) {
      if (dash > 0 && (s / dash) % 2 == 1) continue;
      const double t = double(s) / steps;
      const int x = int(std::lround(x0 + (x1 - x0) * t)), y = int(std::lround(y0 + (y1 - y0) * t));
      const int a = -(thick - 1) / 2, b = thick / 2;
      for (int dy = a; dy <= b; ++dy)
        for (int dx = a; dx <= b; ++dx) set(x + dx, y + dy, c);
    }
  }
};

/// A 5×7 bitmap font for the plot's labels: the few characters they use.
struct Glyph {
  char c;
  const char* rows[7];
};
constexpr Glyph kFont[] = {
    {'0', {" ### ", "#   #", "#  ##", "# # #", "##  #", "#   #", " ### "}},
    {'1', {"  #  ", " ##  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### "}},
    {'2', {" ### ", "#   #", "    #", "   # ", "  #  ", " #   ", "#####"}},
    {'3', {"#####", "   # ", "  #  ", "   # ", "    #", "#   #", " ### "}},
    {'4', {"   # ", "  ## ", " # # ", "#  # ", "#####", "   # ", "   # "}},
    {'5', {"#####", "#    ", "#### ", "    #", "    #", "#   #", " ### "}},
    {'6', {"  ## ", " #   ", "#    ", "#### ", "#   #", "#   #", " ### "}},
    {'7', {"#####", "    #", "   # ", "  #  ", " #   ", " #   ", " #   "}},
    {'8', {" ### ", "#   #", "#   #", " ### ", "#   #", "#   #", " ### "}},
    {'9', {" ### ", "#   #", "#   #", " ####", "    #", "   # ", " ##  "}},
    {'.', {"     ", "     ", "     ", "     ", "     ", " ##  ", " ##  "}},
    {'-', {"     ", "     ", "     ", " ### ", "     ", "     ", "     "}},
    {'/', {"     ", "    #", "   # ", "  #  ", " #   ", "#    ", "     "}},
    {'^', {"  #  ", " # # ", "#   #", "     ", "     ", "     ", "     "}},
    {'a', {"     ", "     ", " ### ", "    #", " ####", "#   #", " ####"}},
    {'b', {"#    ", "#    ", "# ## ", "##  #", "#   #", "#   #", "#### "}},
    {'c', {"     ", "     ", " ### ", "#    ", "#    ", "#   #", " ### "}},
    {'d', {"    #", "    #", " ## #", "#  ##", "#   #", "#   #", " ####"}},
    {'e', {"     ", "     ", " ### ", "#   #", "#####", "#    ", " ### "}},
    {'i', {"  #  ", "     ", " ##  ", "  #  ", "  #  ", "  #  ", " ### "}},
    {'k', {"#    ", "#    ", "#  # ", "# #  ", "##   ", "# #  ", "#  # "}},
    {'l', {" ##  ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### "}},
    {'n', {"     ", "     ", "# ## ", "##  #", "#   #", "#   #", "#   #"}},
    {'o', {"     ", "     ", " ### ", "#   #", "#   #", "#   #", " ### "}},
    {'p', {"     ", "     ", "#### ", "#   #", "#### ", "#    ", "#    "}},
    {'r', {"     ", "     ", "# ## ", "##  #", "#    ", "#    ", "#    "}},
    {'s', {"     ", "     ", " ####", "#    ", " ### ", "    #", "#### "}},
    {'t', {" #   ", " #   ", "###  ", " #   ", " #   ", " #  #", "  ## "}},
    {'u', {"     ", "     ", "#   #", "#   #", "#   #", "#  ##", " ## #"}},
    {'v', {"     ", "     ", "#   #", "#   #", "#   #", " # # ", "  #  "}},
    {'w', {"     ", "     ", "#   #", "#   #", "# # #", "# # #", " # # "}},
    {'y', {"     ", "     ", "#   #", "#   #", " ####", "    #", " ### "}},
    {'C', {" ### ", "#   #", "#    ", "#    ", "#    ", "#   #", " ### "}},
    {'R', {"#### ", "#   #", "#   #", "#### ", "# #  ", "#  # ", "#   #"}},
    {'W', {"#   #", "#   #", "#   #", "# # #", "# # #", "# # #", " # # "}},
};

/// Draws s with its top-left corner at (x, y), `scale` pixels per font pixel;
/// align −1 left, 0 centre, +1 right of x. Characters outside kFont are spaces.
void text(Canvas& c, int x, int y, const std::string& s, Rgb col, int scale = 2, int align = -1) {
  const int adv = 6 * scale, width = int(s.size()) * adv - scale;
  int x0 = align < 0 ? x : align == 0 ? x - width / 2 : x - width;
  for (char ch : s) {
    for (const Glyph& g : kFont) {
      if (g.c != ch) continue;
      for (int r = 0; r < 7; ++r)
        for (int k = 0; k < 5; ++k)
          if (g.rows[r][k] == '#')
            c.fill(x0 + k * scale, y + r * scale, x0 + (k + 1) * scale - 1, y + (r + 1) * scale - 1, col);
    }
    x0 += adv;
  }
}

/// One panel: a function of q = r/R in [0, 1] drawn over [yLo, yHi].
struct Panel {
  int x0, y0, x1, y1;  // pixel rectangle of the plot area
  double yLo, yHi;
  /// Pixel column of q.
  double px(double q) const { return x0 + q * (x1 - x0); }
  /// Pixel row of value v (clamped a little outside the panel, so clipped lines stay short).
  double py(double v) const {
    const double t = (v - yLo) / (yHi - yLo);
    return y1 - std::clamp(t, -0.05, 1.05) * (y1 - y0);
  }
};

/// Axes, grid lines at q = ¼, ½, ¾ and at every `yStep`, the zero line, tick labels and the title.
void drawFrame(Canvas& c, const Panel& p, double yStep, const std::string& title) {
  const Rgb grid{225, 225, 225}, zero{150, 150, 150}, axis{0, 0, 0};
  c.clipAll();
  for (double q : {0.25, 0.5, 0.75}) c.line(p.px(q), p.y0, p.px(q), p.y1, grid);
  for (double v = std::ceil(p.yLo / yStep) * yStep; v <= p.yHi; v += yStep) c.line(p.x0, p.py(v), p.x1, p.py(v), grid);
  if (p.yLo < 0 && p.yHi > 0) c.line(p.x0, p.py(0), p.x1, p.py(0), zero, 1);
  c.line(p.x0, p.y0, p.x0, p.y1, axis, 2);
  c.line(p.x0, p.y1, p.x1, p.y1, axis, 2);
  char buf[32];
  for (double q : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    c.line(p.px(q), p.y1, p.px(q), p.y1 + 6, axis, 2);  // ticks
    std::snprintf(buf, sizeof buf, "%g", q);
    text(c, int(p.px(q)), p.y1 + 12, buf, axis, 2, 0);
  }
  text(c, p.x1, p.y1 + 34, "r/R", axis, 2, 1);
  for (double v = std::ceil(p.yLo / yStep) * yStep; v <= p.yHi; v += yStep) {
    std::snprintf(buf, sizeof buf, "%g", std::fabs(v) < 1e-9 ? 0.0 : v);
    text(c, p.x0 - 8, int(p.py(v)) - 7, buf, axis, 2, 1);
  }
  text(c, (p.x0 + p.x1) / 2, p.y0 - 30, title, axis, 3, 0);
}

/// Draws f(q) for q in (0, 1] as a thick polyline clipped to the panel.
template <class F>
void drawCurve(Canvas& c, const Panel& p, Rgb col, F f) {
  c.clip(p.x0, p.y0, p.x1, p.y1);
  const int n = 800;
  double qa = 0.5 / n, va = f(qa);
  for (int i = 1; i <= n; ++i) {
    const double qb = double(i) / n, vb = f(qb);
    if (std::isfinite(va) && std::isfinite(vb)) c.line(p.px(qa), p.py(va), p.px(qb), p.py(vb), col, 3);
    qa = qb;
    va = vb;
  }
  c.clipAll();
}

/// The three panels (W R², dW/dr R³, ∇²W R⁴ against r/R, with R = 1) and the legend.
void drawKernels(const std::string& path) {
  const int W = 1560, H = 560, top = 50, bottom = 480;
  Canvas c(W, H);
  const Panel pw{80, top, 540, bottom, -0.25, 3.5};
  const Panel pd{600 + 20, top, 1060 + 20, bottom, -10.5, 0.75};
  const Panel pl{1100 + 40, top, 1540, bottom, -100, 100};
  drawFrame(c, pw, 0.5, "W R^2");
  drawFrame(c, pd, 1.0, "dW/dr R^3");
  drawFrame(c, pl, 20.0, "lap W R^4");
  // The viscosity kernel's Laplacian clamp, rMin = 0.05 R (dashed).
  c.line(pl.px(0.05), pl.y0, pl.px(0.05), pl.y1, kVisc, 1, 4);

  const Poly6<double> poly6(1.0);
  const Spiky<double> spiky(1.0);
  const ViscosityKernel<double> visc(1.0);
  const CubicSpline<double> cubic(1.0);
  const WendlandC2<double> wendland(1.0);
  const auto plot = [&](const auto& k, Rgb col) {
    drawCurve(c, pw, col, [&](double q) { return k.value(q); });
    drawCurve(c, pd, col, [&](double q) { return k.derivative(q); });
    drawCurve(c, pl, col, [&](double q) { return k.laplacian(q); });
  };
  plot(poly6, kPoly6);
  plot(spiky, kSpiky);
  plot(visc, kVisc);
  plot(cubic, kCubic);
  plot(wendland, kWendland);

  // Legend: a box and the name of each kernel, top right of the first panel.
  int y = top + 12;
  const Rgb cols[5] = {kPoly6, kSpiky, kVisc, kCubic, kWendland};
  const char* names[5] = {"poly6", "spiky", "viscosity", "cubic", "wendland C2"};
  for (int i = 0; i < 5; ++i) {
    c.fill(pw.x1 - 200, y, pw.x1 - 160, y + 13, cols[i]);
    text(c, pw.x1 - 150, y, names[i], Rgb{0, 0, 0}, 2);
    y += 24;
  }
  writePngAtomic(path, W, H, c.px.data(), 6);
}

/// "1.23e-03 (2.00)": an error and its observed order against the previous row.
std::string cell(double e, const study::Errors* prev, double study::Errors::*m, double dx) {
  char buf[64];
  if (std::isnan(e)) return "—";
  if (prev)
    std::snprintf(buf, sizeof buf, "%.2e (%.2f)", e, study::order(prev->*m, prev->dx, e, dx));
  else
    std::snprintf(buf, sizeof buf, "%.2e", e);
  return buf;
}

template <class K>
void tableRows(double jitter) {
  const study::Errors* prev = nullptr;
  study::Errors rows[4];
  const int ns[4] = {40, 80, 160, 320};
  for (int r = 0; r < 4; ++r) {
    rows[r] = study::measure<K>(ns[r], 3.0, jitter);
    const study::Errors& e = rows[r];
    std::printf("| %s | %d | %s | %s | %s | %s | %s | %s | %s | %s |\n", K::name, ns[r],
                cell(e.sample, prev, &study::Errors::sample, e.dx).c_str(),
                cell(e.shepard, prev, &study::Errors::shepard, e.dx).c_str(),
                cell(e.gradient, prev, &study::Errors::gradient, e.dx).c_str(),
                cell(e.gradientSym, prev, &study::Errors::gradientSym, e.dx).c_str(),
                cell(e.gradientCorr, prev, &study::Errors::gradientCorr, e.dx).c_str(),
                cell(e.laplacian, prev, &study::Errors::laplacian, e.dx).c_str(),
                cell(e.laplacianBrook, prev, &study::Errors::laplacianBrook, e.dx).c_str(),
                cell(e.laplacianNorm, prev, &study::Errors::laplacianNorm, e.dx).c_str());
    prev = &rows[r];
  }
}

void table(double jitter) {
  std::printf(
      "| kernel | n | sample | Shepard | ∇ difference | ∇ symmetric | ∇ corrected | ∇² kernel | ∇² Brookshaw | ∇² renormalised |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  tableRows<Poly6<double>>(jitter);
  tableRows<Spiky<double>>(jitter);
  tableRows<ViscosityKernel<double>>(jitter);
  tableRows<CubicSpline<double>>(jitter);
  tableRows<WendlandC2<double>>(jitter);
}

}  // namespace

int main(int argc, char** argv) {
  std::string png = "docs/images/kernels.png";
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--png") && i + 1 < argc) {
      png = argv[++i];
    } else if (!std::strcmp(argv[i], "--no-png")) {
      png.clear();
    } else {
      std::fprintf(stderr, "usage: sph2d_kernel_report [--png PATH | --no-png]\n");
      return 2;
    }
  }
  try {
    if (!png.empty()) {
      drawKernels(png);
      std::fprintf(stderr, "wrote %s\n", png.c_str());
    }
    std::printf(
        "Max-norm error (observed order against the row above) of A = sin(3x + 0.5) cos(2y − 0.3) on [0, 2]²,\n");
    std::printf("n × n particles (dx = 2/n, volume dx², R = 3 dx), at points in [0.5, 1.5]².\n\n");
    std::printf("Regular lattice:\n\n");
    table(0.0);
    std::printf("\nJittered lattice (each particle moved by up to ±0.1 dx per axis, seed 7):\n\n");
    table(0.1);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sph2d_kernel_report: %s\n", e.what());
    return 1;
  }
  return 0;
}
