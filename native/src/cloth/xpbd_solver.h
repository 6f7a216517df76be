// Substepped XPBD cloth (Macklin et al. 2019, "Small Steps in Physics Simulation"): a frame is
// split into n substeps of one constraint iteration each; the Lagrange multipliers start at zero
// every substep, so none are stored. Constraint kinds and colouring: cloth/garment_topology.h.
// Method, defaults and figures: docs/cloth-solver.md.
//
// Layout (ready for an OpenCL port): positions, previous positions and velocities are arrays of
// Eigen::Vector4f, xyz in metres (velocities m/s), w = inverse mass (0 = pinned) in positions.
// Each colour group of each constraint kind could run one work-item per constraint; here they run
// in order, so the result is deterministic (bit-identical for identical input on one build).
// step() allocates nothing. Nothing throws: bad arguments return false and change nothing.
#pragma once

#include "cloth/collider_motion.h"
#include "cloth/garment_topology.h"
#include "proxies/collision.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace drape {

struct XpbdParams {
  Vec3 gravity = Vec3(0.0f, -9.81f, 0.0f);  // m/s^2
  // Compliance (inverse stiffness, m/N for these distance constraints); 0 = rigid.
  float stretch_compliance = 0.0f;
  float shear_compliance = 1e-6f;
  float bend_compliance = 1e-3f;
  float tether_compliance = 0.0f;
  float tether_scale = 1.0f;      // a particle may not go farther than rest * scale from its anchor
  float damping = 1.0f;           // 1/s, velocity scaled by exp(-damping * h) every substep
  float drag = 0.0f;              // 1/s, dv/dt += drag * (wind - v)
  Vec3 wind = Vec3::Zero();       // m/s
  float max_speed = 20.0f;        // m/s, speed clamp after integration; <= 0: none
  CollisionParams collision;      // used when a collider is set
  // Collision every this many substeps (and always on the last), [0, 8]: the swept test and
  // friction then span the substeps in between. 1 = every substep; 0 = by the garment's
  // resolution (collisionStrideFor).
  int collision_stride = 1;
  // Constraint projection passes per substep, [1, 64]. 1 is the method (many substeps of one
  // iteration); more passes exist to price that choice (drape-bench, docs/benchmarks.md) and for
  // the converged reference. Multipliers restart at zero every pass (none are stored), so a
  // compliant constraint comes out a little stiffer with more passes; rigid ones are unaffected.
  int iterations = 1;
  // Strain limit at the end of a step (Provot 1995's limit on over-stretched springs, applied to
  // positions): in the step's last substep, after the constraint passes and before collision,
  // `strain_limit_passes` Gauss–Seidel passes over the structural (stretch) edges pull every edge
  // longer than rest * (1 + strain_limit) back to that length; shorter edges are left alone. The
  // step's output is what the host draws: one substep's pass leaves a long chain of edges
  // stretched by g h^2 N / L (docs/garments.md), and the limit takes the excess out of the pose
  // shown at the cost of two passes in one substep (edges under the limit skip their stores),
  // where more substeps or passes would cost every substep. The correction becomes velocity.
  // 0 = off (the solver's default; garments use 0.10, GarmentSimParams). [0, 10].
  float strain_limit = 0.0f;
  int strain_limit_passes = 2;  // [1, 16]
};

// The collision stride a cloth of `particles` particles runs: `stride` when it is set (1-8); for 0
// (automatic) every substep from kCollideEverySubstepMinParticles to
// kCollideEverySubstepMaxParticles particles and every second one outside. Why: colliding every
// second substep, a coarse garment's sleeves and trouser legs come off the limbs in many more
// frames (the quality matrix at 400-1 200 particles: 3 118 frames with an opening off against
// 1 251 colliding every substep, and a lower P99 stretch at 400-600), and up to 1 250 particles
// collision every substep costs at most about 15 % more than the default resolution (1 809
// particles) costs every second substep. Finer garments lose fewer frames and it would cost them
// 35-45 % of the frame; at 200 particles (edges ~7 cm, longer than a limb is thick) it saves few
// frames off (8 %) for a P99 stretch 23 % higher, and the stress scenarios' recoveries got worse
// (docs/garments.md, "Coarse garments collide every substep"). The CPU and OpenCL solvers both
// resolve it here, so they run the same stride.
constexpr size_t kCollideEverySubstepMinParticles = 300;
constexpr size_t kCollideEverySubstepMaxParticles = 1250;
inline int collisionStrideFor(int stride, size_t particles) {
  if (stride > 0) return stride;
  return particles >= kCollideEverySubstepMinParticles && particles <= kCollideEverySubstepMaxParticles ? 1 : 2;
}

// Wall-clock split of the last step (only measured when enabled, for benchmarks): constraints =
// prediction, projection and velocity update; collision = per-substep collider setup + collide().
struct XpbdTimings {
  double constraints_ns = 0.0;
  double collision_ns = 0.0;
};

// The order of a constraint pass, CPU and OpenCL alike: the distance constraints by kind in this
// order (0 stretch, 1 shear, 2 bend), each kind colour by colour, then the tethers. Gauss–Seidel
// leaves the constraints projected last closest to satisfied, and the structural edges (stretch)
// are what a garment must not lengthen: projected after shear and bend, the P99 stretch fell in
// 28 of 30 take x garment cases at the same cost (Ges01 T-shirt 20.9 -> 17.2 %). The tethers stay
// last, the limit nothing may undo (projected first, coarse meshes and low substep rates
// stretched more). docs/cloth-solver.md, "Projection order".
inline constexpr uint8_t kDistanceKindOrder[3] = {1, 2, 0};

class XpbdSolver {
 public:
  static constexpr int kDefaultSubsteps = 10;

  // Copies the topology; particles start at rest at its rest positions, pin targets there.
  explicit XpbdSolver(GarmentTopology topology);

  // Rejects non-finite values, negative compliance/damping/drag, tether_scale < 1.
  bool setParams(const XpbdParams& params, std::string& error);
  const XpbdParams& params() const { return params_; }

  // Targets of the pinned particles at the end of the next step, one per topology().pinned entry
  // (same order). During step() pinned particles move linearly from where they are to the target
  // across the substeps. Rejects a count mismatch or a non-finite target.
  bool setPinTargets(const Vec3* targets, size_t count, std::string& error);

  // Optional ellipsoid collision against fixed ellipsoids, called once per substep after the
  // constraints with the substep's start positions as `previous`. The caller keeps the collider
  // alive and has set its ellipsoids. nullptr: none. Replaced by setColliderMotion when that is set.
  void setCollider(const EllipsoidCollider* collider) { collider_ = collider; }
  // Which rim edges the collision tests (EllipsoidCollider::collideRims): those whose two
  // particles are both on (one byte per particle); empty: all of them. Kept until the next call.
  void setRimGate(const std::vector<uint8_t>& on) { rim_gate_ = on; }
  // Moving ellipsoids for the following steps: `start` at the step start, `end` at its end,
  // interpolated across the substeps (cloth/collider_motion.h). The solver writes the collider's
  // ellipsoids every substep. count 0 turns it off. Validation as ColliderMotion::set.
  bool setColliderMotion(EllipsoidCollider* collider, const Ellipsoid* start, const Ellipsoid* end,
                         int count, float margin_m, std::string& error) {
    return motion_.set(collider, start, end, count, margin_m, error);
  }

  // Moves the whole state rigidly: every position (and pin target) x -> R (x - pivot) + pivot + t,
  // velocities v -> velocity_scale * R v. Used to carry the garment with the body (inertia scaling)
  // and to reset it on a teleport. R must be a rotation; nothing is checked (internal use).
  void transform(const Mat3& R, const Vec3& pivot, const Vec3& t, float velocity_scale);

  // Teleport: all particles to `positions` (particleCount() xyz), velocities zero, inverse masses
  // from the topology, pin targets = the new pinned positions. Rejects a count mismatch or
  // non-finite input.
  bool reset(const Vec3* positions, size_t count, std::string& error);

  // Advances dt seconds in `substeps` substeps. Rejects dt not in (0, 1], substeps not in
  // [1, 1000], or a substep shorter than kMinSubstepS (velocities are (x - x_prev) / h: a tiny h
  // makes float rounding a speed, a denormal one overflows): false, nothing changed.
  static constexpr float kMinSubstepS = 1e-6f;
  bool step(float dt, int substeps = kDefaultSubsteps);

  const GarmentTopology& topology() const { return topology_; }
  size_t particleCount() const { return topology_.particleCount(); }
  const Eigen::Vector4f* positions() const { return x_.data(); }    // w = inverse mass
  // Writable xyz for callers that constrain particles between steps (keep w as it is).
  Eigen::Vector4f* mutablePositions() { return x_.data(); }
  const Eigen::Vector4f* velocities() const { return v_.data(); }   // w = 0
  // Every particle's velocity (xyz m/s, w ignored): a garment coming back from the OpenCL
  // backend keeps its motion. False, nothing changed, on a wrong count or a non-finite value.
  bool setVelocities(const Eigen::Vector4f* v, size_t count) {
    if (v == nullptr || count != particleCount()) return false;
    for (size_t i = 0; i < count; ++i)
      if (!v[i].head<3>().allFinite()) return false;
    for (size_t i = 0; i < count; ++i) v_[i] = Eigen::Vector4f(v[i].x(), v[i].y(), v[i].z(), 0.0f);
    return true;
  }
  // Collision statistics summed over the last step's substeps.
  const CollisionStats& lastCollisionStats() const { return collision_stats_; }
  // Off by default (two clock reads per substep part when on).
  void setTimingEnabled(bool on) { timing_ = on; }
  // On by default where the CPU has AVX: the per-substep velocity update and prediction two
  // particles at a time (the same bits as one at a time). Off: one at a time (tests compare).
  void setPairedUpdate(bool on) { paired_update_ = on; }
  // On by default where the CPU has AVX-512F: constraints projected 16 at a time, and the fused
  // velocity update four particles at a time (the same bits as 8, 4 or 2 at a time). Off: the AVX
  // (or SSE) kernels (tests compare).
  void setWideProjection(bool on) { wide_projection_ = on; }
  const XpbdTimings& lastTimings() const { return timings_; }

  // Constraint storage for the SIMD kernels: every colour group padded to a multiple of kLanes (16)
  // with dummy constraints on the dummy particle x_[n] (w = 0, never read back), so a batch of
  // kLanes constraints shares no particle and needs no tail loop. Stretch, shear and bend are
  // one list (their colour groups concatenated in kDistanceKindOrder: the same Gauss–Seidel
  // order as three passes), each constraint carrying its kind's compliance.
  // A run of whole batches the AVX-512 kernel moves as 64-byte vectors (Batches::wide_runs).
  enum class RunKind : uint8_t { Quads, Pairs };
  struct WideRun {
    uint32_t begin, end;
    RunKind kind;
  };
  struct Batches {
    std::vector<uint32_t> a, b;
    std::vector<uint32_t> a_off, b_off;  // a, b times sizeof(Vec4): the AVX kernel's addresses
    std::vector<float> rest, compliance;
    std::vector<float> w_ab;   // w_a + w_b (w_a for tethers): fixed, so a new h costs one
                               // division per constraint and no gathers
    std::vector<float> inv_w;  // 1 / (w_a + w_b + compliance / h^2), for inv_w_h2_; 0 = inert
    // [begin, end) runs of entries with compliance > 0: the only ones a new h changes (the
    // others, rigid constraints and padding, are set once by refreshCompliance)
    std::vector<std::pair<uint32_t, uint32_t>> compliant;
    std::vector<uint32_t> group_offsets{0};
    // [begin, end) runs of whole batches of kLanes (16) whose lanes q, q + 4, q + 8, q + 12 are
    // four consecutive particles at both ends (tethers: at the free end a; quadOrder in
    // xpbd_solver.cpp): the AVX-512 kernel moves each such quad as one 64-byte load and store
    // instead of four 16-byte ones, the AVX kernel each half as one 32-byte one.
    std::vector<std::pair<uint32_t, uint32_t>> quad_runs;
    // What the AVX-512 kernel walks, in order: the quad runs (RunKind::Quads) and, after each
    // group's, runs of whole batches whose lanes q, q + 4, q + 8, q + 12 hold (p, p + 1),
    // (p + 2, p + 3), (p + 4, p + 5), (p + 6, p + 7) (RunKind::Pairs: quadOrder's pair octets, a
    // row's edges every other one; distance constraints only), each octet's eight particles moved
    // as two 64-byte loads and stores.
    std::vector<WideRun> wide_runs;
  };
  // The lists as the kernels run them (tests check their layout).
  const Batches& distanceBatches() const { return distance_; }
  const Batches& tetherBatches() const { return tethers_; }

 private:
  // pin_t: fraction of the step at the substep end; collider: this substep's, or null.
  // span_prev: positions at the start of the collision span (the substep start when stride 1).
  // predicted: the prediction already ran (fused into the previous substep's last loop);
  // predict_next: run the next substep's prediction in this one's last loop (same step, same h),
  // with each particle's position before it copied to capture[i] when capture is not null.
  void substep(float h, float pin_t, const EllipsoidCollider* collider, const Eigen::Vector4f* span_prev,
               bool predicted, bool predict_next, Eigen::Vector4f* capture);
  void buildBatches();
  void refreshCompliance();  // after setParams

  GarmentTopology topology_;
  std::vector<uint8_t> rim_gate_;  // setRimGate
  XpbdParams params_;
  Batches distance_, tethers_;
  float inv_w_h2_ = -1.0f;  // the 1/h^2 that Batches::inv_w was computed for
  std::vector<uint8_t> distance_kind_;  // 0 stretch, 1 shear, 2 bend (3 padding), per entry
  size_t stretch_first_ = 0;            // where the stretch colour groups start in distance_
  std::vector<Eigen::Vector4f> x_, prev_, v_;  // n + 1 entries: x_[n] is the dummy particle
  std::vector<Eigen::Vector4f> span_start_;     // positions where the current collision span began
  std::vector<Vec3> pin_start_, pin_target_;
  const EllipsoidCollider* collider_ = nullptr;
  ColliderMotion motion_;
  CollisionStats collision_stats_;
  bool timing_ = false;
  bool paired_update_ = true;
  bool wide_projection_ = true;
  XpbdTimings timings_;
};

}  // namespace drape
