// The body's tracking ellipsoids moving across one cloth step. A step gets the ellipsoids at its
// start (the body of the previous frame) and at its end (this frame); every substep the collider
// is given the pair interpolated at the substep's start and end fractions, so a limb that moves
// 20 cm in a frame sweeps through the substeps (and the collider's swept test sees each part of
// that sweep) instead of jumping once. Shared by both cloth solvers.
#pragma once

#include "proxies/collision.h"
#include "proxies/ellipsoid.h"

#include <string>
#include <vector>

namespace drape {

class ColliderMotion {
 public:
  // The collider is kept by the caller and must outlive the solver's use of it. start/end: count
  // ellipsoids each (same order); copied. Allocates only when count grows. Rejects a null
  // collider with count > 0, null arrays with count > 0, a negative count, or a non-finite or
  // negative margin.
  bool set(EllipsoidCollider* collider, const Ellipsoid* start, const Ellipsoid* end, int count,
           float margin_m, std::string& error);
  // No collision in the next steps.
  void clear();
  bool active() const { return collider_ != nullptr && count_ > 0; }
  // Gives the collider the ellipsoids of substep s of n (interpolated at s/n and (s+1)/n). The
  // substep-end ellipsoids are kept and reused as the next substep's start.
  EllipsoidCollider* beginSubstep(int s, int n) { return beginSpan(s, s + 1, n); }
  // The same for the span of substeps [s0, s1) (collision every few substeps). Spans must be
  // consecutive within a step, the first starting at 0.
  EllipsoidCollider* beginSpan(int s0, int s1, int n);

 private:
  EllipsoidCollider* collider_ = nullptr;
  std::vector<Ellipsoid> start_, end_, a_, b_;
  int count_ = 0;
  float margin_ = EllipsoidCollider::kDefaultMargin;
  bool identical_ = false;  // start == end: no interpolation needed
  // Per ellipsoid, what interpolateEllipsoidPose's slerp computes from the two rotations alone
  // (unit quaternions, their dot product and angle), computed once per step instead of once per
  // collision span: the same operations on the same values, so the same bits.
  struct Slerp {
    Quat a, b;
    float d = 1.0f, theta = 0.0f, sin_theta = 0.0f;
    bool linear = true;  // |d| >= 1 - epsilon: Eigen's slerp blends linearly
  };
  std::vector<Slerp> slerp_;
  const Ellipsoid* span_end_ = nullptr;    // the last span's end ellipsoids (start_, end_, a_ or b_)
  // The step's hold boxes (EllipsoidCollider::setSpanEllipsoids), made by holdBoxes() at its first span.
  void holdBoxes();
  std::vector<Vec3> hold_min_, hold_max_;
};

}  // namespace drape
