// The substep of the equation-of-state solvers (muller2003, wcsph): the
// stages they share around their own density, pressure and force.
//
// force_limit, the last stage before integrate: the World sized this substep
// from the previous substep's largest acceleration (Monaghan 1992's force
// condition, dt ≤ kForceCfl·sqrt(R/a_max)); when a force jumps within one
// substep (a surface particle pulled onto its neighbour by tension, an
// overlap), the explicit step would turn that jump into speed. The forces of
// these solvers are those of the substep's start and do not depend on dt, so
// the stage shortens this substep to the limit of its own accelerations; the
// World advances its clock by the substep actually taken (stepper.cpp).
// Issue 18, hard case 11 (docs/STABILITY.md): a freely strained drop with
// tension gained 7× its kinetic energy without it.
#include <cmath>

#include "core/constants.hpp"
#include "solvers/solver.hpp"
#include "step/stages.hpp"

namespace sph2d {

namespace {

/// Shortens c.dt to kForceCfl·sqrt(R/a_max) of this substep's accelerations when that is shorter.
void limitStepByForce(StepContext& c) {
  const Real amax = maxAccelOf(c.P, c.pool);
  c.accelMeasured = amax;  // integrate, the last of these stages, leaves a as it is
  if (!(amax > 0)) return;
  const Real limit = kForceCfl * std::sqrt(c.R / amax);
  if (limit < c.dt) c.dt = limit;
}

}  // namespace

std::vector<Stage> explicitStages(Stage::Fn density, std::function<void(StepContext&)> pressure,
                                  Stage::Fn pressureForce) {
  // Density, pressure, the pressure force and integrate write these for every particle before
  // anything reads them (p stays: a bad density reports each particle's last pressure).
  constexpr unsigned kRewritten = kRewritesRho | kRewritesInvRho | kRewritesPOverRho | kRewritesA | kRewritesXPrev;
  return {plainStage("grid", [](StepContext& c) { stageGrid(c, reorderThisStep(c), kRewritten); }),
          plainStage("neighbours", [](StepContext& c) { stageNeighbours(c); }),
          Stage{"density", std::move(density)},
          plainStage("pressure", std::move(pressure)),
          Stage{"pressure_force", std::move(pressureForce)},
          Stage::effects(),
          plainStage("force_limit", limitStepByForce),
          Stage{"integrate", [](StepContext& c) { return stageIntegrate(c); }}};
}

}  // namespace sph2d
