// The stage list's dispatcher: runs, times and guards the stages by index.
#include "step/stage_list.hpp"

#include <chrono>
#include <stdexcept>

namespace sph2d {

void StageList::clear() {
  stages_.clear();
  timingOf_.clear();
}

void StageList::add(Stage s) {
  if (s.effectsMarker || s.velocityMarker || !s.run)
    throw std::logic_error("StageList::add: stage '" + s.name + "' has no work");
  std::size_t k = 0;
  while (k < timing_.size() && timing_[k].name != s.name) ++k;
  if (k == timing_.size()) timing_.push_back(StageTiming{s.name, 0, 0});
  timingOf_.push_back(k);
  stages_.push_back(std::move(s));
}

void StageList::run(StepContext& c, const Fail& fail, const std::atomic<bool>* stop) {
  using Clock = std::chrono::steady_clock;
  for (std::size_t k = 0; k < stages_.size(); ++k) {
    if (stop && stop->load(std::memory_order_relaxed)) throw Interrupted("stopped by the stop flag", stages_[k].name);
    const auto t0 = Clock::now();
    std::size_t bad = kNone;
    try {
      bad = stages_[k].run(c);
    } catch (const Interrupted& e) {
      if (!e.stage.empty()) throw;
      throw Interrupted(e.what(), stages_[k].name);  // the job system stopped inside this stage
    }
    StageTiming& t = timing_[timingOf_[k]];
    t.seconds += std::chrono::duration<double>(Clock::now() - t0).count();
    ++t.calls;
    if (bad != kNone) fail(stages_[k].name, bad);
  }
}

void StageList::resetTimings() {
  for (StageTiming& t : timing_) {
    t.seconds = 0;
    t.calls = 0;
  }
}

}  // namespace sph2d
