// range_message.hpp (internal) — how a number appears in a message, and the message of a
// value outside its range: the scene loader's (scene_reader.cpp) and the World's check of a
// solver built in code (solvers/registry.cpp) say the same words.
#pragma once

#include <cmath>
#include <sstream>
#include <string>

namespace sph2d {

/// A number as messages write it: integral values without a decimal point, others as
/// std::ostream writes a double (6 significant digits).
inline std::string fmt(double v) {
  if (v == std::floor(v) && std::fabs(v) < 1e15) return std::to_string(static_cast<long long>(v));
  std::ostringstream o;
  o << v;
  return o.str();
}

/// "" when v is finite and within [lo, hi] ((lo, hi] when loOpen); else the message a key
/// outside its range fails with: "value V is out of range; allowed: >= lo and <= hi".
inline std::string rangeProblem(double v, double lo, double hi, bool loOpen) {
  const bool below = loOpen ? !(v > lo) : !(v >= lo);
  if (std::isfinite(v) && !below && !(v > hi)) return "";
  return "value " + fmt(v) + " is out of range; allowed: " + (loOpen ? "> " : ">= ") + fmt(lo) + " and <= " + fmt(hi);
}

}  // namespace sph2d
