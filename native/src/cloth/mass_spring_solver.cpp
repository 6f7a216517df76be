#include "cloth/mass_spring_solver.h"

#include "common/plain3.h"

#include <chrono>
#include <cmath>
#include <utility>

namespace drape {
namespace {
using Vec4 = Eigen::Vector4f;
}  // namespace

MassSpringSolver::MassSpringSolver(GarmentTopology topology) : topology_(std::move(topology)) {
  const size_t n = topology_.particleCount();
  x_.resize(n);
  v_.assign(n, Vec4::Zero());
  f_.assign(n, Vec4::Zero());
  for (size_t i = 0; i < n; ++i) {
    const Vec3& p = topology_.rest_positions[i];
    x_[i] = Vec4(p.x(), p.y(), p.z(), topology_.inverse_mass[i]);
  }
  good_x_ = x_;
  good_v_ = v_;
  prev_ = x_;
  predicted_ = x_;
  pin_start_.resize(topology_.pinned.size());
  pin_target_.resize(topology_.pinned.size());
  for (size_t k = 0; k < topology_.pinned.size(); ++k)
    pin_target_[k] = topology_.rest_positions[topology_.pinned[k]];
}

bool MassSpringSolver::setParams(const MassSpringParams& p, std::string& error) {
  if (!isFinite(p.gravity)) {
    error = "gravity must be finite";
    return false;
  }
  const float non_negative[] = {p.stretch_stiffness, p.shear_stiffness, p.bend_stiffness,
                                p.spring_damping, p.damping};
  for (float f : non_negative) {
    if (!std::isfinite(f) || f < 0.0f) {
      error = "stiffness and damping must be finite and not negative";
      return false;
    }
  }
  if (!std::isfinite(p.explosion_speed) || !(p.explosion_speed > 0.0f)) {
    error = "explosion_speed must be positive and finite";
    return false;
  }
  params_ = p;
  return true;
}

bool MassSpringSolver::setPinTargets(const Vec3* targets, size_t count, std::string& error) {
  if (count != pin_target_.size() || (count > 0 && targets == nullptr)) {
    error = "expected " + std::to_string(pin_target_.size()) + " pin targets, got " +
            std::to_string(count);
    return false;
  }
  for (size_t k = 0; k < count; ++k) {
    if (!isFinite(targets[k])) {
      error = "pin target " + std::to_string(k) + " is not finite";
      return false;
    }
  }
  for (size_t k = 0; k < count; ++k) pin_target_[k] = targets[k];
  return true;
}

// The per-spring and per-particle loops in Plain3 / floats (common/plain3.h), in the order of the
// Eigen expressions they replaced: the same bits in an optimised build; the sanitizer build (-O1),
// where Eigen's expression templates stay calls, runs them several times faster.
void MassSpringSolver::addSprings(const DistanceConstraints& c, float k) {
  if (k == 0.0f && params_.spring_damping == 0.0f) return;
  const float cd = params_.spring_damping;
  for (size_t s = 0; s < c.size(); ++s) {
    const uint32_t a = c.a[s], b = c.b[s];
    const Plain3<float> d = plain3(x_[a]) - plain3(x_[b]);
    const float len = norm(d);
    if (len <= 1e-9f) continue;
    const Plain3<float> dir = d / len;
    const float rel = dot(plain3(v_[a]) - plain3(v_[b]), dir);
    const Plain3<float> force = (-k * (len - c.rest[s]) - cd * rel) * dir;
    addTo(f_[a], force);
    subtractFrom(f_[b], force);
  }
}

bool MassSpringSolver::step(float dt, int substeps) {
  if (!(dt > 0.0f) || !(dt <= 1.0f) || substeps < 1 || substeps > 100000) return false;
  const size_t n = x_.size();
  for (size_t i = 0; i < n; ++i) {
    good_x_[i] = x_[i];
    good_v_[i] = v_[i];
  }
  for (size_t k = 0; k < pin_start_.size(); ++k)
    pin_start_[k] = x_[topology_.pinned[k]].head<3>();
  collision_stats_ = CollisionStats{};
  collide_ms_ = 0.0;
  const MassSpringParams& p = params_;
  const float h = dt / static_cast<float>(substeps);
  const float keep = std::exp(-p.damping * h);
  const float inv_n = 1.0f / static_cast<float>(substeps);
  for (int s = 0; s < substeps; ++s) {
    for (size_t i = 0; i < n; ++i) f_[i].setZero();
    addSprings(topology_.stretch, p.stretch_stiffness);
    addSprings(topology_.shear, p.shear_stiffness);
    addSprings(topology_.bend, p.bend_stiffness);
    // Symplectic Euler: v += h a, x += h v (every particle independent).
    for (size_t i = 0; i < n; ++i) prev_[i] = x_[i];
    for (size_t i = 0; i < n; ++i) {
      float* x = x_[i].data();
      const float w = x[3];
      if (w == 0.0f) continue;
      float* v = v_[i].data();
      const float* f = f_[i].data();
      for (int j = 0; j < 3; ++j) {
        v[j] = (v[j] + h * (p.gravity[j] + w * f[j])) * keep;
        x[j] += h * v[j];
      }
    }
    const float t = s + 1 == substeps ? 1.0f : static_cast<float>(s + 1) * inv_n;
    for (size_t k = 0; k < pin_target_.size(); ++k) {
      const uint32_t i = topology_.pinned[k];
      const Vec3 at = pin_start_[k] + t * (pin_target_[k] - pin_start_[k]);
      v_[i].head<3>() = (at - x_[i].head<3>()) / h;
      x_[i].head<3>() = at;
    }
    if (EllipsoidCollider* collider = motion_.beginSubstep(s, substeps)) {
      for (size_t i = 0; i < n; ++i) predicted_[i] = x_[i];
      const auto t0 = std::chrono::steady_clock::now();
      const CollisionStats cs = collider->collide(x_.data(), prev_.data(), n, p.collision);
      collide_ms_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      collision_stats_.tests += cs.tests;
      collision_stats_.contacts += cs.contacts;
      collision_stats_.swept_catches += cs.swept_catches;
      collision_stats_.escapes += cs.escapes;
      const float inv_h = 1.0f / h;
      for (size_t i = 0; i < n; ++i)
        v_[i].head<3>() += (x_[i].head<3>() - predicted_[i].head<3>()) * inv_h;
    }
  }
  const float limit2 = p.explosion_speed * p.explosion_speed;
  bool exploded = false;
  for (size_t i = 0; i < n && !exploded; ++i) {
    const float s2 = v_[i].head<3>().squaredNorm();
    exploded = !std::isfinite(s2) || !(s2 <= limit2) || !isFinite(Vec3(x_[i].head<3>()));
  }
  if (exploded) {
    for (size_t i = 0; i < n; ++i) {
      x_[i] = good_x_[i];
      v_[i] = good_v_[i];
    }
    ++explosions_;
    return false;
  }
  return true;
}

}  // namespace drape

namespace drape {

void MassSpringSolver::transform(const Mat3& R, const Vec3& pivot, const Vec3& t,
                                 float velocity_scale) {
  const Vec3 shift = pivot + t;
  for (size_t i = 0; i < x_.size(); ++i) {
    x_[i].head<3>() = R * (Vec3(x_[i].head<3>()) - pivot) + shift;
    v_[i].head<3>() = velocity_scale * (R * Vec3(v_[i].head<3>()));
  }
  for (Vec3& p : pin_target_) p = R * (p - pivot) + shift;
}

}  // namespace drape

namespace drape {

bool MassSpringSolver::reset(const Vec3* positions, size_t count, std::string& error) {
  if (count != x_.size() || positions == nullptr) {
    error = "expected " + std::to_string(x_.size()) + " positions, got " + std::to_string(count);
    return false;
  }
  for (size_t i = 0; i < count; ++i) {
    if (!isFinite(positions[i])) {
      error = "position " + std::to_string(i) + " is not finite";
      return false;
    }
  }
  for (size_t i = 0; i < count; ++i) {  // w from the topology too (as XpbdSolver::reset)
    x_[i] = Vec4(positions[i].x(), positions[i].y(), positions[i].z(), topology_.inverse_mass[i]);
    v_[i].setZero();
  }
  for (size_t k = 0; k < pin_target_.size(); ++k) pin_target_[k] = positions[topology_.pinned[k]];
  return true;
}

}  // namespace drape
