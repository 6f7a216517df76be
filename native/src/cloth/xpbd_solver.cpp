#include "cloth/xpbd_solver.h"

#include <cmath>
#include <utility>

namespace drape {
namespace {

using Vec4 = Eigen::Vector4f;

bool finite(const Vec3& v) { return isFinite(v); }
bool finite(float f) { return std::isfinite(f); }

}  // namespace

XpbdSolver::XpbdSolver(GarmentTopology topology) : topology_(std::move(topology)) {
  const size_t n = topology_.particleCount();
  x_.resize(n);
  prev_.resize(n);
  v_.assign(n, Vec4::Zero());
  for (size_t i = 0; i < n; ++i) {
    const Vec3& p = topology_.rest_positions[i];
    x_[i] = Vec4(p.x(), p.y(), p.z(), topology_.inverse_mass[i]);
  }
  prev_ = x_;
  pin_start_.resize(topology_.pinned.size());
  pin_target_.resize(topology_.pinned.size());
  for (size_t k = 0; k < topology_.pinned.size(); ++k)
    pin_target_[k] = topology_.rest_positions[topology_.pinned[k]];
}

bool XpbdSolver::setParams(const XpbdParams& p, std::string& error) {
  if (!finite(p.gravity) || !finite(p.wind)) {
    error = "gravity and wind must be finite";
    return false;
  }
  const float non_negative[] = {p.stretch_compliance, p.shear_compliance, p.bend_compliance,
                                p.tether_compliance, p.damping, p.drag};
  for (float f : non_negative) {
    if (!finite(f) || f < 0.0f) {
      error = "compliance, damping and drag must be finite and not negative";
      return false;
    }
  }
  if (!finite(p.tether_scale) || p.tether_scale < 1.0f) {
    error = "tether_scale must be finite and at least 1";
    return false;
  }
  if (!finite(p.max_speed)) {
    error = "max_speed must be finite (<= 0 disables the clamp)";
    return false;
  }
  params_ = p;
  return true;
}

bool XpbdSolver::setPinTargets(const Vec3* targets, size_t count, std::string& error) {
  if (count != pin_target_.size() || (count > 0 && targets == nullptr)) {
    error = "expected " + std::to_string(pin_target_.size()) + " pin targets, got " +
            std::to_string(count);
    return false;
  }
  for (size_t k = 0; k < count; ++k) {
    if (!finite(targets[k])) {
      error = "pin target " + std::to_string(k) + " is not finite";
      return false;
    }
  }
  for (size_t k = 0; k < count; ++k) pin_target_[k] = targets[k];
  return true;
}

bool XpbdSolver::reset(const Vec3* positions, size_t count, std::string& error) {
  if (count != x_.size() || positions == nullptr) {
    error = "expected " + std::to_string(x_.size()) + " positions, got " + std::to_string(count);
    return false;
  }
  for (size_t i = 0; i < count; ++i) {
    if (!finite(positions[i])) {
      error = "position " + std::to_string(i) + " is not finite";
      return false;
    }
  }
  for (size_t i = 0; i < count; ++i) {
    x_[i].head<3>() = positions[i];
    v_[i].setZero();
  }
  prev_ = x_;  // same size: no allocation
  for (size_t k = 0; k < pin_target_.size(); ++k) pin_target_[k] = positions[topology_.pinned[k]];
  return true;
}

bool XpbdSolver::step(float dt, int substeps) {
  if (!(dt > 0.0f) || !(dt <= 1.0f) || substeps < 1 || substeps > 1000) return false;
  for (size_t k = 0; k < pin_start_.size(); ++k)
    pin_start_[k] = x_[topology_.pinned[k]].head<3>();
  collision_stats_ = CollisionStats{};
  const float h = dt / static_cast<float>(substeps);
  const float inv_n = 1.0f / static_cast<float>(substeps);
  for (int s = 0; s < substeps; ++s) {
    const EllipsoidCollider* collider = motion_.active() ? motion_.beginSubstep(s, substeps) : collider_;
    substep(h, s + 1 == substeps ? 1.0f : static_cast<float>(s + 1) * inv_n, collider);
  }
  return true;
}

void XpbdSolver::transform(const Mat3& R, const Vec3& pivot, const Vec3& t, float velocity_scale) {
  const Vec3 shift = pivot + t;
  for (size_t i = 0; i < x_.size(); ++i) {
    x_[i].head<3>() = R * (Vec3(x_[i].head<3>()) - pivot) + shift;
    prev_[i].head<3>() = R * (Vec3(prev_[i].head<3>()) - pivot) + shift;
    v_[i].head<3>() = velocity_scale * (R * Vec3(v_[i].head<3>()));
  }
  for (Vec3& p : pin_target_) p = R * (p - pivot) + shift;
}

void XpbdSolver::substep(float h, float pin_t, const EllipsoidCollider* collider) {
  const XpbdParams& p = params_;
  const size_t n = x_.size();
  const Vec3 g = p.gravity;
  const float max_speed2 = p.max_speed > 0.0f ? p.max_speed * p.max_speed : 0.0f;
  // 1. Predict: explicit velocity update (gravity, drag towards the wind), clamp, move.
  for (size_t i = 0; i < n; ++i) {
    prev_[i] = x_[i];
    if (x_[i].w() == 0.0f) continue;
    Vec3 v = v_[i].head<3>();
    v += h * (g + p.drag * (p.wind - v));
    if (max_speed2 > 0.0f) {
      const float s2 = v.squaredNorm();
      if (s2 > max_speed2) v *= p.max_speed / std::sqrt(s2);
    }
    v_[i].head<3>() = v;
    x_[i].head<3>() += h * v;
  }
  // Pinned particles follow their targets, interpolated linearly across the step.
  for (size_t k = 0; k < pin_target_.size(); ++k) {
    const Vec3 at = pin_start_[k] + pin_t * (pin_target_[k] - pin_start_[k]);
    x_[topology_.pinned[k]].head<3>() = at;
  }
  // 2. One XPBD iteration per constraint kind, colour by colour (alpha~ = alpha / h^2).
  const float inv_h2 = 1.0f / (h * h);
  project(topology_.stretch, p.stretch_compliance * inv_h2);
  project(topology_.shear, p.shear_compliance * inv_h2);
  project(topology_.bend, p.bend_compliance * inv_h2);
  projectTethers(p.tether_compliance * inv_h2);
  // 3. Collision against the tracking ellipsoids.
  if (collider != nullptr) {
    const CollisionStats cs = collider->collide(x_.data(), prev_.data(), n, p.collision);
    collision_stats_.tests += cs.tests;
    collision_stats_.contacts += cs.contacts;
    collision_stats_.swept_catches += cs.swept_catches;
    collision_stats_.escapes += cs.escapes;
  }
  // 4. Velocities from positions, then damping.
  const float inv_h = 1.0f / h;
  const float keep = std::exp(-p.damping * h);
  for (size_t i = 0; i < n; ++i) {
    Vec3 v = (x_[i].head<3>() - prev_[i].head<3>()) * inv_h;
    v_[i].head<3>() = v * keep;
  }
}

void XpbdSolver::project(const DistanceConstraints& c, float alpha_tilde) {
  const size_t m = c.size();
  Vec4* x = x_.data();
  for (size_t k = 0; k < m; ++k) {
    Vec4& pa = x[c.a[k]];
    Vec4& pb = x[c.b[k]];
    const float wa = pa.w(), wb = pb.w();
    const float wsum = wa + wb + alpha_tilde;
    if (wsum <= 0.0f) continue;
    const Vec3 d = pa.head<3>() - pb.head<3>();
    const float len = d.norm();
    if (len <= 1e-9f) continue;
    // Delta lambda = -C / (w_a + w_b + alpha~), lambda starting at 0 (one iteration).
    const float dl = -(len - c.rest[k]) / wsum;
    const Vec3 corr = (dl / len) * d;
    pa.head<3>() += wa * corr;
    pb.head<3>() -= wb * corr;
  }
}

void XpbdSolver::projectTethers(float alpha_tilde) {
  const DistanceConstraints& c = topology_.tether;
  const float scale = params_.tether_scale;
  Vec4* x = x_.data();
  for (size_t k = 0; k < c.size(); ++k) {
    Vec4& pa = x[c.a[k]];
    const Vec3 d = pa.head<3>() - x[c.b[k]].head<3>();
    const float len2 = d.squaredNorm();
    const float limit = c.rest[k] * scale;
    if (len2 <= limit * limit) continue;  // inequality: only pulls back
    const float len = std::sqrt(len2);
    const float wa = pa.w();
    if (wa + alpha_tilde <= 0.0f) continue;
    const float dl = -(len - limit) / (wa + alpha_tilde);
    pa.head<3>() += (wa * dl / len) * d;
  }
}

}  // namespace drape
