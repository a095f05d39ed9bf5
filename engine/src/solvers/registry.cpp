// The solvers a scene can name.
#include <stdexcept>
#include <string>

#include "solvers/solver.hpp"

namespace sph2d {

std::unique_ptr<Solver> makeMuller2003();

const std::vector<std::string>& solverNames() {
  static const std::vector<std::string> names = {"muller2003"};
  return names;
}

std::unique_ptr<Solver> makeSolver(const SolverDef& def) {
  if (def.type == "muller2003") return makeMuller2003();
  throw std::invalid_argument("unknown solver '" + def.type + "'");
}

}  // namespace sph2d
