#include "cloth/collider_motion.h"

#include <algorithm>
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
  slerp_.resize(static_cast<size_t>(count));
  if (!identical_) {
    // Eigen's QuaternionBase::slerp, the part that does not depend on t (interpolateEllipsoidPose
    // normalises both quaternions first).
    const float one = 1.0f - Eigen::NumTraits<float>::epsilon();
    for (int k = 0; k < count; ++k) {
      Slerp& q = slerp_[static_cast<size_t>(k)];
      q.a = Quat(start[k].rotation);
      q.b = Quat(end[k].rotation);
      q.a.normalize();
      q.b.normalize();
      q.d = q.a.dot(q.b);
      const float abs_d = std::abs(q.d);
      q.linear = abs_d >= one;
      if (!q.linear) {
        q.theta = std::acos(abs_d);
        q.sin_theta = std::sin(q.theta);
      }
    }
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
  // The span starts where the previous one ended (the step's start for the first); its end is
  // the step's end or the interpolation, written into whichever buffer the start is not in.
  const Ellipsoid* from = s0 == 0 ? start_.data() : span_end_;
  const Ellipsoid* to = end_.data();
  if (t1 != 1.0f) {
    std::vector<Ellipsoid>& out = from == a_.data() ? b_ : a_;
    for (int k = 0; k < count_; ++k) {
      // interpolateEllipsoidPose(start_[k], end_[k], t1) with the slerp's t-free part from set().
      const Ellipsoid& a = start_[k];
      const Ellipsoid& b = end_[k];
      const Slerp& q = slerp_[static_cast<size_t>(k)];
      Ellipsoid& e = out[k];
      e.centre = a.centre + t1 * (b.centre - a.centre);
      e.radii = a.radii + t1 * (b.radii - a.radii);
      float scale0, scale1;
      if (q.linear) {
        scale0 = 1.0f - t1;
        scale1 = t1;
      } else {
        scale0 = std::sin((1.0f - t1) * q.theta) / q.sin_theta;
        scale1 = std::sin(t1 * q.theta) / q.sin_theta;
      }
      if (q.d < 0.0f) scale1 = -scale1;
      e.rotation = Quat(scale0 * q.a.coeffs() + scale1 * q.b.coeffs()).toRotationMatrix();
    }
    to = out.data();
  }
  span_end_ = to;
  if (s0 == 0) holdBoxes();
  collider_->setSpanEllipsoids(from, to, count_, margin_, s0 == 0 ? hold_min_.data() : nullptr,
                               s0 == 0 ? hold_max_.data() : nullptr);
  return collider_;
}

// Boxes holding ellipsoid k's box (radii + margin, as the collider inflates them) at every pose
// between start_[k] and end_[k], so every span's swept box: the centre moves on the segment; the
// half extent along axis i, |row i of R diag(r)|, is at most that of either end with r_hat (the
// larger radii of the two ends: radii move linearly) plus r_hat_max |R(t)^T e_i - R_end^T e_i|,
// and R(t) turns from the nearer end by at most half the rotation phi between them (the slerp's
// arc): |R(t)^T e_i - R_end^T e_i| <= 2 sin(phi / 4) = sqrt(2 - 2 cos(phi / 2)) = sqrt(2 - 2 |d|),
// d the quaternions' dot product. Never more than r_hat_max. Plus 1 mm for rounding; the collider
// checks each span's swept box against its hold box and builds its own grid if one leaves it.
void ColliderMotion::holdBoxes() {
  hold_min_.resize(static_cast<size_t>(count_));
  hold_max_.resize(static_cast<size_t>(count_));
  constexpr float kSlack = 1e-3f;
  for (int k = 0; k < count_; ++k) {
    const Ellipsoid& a = start_[k];
    const Ellipsoid& b = end_[k];
    Vec3 r;
    for (int i = 0; i < 3; ++i) r[i] = std::max(std::max(a.radii[i], b.radii[i]) + margin_, 1e-6f);
    const float r_max = r.maxCoeff();
    const float turn = r_max * std::sqrt(std::max(0.0f, 2.0f - 2.0f * std::abs(slerp_[static_cast<size_t>(k)].d)));
    for (int i = 0; i < 3; ++i) {
      const float ha = a.rotation.row(i).cwiseProduct(r.transpose()).norm();
      const float hb = b.rotation.row(i).cwiseProduct(r.transpose()).norm();
      const float half = std::min(r_max, std::max(ha, hb) + turn) + kSlack;
      hold_min_[static_cast<size_t>(k)][i] = std::min(a.centre[i], b.centre[i]) - half;
      hold_max_[static_cast<size_t>(k)][i] = std::max(a.centre[i], b.centre[i]) + half;
    }
  }
}

}  // namespace drape
