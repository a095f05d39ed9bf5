// particle_index.cpp — the World's lookups by id and by region (particle_index.hpp).
#include "world/particle_index.hpp"

namespace sph2d {

std::size_t ParticleIndex::slotOf(const ParticleStore& P, std::uint32_t id) const {
  const std::size_t slot = findId(id);
  if (slot < P.size() && P.id[slot] == id) return slot;
  // Stale (the slot moved, or the id is absent, perhaps because it is newer than the
  // index): rebuild, then the answer is exact.
  rebuildIds(P);
  return findId(id);
}

void ParticleIndex::rebuildIds(const ParticleStore& P) const {
  ids_.resize(P.size());
  for (std::size_t i = 0; i < P.size(); ++i) ids_[i] = {P.id[i], std::uint32_t(i)};
  std::sort(ids_.begin(), ids_.end());
}

std::size_t ParticleIndex::findId(std::uint32_t id) const {
  const auto it = std::lower_bound(ids_.begin(), ids_.end(), std::make_pair(id, std::uint32_t(0)));
  return it != ids_.end() && it->first == id ? std::size_t(it->second) : npos;
}

const ParticleIndex::Grid& ParticleIndex::grid(const ParticleStore& P, std::uint64_t steps, double cell) const {
  Grid& g = grid_;
  if (g.steps == steps && g.edits == edits_ && g.count == P.size()) return g;
  g.steps = steps;
  g.edits = edits_;
  g.count = P.size();
  g.nx = g.ny = 0;
  g.start.clear();
  g.items.clear();
  if (P.size() == 0) return g;
  double x0 = P.x[0].x(), y0 = P.x[0].y(), x1 = x0, y1 = y0;
  for (const Vec2& x : P.x) {
    x0 = std::min(x0, double(x.x()));
    x1 = std::max(x1, double(x.x()));
    y0 = std::min(y0, double(x.y()));
    y1 = std::max(y1, double(x.y()));
  }
  // Cells of the support radius, grown when spray makes the bounds huge (at most 4 cells a particle).
  g.h = cell;
  const double most = 4.0 * double(P.size()) + 64;
  while (((x1 - x0) / g.h + 1) * ((y1 - y0) / g.h + 1) > most) g.h *= 2;
  g.x0 = x0;
  g.y0 = y0;
  g.nx = long((x1 - x0) / g.h) + 1;
  g.ny = long((y1 - y0) / g.h) + 1;
  const std::size_t cells = std::size_t(g.nx * g.ny);
  std::vector<std::uint32_t> cellOf(P.size());
  g.start.assign(cells + 1, 0);
  for (std::size_t i = 0; i < P.size(); ++i) {
    const long ci = std::min(g.nx - 1, long((double(P.x[i].x()) - x0) / g.h));
    const long cj = std::min(g.ny - 1, long((double(P.x[i].y()) - y0) / g.h));
    cellOf[i] = std::uint32_t(cj * g.nx + ci);
    ++g.start[cellOf[i] + 1];
  }
  for (std::size_t k = 0; k < cells; ++k) g.start[k + 1] += g.start[k];
  g.items.resize(P.size());
  std::vector<std::uint32_t> fill(g.start.begin(), g.start.end() - 1);
  for (std::size_t i = 0; i < P.size(); ++i) g.items[fill[cellOf[i]]++] = std::uint32_t(i);  // slot order within a cell
  return g;
}

}  // namespace sph2d
