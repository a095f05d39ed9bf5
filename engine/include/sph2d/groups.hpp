// sph2d/groups.hpp — particle groups: a set of particles made together that moves as one
// rigid body (stiffness 1) or springs back towards its shape (a jelly: stiffness below 1),
// by shape matching (Müller, Heidelberger, Teschner & Gross 2005, "Meshless deformations
// based on shape matching"). World::createGroup, World::groupState, World::applyGroupImpulse.
#pragma once

#include <cstddef>
#include <cstdint>

#include "sph2d/fluid_block.hpp"
#include "sph2d/math.hpp"

namespace sph2d {

/// A group to make: its particles fill `region` (on the lattice of the spacing, as addBlock
/// does; its material and velocity too).
struct GroupDef {
  FluidBlockDef region;
  /// The share of the way to the best-fit rigid placement of its rest shape each particle
  /// goes per substep: 1 a rigid body, below 1 an elastic one (0 < stiffness ≤ 1).
  double stiffness = 1;
  /// Elastic only: the strain beyond which it yields (plastic): a particle farther from its
  /// place than this times its rest distance from the centre (at least a spacing) moves its
  /// place in the rest shape by the excess, at most half a spacing a substep (a flow: taken at
  /// once, a hard landing crossed places and blew a stiff block up). 0: it always springs back.
  double yieldStrain = 0;
  /// Elastic only: the strain at which it breaks: after the substep, pairs of neighbours (in
  /// the rest shape, at most 1.5 spacings apart) stretched by more than this part are cut, and
  /// what stays connected becomes a group of its own (at least 3 particles; fewer go free as
  /// fluid). At most the support over 1.5 spacings, less 1 (0.33 on the game solver, whose
  /// support is 2 spacings). 0: it never breaks.
  double breakStrain = 0;
  /// The colour it is drawn in, 0xRRGGBB: its particles' own colour (World::setParticleColor),
  /// which the renderer's liquid mode fills the group's blob with (a darker outline round it)
  /// and the particles mode's `color` shows. 0: its material's colour (no colour field).
  std::uint32_t color = 0;
  /// A scene's elastic group without a stiffness of its own.
  static constexpr double kElasticStiffness = 0.25;
};

/// A group as it is now: its centre of mass, the rotation of its shape from when it was made,
/// and the velocity and spin of its particles' momentum.
struct GroupState {
  Vec2d centre{0, 0};
  double angle = 0;  ///< rad, counter-clockwise
  Vec2d velocity{0, 0};
  double angularVelocity = 0;  ///< rad/s
  double mass = 0;             ///< kg per metre of depth
  std::size_t particles = 0;
};

}  // namespace sph2d
