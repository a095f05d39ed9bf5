// pbf_groups.cpp — elastic particle groups under corrections that move positions only (the
// game solver: pbf.hpp, ownVel_). A jelly's particles take their own position corrections into
// velocity (the World's groups stage adds them, after the collisions: Solver::groupMoves): the
// pairs within elastic groups, the walls, the sweeps out of the solids. What its
// pairs with the liquid (and rigid groups) move stays a move of positions on both sides, and the
// grid's compression shift leaves them where they are. Momentum: each pair's two moves are
// opposite (equal masses over the inverse mass ratios), so a jelly's pairs among themselves
// add up to nothing (but in the local iterations, where a listed particle moves and its
// unlisted neighbour does not), and the liquid exchanges momentum with a jelly through the
// grid projection, as with itself. "Own" pairs are those with any elastic group's particle
// (two jellies touching push each other by velocity); a rigid group's particles count as
// the liquid's. The prediction's sweep out of the solids is left to the collide stage. Sums per particle, each by its
// own block: the same bits for any thread count.
#include "solvers/pbf/pbf.hpp"

namespace sph2d {

void Pbf::markElastic(const StepContext& c) {
  ownVel_.clear();
  if (!groupCorrections()) return;
  const std::vector<Real>* stiffness = c.P.find(ParticleStore::kGroupStiffness);
  const std::vector<std::uint32_t>* group = c.P.findU32(ParticleStore::kGroup);
  if (!stiffness || !group) return;
  const std::size_t n = c.P.size();
  bool any = false;
  for (std::size_t i = 0; i < n && !any; ++i) any = (*group)[i] && (*stiffness)[i] > 0 && (*stiffness)[i] < 1;
  if (!any) return;
  ownVel_.resize(n);
  c.pool.parallelFor(n, kStreamBlock, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i)
      ownVel_[i] = std::uint8_t((*group)[i] && (*stiffness)[i] > 0 && (*stiffness)[i] < 1);
  });
}

void Pbf::startElastic(const StepContext& c) {
  markElastic(c);
  if (ownVel_.empty()) return;
  for (std::vector<Vec2>* v : {&cross_, &crossOld_, &crossNew_}) v->assign(c.P.size(), Vec2::Zero());
  xStart_.assign(c.P.x.begin(), c.P.x.end());
}

void Pbf::ownMoves(const StepContext& c) {
  const Real k = Real(1) - toVelocity_;
  c.pool.parallelFor(c.P.size(), kStreamBlock, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i)
      cross_[i] = ownVel_[i] ? Vec2((c.P.x[i] - xStart_[i] - cross_[i]) * k) : Vec2::Zero();
  });
}

}  // namespace sph2d
