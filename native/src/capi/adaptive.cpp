#include "capi/adaptive.h"

#include "cloth/garment_sim.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace drape {

std::string validate(const PipelineOptions& o, bool* nonfinite) {
  std::ostringstream s;
  auto range = [&](const char* name, float v, float lo, float hi) {
    if (!s.str().empty()) return;
    if (!std::isfinite(v)) {
      s << name << " is not finite";
      if (nonfinite) *nonfinite = true;
    } else if (v < lo || v > hi) {
      s << name << " = " << v << " is outside [" << lo << ", " << hi << "]";
    }
  };
  range("sleep_delay_s", o.sleep_delay_s, 0.0f, 60.0f);
  range("sleep_distance_m", o.sleep_distance_m, 0.0f, 1.0f);
  range("sleep_speed_m_s", o.sleep_speed_m_s, 0.0f, 10.0f);
  range("reach_margin_m", o.reach_margin_m, 0.0f, 2.0f);
  return s.str();
}

AdaptiveState::Garment* AdaptiveState::find(const GarmentSim* g) {
  for (Garment& s : garments_)
    if (s.g == g) return &s;
  return nullptr;
}

const AdaptiveState::Garment* AdaptiveState::find(const GarmentSim* g) const {
  for (const Garment& s : garments_)
    if (s.g == g) return &s;
  return nullptr;
}

void AdaptiveState::addGarment(const GarmentSim* g, std::vector<ReachSphere> reach) {
  Garment s;
  s.g = g;
  s.reach = std::move(reach);
  garments_.push_back(std::move(s));
}

void AdaptiveState::removeGarment(const GarmentSim* g) {
  garments_.erase(std::remove_if(garments_.begin(), garments_.end(), [&](const Garment& s) { return s.g == g; }),
                  garments_.end());
}

const std::vector<ReachSphere>* AdaptiveState::reach(const GarmentSim* g) const {
  const Garment* s = find(g);
  return s ? &s->reach : nullptr;
}

void AdaptiveState::observePose(const SkeletonPose& pose, bool teleported, const PipelineOptions& o) {
  float moved = 0.0f;
  if (has_anchor_)
    for (int j = 0; j < kJointCount; ++j) moved = std::max(moved, (pose.position[j] - anchor_[j]).norm());
  if (!has_anchor_ || teleported || !(moved <= o.sleep_distance_m)) {
    for (int j = 0; j < kJointCount; ++j) anchor_[j] = pose.position[j];
    has_anchor_ = true;
    still_since_s_ = clock_s_;
    wakeAll();
  }
}

void AdaptiveState::wakeAll() {
  for (Garment& s : garments_) {
    if (s.asleep) s.woke = true;
    s.asleep = false;
    s.calm = false;
  }
}

void AdaptiveState::wake(const GarmentSim* g) {
  if (Garment* s = find(g)) {
    if (s->asleep) s->woke = true;
    s->asleep = false;
    s->calm = false;
  }
}

bool AdaptiveState::asleep(const GarmentSim* g) const {
  const Garment* s = find(g);
  return s && s->asleep;
}

size_t AdaptiveState::asleepCount() const {
  size_t n = 0;
  for (const Garment& s : garments_) n += s.asleep ? 1 : 0;
  return n;
}

const std::vector<Ellipsoid>* AdaptiveState::wakeStart(const GarmentSim* g, const std::vector<Ellipsoid>& now) {
  Garment* s = find(g);
  if (!s || !s->woke) return nullptr;
  s->woke = false;
  // The garment last stepped against the ellipsoids it fell asleep on: its first step sweeps the
  // body from there to now. Ellipsoids that became reachable since are taken as still.
  s->start = now;
  for (size_t i = 0; i < s->slept_reach.size(); ++i) {
    const size_t k = static_cast<size_t>(s->slept_reach[i]);
    if (k < s->start.size()) s->start[k] = s->slept_ellipsoids[i];
  }
  return &s->start;
}

void AdaptiveState::afterStep(const GarmentSim& g, const std::vector<Ellipsoid>& now, float dt,
                              const PipelineOptions& o) {
  Garment* s = find(&g);
  if (!s) return;
  s->woke = false;
  const Eigen::Vector4f* x = g.positions();
  const size_t n = g.particleCount();
  if (!o.sleep) {
    s->calm = false;
    s->last_x.clear();
    return;
  }
  // Fastest free particle over the step (pinned ones move with the body, which has its own
  // clock). The first step after creation or a wake has nothing to compare with: not calm.
  float max_move2 = std::numeric_limits<float>::infinity();
  if (s->last_x.size() == n) {
    max_move2 = 0.0f;
    for (size_t i = 0; i < n; ++i)
      if (x[i].w() > 0.0f) max_move2 = std::max(max_move2, (x[i] - s->last_x[i]).head<3>().squaredNorm());
  }
  s->last_x.assign(x, x + n);
  const float limit = o.sleep_speed_m_s * dt;
  const bool calm = std::isfinite(max_move2) && max_move2 <= limit * limit;
  if (!calm) {
    s->calm = false;
    return;
  }
  if (!s->calm) {
    s->calm = true;
    s->calm_since_s = clock_s_;
  }
  const double delay = o.sleep_delay_s;
  if (has_anchor_ && clock_s_ - s->calm_since_s >= delay && clock_s_ - still_since_s_ >= delay) {
    s->asleep = true;
    // What it needs to wake without a pop: the ellipsoids it stepped to, the ones it uses.
    const std::vector<int>& reach = g.reachable();
    s->slept_reach.clear();
    s->slept_ellipsoids.clear();
    if (reach.empty()) {
      for (size_t k = 0; k < now.size(); ++k) s->slept_reach.push_back(static_cast<int>(k));
    } else {
      s->slept_reach = reach;
    }
    for (int k : s->slept_reach) s->slept_ellipsoids.push_back(now[static_cast<size_t>(k)]);
  }
}

}  // namespace drape
