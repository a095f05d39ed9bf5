// The substep of the equation-of-state solvers (muller2003, wcsph): the
// stages they share around their own density, pressure and force.
#include "solvers/solver.hpp"

namespace sph2d {

std::vector<Stage> explicitStages(Stage::Fn density, std::function<void(StepContext&)> pressure, Stage::Fn pressureForce) {
  return {plainStage("grid", [](StepContext& c) { stageGrid(c, reorderThisStep(c)); }),
          plainStage("neighbours", [](StepContext& c) { stageNeighbours(c); }),
          Stage{"density", std::move(density)},
          plainStage("pressure", std::move(pressure)),
          Stage{"pressure_force", std::move(pressureForce)},
          Stage::effects(),
          Stage{"integrate", [](StepContext& c) { return stageIntegrate(c); }}};
}

}  // namespace sph2d
