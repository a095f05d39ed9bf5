// stage_list.hpp (internal) — the substep as one explicit list of stages.
//
// The World builds the list once (and again when the user adds a force or
// switches an effect): the solver's stages in its order, the scene's enabled
// effects where the solver puts its effects marker, then the particle system
// (Box2D v3's solver stages, built in one place with one dispatcher). The
// list runs every stage in order, times each by its index and turns a bad
// particle a stage reports into the World's SimulationError. World::stages()
// and docs/ARCHITECTURE.md come from this list.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "sph2d/world.hpp"
#include "step/step_context.hpp"

namespace sph2d {

/// One stage of the substep: a named pass over the particles.
struct Stage {
  /// Runs the stage; returns the lowest slot with a non-finite or runaway value, or kNone.
  using Fn = std::function<std::size_t(StepContext&)>;
  std::string name;            ///< shown by --profile, World::stages() and the guard's errors
  Fn run;                      ///< the work (empty for the effects marker)
  bool effectsMarker = false;  ///< true: not a stage, the place in a solver's list where effects run
  /// True: not a stage, the place where the velocities are final and the positions have not
  /// moved yet (after the pressure): the effects that bound the flow run there (granular).
  bool velocityMarker = false;
  /// The marker a solver puts where the scene's effects run.
  static Stage effects() { return Stage{"", nullptr, true}; }
  /// The marker a solver puts where its velocities are final, before the move; `pressure`
  /// (a stage named "pressure_now" when effects run there) brings P.p up to this substep.
  static Stage velocities(Fn pressure) { return Stage{"pressure_now", std::move(pressure), false, true}; }
};

/// Builds a stage that cannot find a bad particle.
inline Stage plainStage(std::string name, std::function<void(StepContext&)> f) {
  return Stage{std::move(name), [f = std::move(f)](StepContext& c) {
                 f(c);
                 return kNone;
               }};
}

/// The ordered stages of a substep, their timings, and the dispatcher.
class StageList {
 public:
  /// Called when a stage reports bad particle `slot`; must throw.
  using Fail = std::function<void(const std::string& stage, std::size_t slot)>;

  /// Empties the list (timings are kept by name).
  void clear();
  /// Appends a stage (not a marker).
  void add(Stage s);
  /// The stages, in order.
  const std::vector<Stage>& stages() const { return stages_; }
  /// Runs every stage in order, timing each; a stage that reports a bad slot calls `fail`.
  /// With `stop` set (the World's stop flag) it is read before each stage, and the job
  /// system reads it inside them: either way Interrupted is thrown naming the stage.
  void run(StepContext& c, const Fail& fail, const std::atomic<bool>* stop = nullptr);
  /// Wall time and calls per stage name, in the order names first entered the list.
  const std::vector<StageTiming>& timings() const { return timing_; }
  /// Zeroes the timings.
  void resetTimings();

 private:
  std::vector<Stage> stages_;
  std::vector<std::size_t> timingOf_;  ///< per stage: its entry in timing_
  std::vector<StageTiming> timing_;    ///< per name, kept across rebuilds
};

}  // namespace sph2d
