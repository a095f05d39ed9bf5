// depth_grid.cpp — the liquid's coarse CPU grid (see depth_grid.hpp for the design).
#include "depth_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace sph2d {

bool DepthGrid::resize(int EW, int EH, double spacingPx) {
  const int cell = std::max(4, int(std::ceil(spacingPx)));
  const int w = (EW + cell - 1) / cell, h = (EH + cell - 1) / cell;
  if (w == w_ && h == h_ && cell == cell_) return false;
  w_ = w;
  h_ = h;
  cell_ = cell;
  solidsStale_ = true;
  return true;
}

void DepthGrid::buildSolidMask(const RenderInput& in, double x0, double y1, double cellM) {
  // Cells whose centre lies inside a collider (segments: within half a cell of it). The
  // colliders are static, so this runs when the grid or the camera changes.
  solid_.assign(std::size_t(w_) * std::size_t(h_), 0);
  solidsStale_ = false;
  if (!in.colliders) return;
  for (const Collider& c : *in.colliders) {
    const double pad = c.kind == Collider::Kind::Segment ? 0.5 * cellM : 0.0;
    // Cells whose centre can lie in the collider's bounding box (grid rows run top-down).
    const int ix0 = std::max(0, int(std::floor((c.lo.x() - pad - x0) / cellM - 0.5)));
    const int ix1 = std::min(w_ - 1, int(std::ceil((c.hi.x() + pad - x0) / cellM - 0.5)));
    const int iy0 = std::max(0, int(std::floor((y1 - c.hi.y() - pad) / cellM - 0.5)));
    const int iy1 = std::min(h_ - 1, int(std::ceil((y1 - c.lo.y() + pad) / cellM - 0.5)));
    for (int iy = iy0; iy <= iy1; ++iy)
      for (int ix = ix0; ix <= ix1; ++ix) {
        const Vec2d p(x0 + (ix + 0.5) * cellM, y1 - (iy + 0.5) * cellM);
        bool inside = true;
        if (c.kind == Collider::Kind::Polygon) {
          for (std::size_t k = 0; k < c.vertices.size() && inside; ++k)
            inside = c.normals[k].cast<double>().dot(p - c.vertices[k].cast<double>()) <= 0.0;
        } else if (c.kind == Collider::Kind::Circle) {
          inside = (p - c.center.cast<double>()).squaredNorm() <= double(c.radius) * double(c.radius);
        } else {
          const Vec2d a = c.vertices[0].cast<double>(), b = c.vertices[1].cast<double>(), ab = b - a;
          const double t = ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
          inside = (p - (a + t * ab)).norm() <= pad;
        }
        if (inside) solid_[std::size_t(iy) * std::size_t(w_) + std::size_t(ix)] = 1;
      }
  }
}

void DepthGrid::deposit(const RenderInput& in, const std::vector<std::uint32_t>& order, const float* weight, double x0,
                        double y1, double cellM, float areaShare, std::vector<float>& out) const {
  const int w = w_, h = h_;
  out.assign(std::size_t(w) * std::size_t(h), 0.0f);
  const Particles& P = in.particles;
  // Cloud-in-cell deposit (bilinear weights): no aliasing between the lattice and the cells.
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::size_t i = order[k];
    const double cx = (double(P.x[i].x()) - x0) / cellM - 0.5, cy = (y1 - double(P.x[i].y())) / cellM - 0.5;
    if (!(cx > -1 && cy > -1 && cx < w && cy < h)) continue;
    const int ix = int(std::floor(cx)), iy = int(std::floor(cy));
    const float tx = float(cx - ix), ty = float(cy - iy);
    const float m = areaShare * weight[k];
    const float wgt[4] = {(1 - tx) * (1 - ty) * m, tx * (1 - ty) * m, (1 - tx) * ty * m, tx * ty * m};
    for (int q = 0; q < 4; ++q) {
      const int xx = ix + (q & 1), yy = iy + (q >> 1);
      if (xx >= 0 && yy >= 0 && xx < w && yy < h) out[std::size_t(yy) * std::size_t(w) + std::size_t(xx)] += wgt[q];
    }
  }
  for (float& c : out) c = std::min(c, 1.0f);
}

void DepthGrid::localFill(const std::vector<float>& cover, float* out, std::size_t stride) const {
  // The 3×3 mean of the coverage (inside without bounds checks, same order).
  const int w = w_, h = h_;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float s = 0;
      int n = 0;
      if (y > 0 && x > 0 && y + 1 < h && x + 1 < w) {
        for (int dy = -1; dy <= 1; ++dy) {
          const float* c = &cover[std::size_t(y + dy) * std::size_t(w) + std::size_t(x - 1)];
          s += c[0];
          s += c[1];
          s += c[2];
        }
        n = 9;
      } else {
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx, yy = y + dy;
            if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
            s += cover[std::size_t(yy) * std::size_t(w) + std::size_t(xx)];
            ++n;
          }
      }
      out[(std::size_t(y) * std::size_t(w) + std::size_t(x)) * stride] = s / float(n);
    }
}

void DepthGrid::build(const RenderInput& in, const std::vector<double>& ext, double pxPerM,
                      const std::vector<std::uint32_t>& order, const std::vector<float>& weight,
                      const std::vector<float>* liquidWeight) {
  const double spacingPx = in.spacing * pxPerM;
  const int w = w_, h = h_, cell = cell_;
  const double cellM = cell / pxPerM;
  const double x0 = ext[0] - in.origin.x(), y1 = ext[3] - in.origin.y();
  const float areaShare = float((spacingPx * spacingPx) / (double(cell) * double(cell)));
  deposit(in, order, weight.data(), x0, y1, cellM, areaShare, cover_);
  if (solidsStale_) buildSolidMask(in, x0, y1, cellM);
  aux_.assign(std::size_t(w) * std::size_t(h) * 2, 0.0f);
  // Depth of water above, with the light scattered sideways as it goes down: row by row from
  // the top, the depth carried into a row is the row above's, blurred along the row by a
  // binomial kernel [1 4 6 4 1]/16 (variance one cell² per row) over the cells that are not
  // solid. A step in depth between neighbouring columns (under a bump, at the foot of a
  // splash) thus widens like a diffusion, about sqrt(rows below the step) cells, instead of
  // running down as a vertical seam; solids neither pass light nor lend their depth of zero
  // to the water beside them (a wall would otherwise light the water along it).
  // The row buffers carry two cells of zero-weight padding on each side: the kernel's taps
  // need no bounds checks, and a masked tap adds exactly +0 to both sums.
  carry_.assign(std::size_t(w) + 4, 0.0f);
  above_.assign(std::size_t(w) + 4, 0.0f);
  open_.assign(std::size_t(w) + 4, 0.0f);
  static const float kBlur[5] = {1.0f / 16, 4.0f / 16, 6.0f / 16, 4.0f / 16, 1.0f / 16};
  float* carry = carry_.data() + 2;
  float* above = above_.data() + 2;
  float* open = open_.data() + 2;  // 1 where the cell is not solid, 0 where it is and outside
  for (int y = 0; y < h; ++y) {
    const std::size_t row = std::size_t(y) * std::size_t(w);
    for (int x = 0; x < w; ++x) {
      const float c = cover_[row + std::size_t(x)];
      aux_[(row + std::size_t(x)) * 2] = float((carry[x] + 0.5f * c) * cellM);
      carry[x] += c;
      open[x] = solid_[row + std::size_t(x)] ? 0.0f : 1.0f;
    }
    for (int x = 0; x < w; ++x) {
      float s = 0, n = 0;
      for (int d = -2; d <= 2; ++d) {
        const float k = kBlur[d + 2] * open[x + d];
        s += k * carry[x + d];
        n += k;
      }
      above[x] = n > 0 ? s / n : carry[x];
    }
    std::swap(carry, above);
  }
  localFill(cover_, aux_.data() + 1, 2);
  // The water's own fill, for the deep cells (tiles()): grains and groups' particles add nothing
  // to the field, so a sand pile is no deep water.
  liquidFill_.clear();
  if (liquidWeight) {
    deposit(in, order, liquidWeight->data(), x0, y1, cellM, areaShare, liquidCover_);
    liquidFill_.resize(std::size_t(w) * std::size_t(h));
    localFill(liquidCover_, liquidFill_.data(), 1);
  }
}

namespace {
/// `a` becomes the window test over ±`reach` cells of each cell, along rows, then along columns
/// (running counts; `tmp` and `count` are scratch): the cells whose window holds a set cell, or
/// (`all`) whose whole window is set, cells beyond the grid counting as unset. The column pass
/// runs row by row with a count per column, so that it reads the grid in order.
void windowTest(std::vector<std::uint8_t>& a, std::vector<std::uint8_t>& tmp, std::vector<int>& count, int w, int h,
                int reach, bool all) {
  tmp.resize(a.size());
  const int need = all ? 2 * reach + 1 : 1;
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* r = &a[std::size_t(y) * std::size_t(w)];
    std::uint8_t* o = &tmp[std::size_t(y) * std::size_t(w)];
    int n = 0;
    for (int x = 0; x < std::min(reach, w); ++x) n += r[x];
    for (int x = 0; x < w; ++x) {
      if (x + reach < w) n += r[x + reach];
      if (x - reach - 1 >= 0) n -= r[x - reach - 1];
      o[x] = n >= need;
    }
  }
  count.assign(std::size_t(w), 0);
  int* n = count.data();
  for (int y = 0; y < std::min(reach, h); ++y) {
    const std::uint8_t* r = &tmp[std::size_t(y) * std::size_t(w)];
    for (int x = 0; x < w; ++x) n[x] += r[x];
  }
  for (int y = 0; y < h; ++y) {
    if (y + reach < h) {
      const std::uint8_t* r = &tmp[std::size_t(y + reach) * std::size_t(w)];
      for (int x = 0; x < w; ++x) n[x] += r[x];
    }
    if (y - reach - 1 >= 0) {
      const std::uint8_t* r = &tmp[std::size_t(y - reach - 1) * std::size_t(w)];
      for (int x = 0; x < w; ++x) n[x] -= r[x];
    }
    std::uint8_t* o = &a[std::size_t(y) * std::size_t(w)];
    for (int x = 0; x < w; ++x) o[x] = n[x] >= need;
  }
}
}  // namespace

void DepthGrid::markVisible(const float* rg, int tw, int th, int EW, int EH, float tapPx, float bulk) {
  // One bit per texel above the limit, 64 to a word, a row of words per texel row.
  const float limit = 0.98f * (0.24f - 0.0005f) / (1.0f + 0.3536f / tapPx) * bulk;
  field_ = FieldBits{tw, th, float(tw) / float(EW), float(th) / float(EH), tapPx, (tw + 63) / 64};
  hot_.assign(std::size_t(th) * std::size_t(field_.words), 0);
  for (int y = 0; y < th; ++y) {
    const float* row = rg + std::size_t(y) * std::size_t(tw) * 2;
    std::uint64_t* bits = &hot_[std::size_t(y) * std::size_t(field_.words)];
    for (int x0 = 0; x0 < tw; x0 += 64) {
      std::uint64_t word = 0;
      const int n = std::min(64, tw - x0);
      for (int k = 0; k < n; ++k) word |= std::uint64_t(row[2 * (x0 + k)] > limit) << k;
      bits[x0 / 64] = word;
    }
  }
}

void DepthGrid::keepVisible(std::uint8_t* row, int cy) {
  // The texels the samples of a cell's pixels read: the pixels' centres ± tapPx, bilinear (a
  // sample at x px reads texels ⌊x·w/EW − 0.5⌋ and the next: the texture spans the target),
  // clamped to the edge. The field's rows the cell row reads are joined (or) into one, then
  // each cell tests its columns.
  const FieldBits& F = field_;
  auto first = [&](int p0, int n, float scale) {
    return std::clamp(int(std::floor((float(p0) + 0.5f - F.tapPx) * scale - 0.5f)), 0, n - 1);
  };
  auto last = [&](int p1, int n, float scale) {
    return std::clamp(int(std::floor((float(p1) - 0.5f + F.tapPx) * scale - 0.5f)) + 1, 0, n - 1);
  };
  if (F.w < 1 || F.h < 1) {
    std::fill(row, row + w_, std::uint8_t(0));
    return;
  }
  joined_.assign(std::size_t(F.words), 0);
  for (int y = first(cy * cell_, F.h, F.sy), y1 = last((cy + 1) * cell_, F.h, F.sy); y <= y1; ++y) {
    const std::uint64_t* bits = &hot_[std::size_t(y) * std::size_t(F.words)];
    for (int wd = 0; wd < F.words; ++wd) joined_[std::size_t(wd)] |= bits[wd];
  }
  for (int cx = 0; cx < w_; ++cx) {
    if (!row[cx]) continue;
    const int x0 = first(cx * cell_, F.w, F.sx), x1 = last((cx + 1) * cell_, F.w, F.sx);
    bool any = false;
    for (int wd = x0 / 64; wd <= x1 / 64 && !any; ++wd) {
      std::uint64_t m = joined_[std::size_t(wd)];
      if (wd == x0 / 64) m &= ~std::uint64_t(0) << (x0 % 64);
      if (wd == x1 / 64 && x1 % 64 < 63) m &= (std::uint64_t(1) << (x1 % 64 + 1)) - 1;
      any = m != 0;
    }
    row[cx] = any;
  }
}

std::pair<int, int> DepthGrid::tiles(float spriteRadiusPx, int EW, int EH, std::vector<float>& out,
                                     std::size_t& interiorFirst, bool onlyVisible) {
  const int w = w_, h = h_;
  const int reach = int(std::ceil((spriteRadiusPx + 1.0f) / float(cell_)));
  // Reachable: cells with water, dilated by `reach` cells. Deep: cells whose neighbours as far
  // as `reach` all hold water (a local fill of kFull or more) and none is solid; their fill
  // becomes kDeepFill (at most 1 elsewhere). Interior: deep cells
  // whose eight neighbours are deep too, so that the fill sampled anywhere over them is kDeepFill.
  const std::size_t cells = std::size_t(w) * std::size_t(h);
  active_.resize(cells);
  full_.resize(cells);
  {
    const float* cover = cover_.data();
    const float* aux = aux_.data();
    const float* liquid = liquidFill_.empty() ? nullptr : liquidFill_.data();
    const std::uint8_t* solid = solid_.data();
    std::uint8_t* a = active_.data();
    std::uint8_t* fu = full_.data();
    for (std::size_t k = 0; k < cells; ++k) {
      a[k] = cover[k] > 0.0f;
      fu[k] = ((liquid ? liquid[k] : aux[2 * k + 1]) >= kFull) & !solid[k];
    }
  }
  windowTest(active_, activeTmp_, count_, w, h, reach, false);
  // The next cell of `row` (w cells) at or after x holding v, or w (memchr: most rows are empty).
  auto next = [w](const std::uint8_t* row, int x, std::uint8_t v) {
    const void* p = std::memchr(row + x, v, std::size_t(w - x));
    return p ? int(static_cast<const std::uint8_t*>(p) - row) : w;
  };
  if (onlyVisible)
    for (int y = 0; y < h; ++y) {
      std::uint8_t* row = &active_[std::size_t(y) * std::size_t(w)];
      if (next(row, 0, 1) < w) keepVisible(row, y);
    }
  windowTest(full_, activeTmp_, count_, w, h, reach, true);
  for (std::size_t k = 0; k < cells; ++k) aux_[2 * k + 1] = full_[k] ? kDeepFill : aux_[2 * k + 1];
  windowTest(full_, activeTmp_, count_, w, h, 1, true);
  // Each cell's kind (0: no tile, 1: the full program's, 2: interior) into activeTmp_, then the
  // runs of kind 1 in each row, then those of kind 2.
  std::uint8_t* kind = activeTmp_.data();
  for (std::size_t k = 0; k < cells; ++k) kind[k] = std::uint8_t(active_[k] * (1 + full_[k]));
  out.clear();
  int rowFirst = h, rowLast = -1;
  auto ndcX = [&](int px) { return float(std::min(px, EW)) / float(EW) * 2.0f - 1.0f; };
  auto ndcY = [&](int py) { return float(std::min(py, EH)) / float(EH) * 2.0f - 1.0f; };
  for (std::uint8_t pass = 1; pass <= 2; ++pass) {
    if (pass == 2) interiorFirst = out.size() / 2;
    for (int y = 0; y < h; ++y) {
      const std::uint8_t* row = kind + std::size_t(y) * std::size_t(w);
      for (int x = next(row, 0, pass); x < w; x = next(row, x, pass)) {
        int e = x;
        while (e < w && row[e] == pass) ++e;
        const float x0 = ndcX(x * cell_), x1 = ndcX(e * cell_), y0 = ndcY(y * cell_), y1 = ndcY((y + 1) * cell_);
        const float q[12] = {x0, y0, x1, y0, x0, y1, x0, y1, x1, y0, x1, y1};
        out.insert(out.end(), q, q + 12);
        rowFirst = std::min(rowFirst, y);
        rowLast = std::max(rowLast, y);
        x = e;
      }
    }
  }
  if (rowLast < 0) return {0, 0};
  return {std::min(rowFirst * cell_, EH), std::min((rowLast + 1) * cell_, EH)};
}

}  // namespace sph2d
