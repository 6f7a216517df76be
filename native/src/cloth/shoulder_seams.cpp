#include "cloth/shoulder_seams.h"

#include <algorithm>
#include <cmath>

namespace drape {

void ShoulderSeams::bind(const BodyModel& body_rest, const std::vector<Vec3>& positions,
                         const std::vector<uint32_t>& pinned, const std::vector<int>& pin_ring) {
  pin_side_.clear();
  top_ = -1;
  const int first = body_rest.chainFirstRing(Chain::Torso), count = body_rest.chainRingCount(Chain::Torso);
  if (count <= 0 || pinned.size() != pin_ring.size()) return;
  const int top = first + count - 1;
  if (std::find(pin_ring.begin(), pin_ring.end(), top) == pin_ring.end()) return;  // no seam pins
  top_ = top;
  const auto& rings = body_rest.rings();
  const Chain arms[2] = {Chain::ArmL, Chain::ArmR};
  for (int s = 0; s < 2; ++s) {
    const int n = body_rest.chainRingCount(arms[s]), j = body_rest.chainFirstRing(arms[s]);
    // The arm's direction needs a second ring down the upper arm.
    if (n < 2 || j < 0 || static_cast<size_t>(j + n) > rings.size()) return;
    side_[s] = Side{};
    side_[s].junction = j;
    side_[s].upper = j + std::max(1, n / 3);
  }
  pin_side_.assign(pinned.size(), -1);
  for (size_t k = 0; k < pinned.size(); ++k) {
    if (pin_ring[k] != top || pinned[k] >= positions.size()) continue;
    const Vec3& p = positions[pinned[k]];
    const float d0 = (rings[static_cast<size_t>(side_[0].junction)].centre - p).squaredNorm();
    const float d1 = (rings[static_cast<size_t>(side_[1].junction)].centre - p).squaredNorm();
    pin_side_[k] = static_cast<int8_t>(d1 < d0 ? 1 : 0);
  }
}

void ShoulderSeams::restart() {
  for (Side& s : side_) {
    s.sum = Vec3::Zero();
    s.seconds = 0.0f;
  }
}

Vec3 ShoulderSeams::shoulderIn(const BodyModel& body, const Side& s) const {
  const RingPose& t = body.rings()[static_cast<size_t>(top_)];
  return t.frame.transpose() * (body.rings()[static_cast<size_t>(s.junction)].centre - t.centre);
}

bool ShoulderSeams::hangs(const BodyModel& body, const Side& s) const {
  const auto& rings = body.rings();
  const Vec3 arm = rings[static_cast<size_t>(s.upper)].centre - rings[static_cast<size_t>(s.junction)].centre;
  const float len = arm.norm();
  const Vec3 down = -rings[static_cast<size_t>(top_)].frame.col(1);
  return len > 1e-6f && arm.dot(down) >= kHangingCos * len;
}

void ShoulderSeams::observe(const BodyModel& body, float dt) {
  if (!active() || !(dt > 0.0f) || !std::isfinite(dt)) return;
  for (Side& s : side_) {
    if (s.seconds >= kBaselineS || !hangs(body, s)) continue;
    const Vec3 at = shoulderIn(body, s);
    if (!isFinite(at)) continue;
    s.sum += dt * at;
    s.seconds += dt;
  }
}

void ShoulderSeams::shift(const BodyModel& body, std::vector<Vec3>& targets) const {
  if (!active()) return;
  const RingPose& t = body.rings()[static_cast<size_t>(top_)];
  Vec3 moved[2] = {Vec3::Zero(), Vec3::Zero()};
  for (int s = 0; s < 2; ++s) {
    const Side& side = side_[s];
    if (!(side.seconds > 0.0f)) continue;  // not seen hanging yet: the seam stays with the torso
    const Vec3 m = t.frame * (shoulderIn(body, side) - side.sum / side.seconds);
    if (isFinite(m)) moved[s] = m;
  }
  const size_t n = std::min(targets.size(), pin_side_.size());
  for (size_t k = 0; k < n; ++k)
    if (pin_side_[k] >= 0) targets[k] += moved[pin_side_[k]];
}

}  // namespace drape
