#include "cloth/collider_motion.h"

#include <cmath>
#include <cstring>

namespace drape {

bool ColliderMotion::set(EllipsoidCollider* collider, const Ellipsoid* start, const Ellipsoid* end,
                         int count, float margin_m, std::string& error) {
  if (count < 0) {
    error = "ellipsoid count must not be negative";
    return false;
  }
  if (count > 0 && (collider == nullptr || start == nullptr || end == nullptr)) {
    error = "collider and ellipsoid arrays must not be null when count > 0";
    return false;
  }
  if (!std::isfinite(margin_m) || margin_m < 0.0f) {
    error = "collision margin must be finite and not negative";
    return false;
  }
  for (int k = 0; k < count; ++k) {
    for (const Ellipsoid* e : {&start[k], &end[k]}) {
      if (!isFinite(e->centre) || !isFinite(e->radii) || !e->rotation.allFinite() ||
          !(e->radii.minCoeff() > 0.0f)) {
        error = "ellipsoid " + std::to_string(k) + " is not finite or has a radius <= 0";
        return false;
      }
    }
  }
  collider_ = count > 0 ? collider : nullptr;
  count_ = count;
  margin_ = margin_m;
  start_.assign(start, start + count);
  end_.assign(end, end + count);
  a_.resize(static_cast<size_t>(count));
  b_.resize(static_cast<size_t>(count));
  identical_ = true;
  for (int k = 0; k < count && identical_; ++k) {
    identical_ = start[k].centre == end[k].centre && start[k].radii == end[k].radii &&
                 start[k].rotation == end[k].rotation;
  }
  return true;
}

void ColliderMotion::clear() {
  collider_ = nullptr;
  count_ = 0;
}

EllipsoidCollider* ColliderMotion::beginSpan(int s0, int s1, int n) {
  if (!active()) return nullptr;
  if (identical_) {
    if (s0 == 0) collider_->setEllipsoids(end_.data(), end_.data(), count_, margin_);
    return collider_;
  }
  const float t1 = s1 >= n ? 1.0f : static_cast<float>(s1) / static_cast<float>(n);
  if (s0 == 0) {
    a_ = start_;  // same size: no allocation
  } else {
    a_.swap(b_);  // the previous substep's end is this one's start
  }
  if (t1 == 1.0f) {
    b_ = end_;
  } else {
    for (int k = 0; k < count_; ++k) b_[k] = interpolateEllipsoidPose(start_[k], end_[k], t1);
  }
  collider_->setEllipsoids(a_.data(), b_.data(), count_, margin_);
  return collider_;
}

}  // namespace drape
