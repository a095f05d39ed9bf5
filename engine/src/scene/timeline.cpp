// timeline.cpp — the scene's timeline of events and their application to a World
// (sph2d/timeline.hpp): the schedule by frame, the applier that turns each event into
// one World call, and the player a game steps.
#include "sph2d/timeline.hpp"

#include <algorithm>
#include <iterator>
#include <sstream>
#include <stdexcept>

namespace sph2d {

void EventSchedule::insert(TimedEvent e) {
  // After every event of the same or an earlier frame: stable within a frame.
  const auto at = std::upper_bound(events_.begin(), events_.end(), e.frame,
                                   [](std::int64_t f, const TimedEvent& x) { return f < x.frame; });
  events_.insert(at, std::move(e));
}

void EventSchedule::addScene(const SceneDef& scene) {
  for (std::size_t k = 0; k < scene.events.size(); ++k) {
    TimedEvent t;
    t.event = scene.events[k];
    t.event.source = "scene";
    t.frame = eventFrame(t.event, scene.fps);
    t.where = (scene.path.empty() ? std::string("scene") : scene.path) + " events[" + std::to_string(k) + "]";
    insert(std::move(t));
  }
}

std::vector<TimedEvent> EventSchedule::take(std::int64_t frame) {
  std::vector<TimedEvent> out;
  std::size_t k = 0;
  while (k < events_.size() && events_[k].frame <= frame) ++k;
  out.assign(std::make_move_iterator(events_.begin()), std::make_move_iterator(events_.begin() + std::ptrdiff_t(k)));
  events_.erase(events_.begin(), events_.begin() + std::ptrdiff_t(k));
  return out;
}

std::string EventApplier::apply(World& w, const EventDef& e) {
  using T = EventDef::Type;
  try {
    switch (e.type) {
      case T::Force: {
        UserForce f;
        f.point = e.point;
        f.radius = e.radius;
        f.strength = e.strength;
        forces_[e.id] = f;
        break;
      }
      case T::Release:
        if (e.id < 0)
          forces_.clear();
        else
          forces_.erase(e.id);
        break;
      case T::Block: {
        FluidBlockDef b = e.block;
        b.material = e.material.empty() ? 0 : w.materialIndex(e.material);
        w.addBlock(b);
        break;
      }
      case T::Drop:
        w.addDrop(e.point, e.radius, e.velocity, e.material.empty() ? 0 : w.materialIndex(e.material));
        break;
      case T::Emitter:
        if (e.hasPoint || e.hasDirection) {
          const EmitterDef& cur = w.emitter(e.index);
          w.moveEmitter(e.index, e.hasPoint ? e.point : cur.position, e.hasDirection ? e.direction : cur.direction);
        }
        if (e.hasEnabled) w.setEmitterEnabled(e.index, e.enabled);
        break;
      case T::Gravity:
        w.setGravity(e.gravity);
        break;
      case T::Effect:
        w.setEffectEnabled(e.effect, e.enabled);
        break;
      case T::Pause:
        paused_ = true;
        pauseSeconds_ = e.seconds;
        break;
      case T::Resume:
        paused_ = false;
        break;
    }
    if (e.type == T::Force || e.type == T::Release) {
      std::vector<UserForce> list;
      for (const auto& f : forces_) list.push_back(f.second);
      w.setUserForces(list);
    }
  } catch (const Interrupted&) {
    throw;  // the World's stop flag: not a property of the event (nothing was added)
  } catch (const std::exception& ex) {
    return ex.what();
  }
  return "";
}

std::string describeEvent(const EventDef& e) {
  using T = EventDef::Type;
  std::ostringstream o;
  o.precision(4);
  auto v = [&](const Vec2d& p) {
    std::ostringstream s;
    s.precision(4);
    s << "(" << p.x() << ", " << p.y() << ")";
    return s.str();
  };
  o << eventTypeName(e.type);
  switch (e.type) {
    case T::Force:
      o << " " << e.id << " at " << v(e.point) << ", radius " << e.radius << " m, " << e.strength << " m/s²";
      break;
    case T::Release:
      o << (e.id < 0 ? " all forces" : " force " + std::to_string(e.id));
      break;
    case T::Block:
      o << " " << v(e.block.min) << " – " << v(e.block.max);
      break;
    case T::Drop:
      o << " at " << v(e.point) << ", radius " << e.radius << " m";
      break;
    case T::Emitter:
      o << " " << e.index;
      if (e.hasEnabled) o << (e.enabled ? " on" : " off");
      if (e.hasPoint) o << " at " << v(e.point);
      if (e.hasDirection) o << " towards " << v(e.direction);
      break;
    case T::Gravity:
      o << " " << v(e.gravity) << " m/s²";
      break;
    case T::Effect:
      o << " " << e.effect << (e.enabled ? " on" : " off");
      break;
    case T::Pause:
      if (e.seconds > 0) o << " " << e.seconds << " s";
      break;
    case T::Resume:
      break;
  }
  return o.str();
}

TimelinePlayer::TimelinePlayer(const SceneDef& scene) { schedule_.addScene(scene); }

void TimelinePlayer::add(std::int64_t frame, const EventDef& e, const std::string& where) {
  TimedEvent t;
  t.frame = frame;
  t.event = e;
  if (t.event.source.empty()) t.event.source = "game";
  t.where = where;
  schedule_.add(std::move(t));
}

std::vector<std::string> TimelinePlayer::stepFrame(World& world) {
  std::vector<std::string> failed;
  for (const TimedEvent& t : schedule_.take(std::int64_t(world.frame()))) {
    const std::string why = applier_.apply(world, t.event);
    if (!why.empty()) failed.push_back(t.where + ": " + describeEvent(t.event) + " not applied: " + why);
  }
  if (!applier_.paused()) world.stepFrame();
  return failed;
}

}  // namespace sph2d
