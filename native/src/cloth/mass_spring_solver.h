// The paper's baseline (§3.1): a mass-spring cloth integrated with explicit (symplectic) Euler in
// n substeps per step. Springs sit on the same particle pairs as the XPBD constraints (stretch,
// shear, bend; no tethers). Each particle's update is independent within a substep (one
// work-item per particle on a GPU, as in the paper).
//
// Stability: for one spring on a particle of mass m, symplectic Euler needs h < 2 sqrt(m / k);
// with several springs on a particle the bound uses their summed stiffness (roughly h <
// 2 sqrt(m / sum k), and damping lowers it further). The solver refuses nothing: it runs any h and
// reports explosions. NaN guard: after every step, a non-finite position/velocity or a speed above
// `explosion_speed` restores the state at the start of that step and counts one explosion.
// step() allocates nothing; nothing throws.
#pragma once

#include "cloth/collider_motion.h"
#include "cloth/garment_topology.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace drape {

struct MassSpringParams {
  Vec3 gravity = Vec3(0.0f, -9.81f, 0.0f);  // m/s^2
  float stretch_stiffness = 100.0f;         // N/m per spring
  float shear_stiffness = 20.0f;            // N/m
  float bend_stiffness = 2.0f;              // N/m
  float spring_damping = 0.01f;             // N s/m along each spring (relative velocity)
  float damping = 1.0f;                     // 1/s, velocity scaled by exp(-damping * h)
  float explosion_speed = 100.0f;           // m/s: faster counts as exploded
  CollisionParams collision;                // used when collider motion is set
};

class MassSpringSolver {
 public:
  explicit MassSpringSolver(GarmentTopology topology);

  // Rejects non-finite or negative values and explosion_speed <= 0.
  bool setParams(const MassSpringParams& params, std::string& error);
  const MassSpringParams& params() const { return params_; }
  // As XpbdSolver::setPinTargets.
  bool setPinTargets(const Vec3* targets, size_t count, std::string& error);

  // As XpbdSolver::setColliderMotion. After each substep's Euler update the collider moves
  // particles out of the ellipsoids and the velocity change that implies is applied too
  // (v += correction / h), so a particle does not keep pushing into the body.
  bool setColliderMotion(EllipsoidCollider* collider, const Ellipsoid* start, const Ellipsoid* end,
                         int count, float margin_m, std::string& error) {
    return motion_.set(collider, start, end, count, margin_m, error);
  }
  // As XpbdSolver::reset: all particles to `positions`, velocities zero, pin targets there.
  bool reset(const Vec3* positions, size_t count, std::string& error);
  // As XpbdSolver::transform.
  void transform(const Mat3& R, const Vec3& pivot, const Vec3& t, float velocity_scale);
  const CollisionStats& lastCollisionStats() const { return collision_stats_; }
  // Wall time spent in the collider during the last step, milliseconds.
  double lastCollideMs() const { return collide_ms_; }

  // Rejects dt not in (0, 1] or substeps not in [1, 100000]. Returns false also when the step
  // exploded (then the state is the one before the step and explosions() grew by one).
  bool step(float dt, int substeps);

  uint32_t explosions() const { return explosions_; }
  const GarmentTopology& topology() const { return topology_; }
  size_t particleCount() const { return x_.size(); }
  const Eigen::Vector4f* positions() const { return x_.data(); }   // w = inverse mass
  // Writable xyz for callers that constrain particles between steps (keep w as it is).
  Eigen::Vector4f* mutablePositions() { return x_.data(); }
  const Eigen::Vector4f* velocities() const { return v_.data(); }

 private:
  void addSprings(const DistanceConstraints& c, float k);

  GarmentTopology topology_;
  MassSpringParams params_;
  std::vector<Eigen::Vector4f> x_, v_, f_, good_x_, good_v_, prev_, predicted_;
  ColliderMotion motion_;
  CollisionStats collision_stats_;
  double collide_ms_ = 0.0;
  std::vector<Vec3> pin_start_, pin_target_;
  uint32_t explosions_ = 0;
};

}  // namespace drape
