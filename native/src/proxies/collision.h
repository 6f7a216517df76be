// Particle–ellipsoid collision (paper §3.3, eq. 7-10) with what Drape adds: an exact closest-point
// response, Coulomb friction against the moving surface, a swept (continuous) test between the
// substep's start and end, and a uniform-grid broad phase. Array-oriented: the cloth solver calls
// collide() once per substep on all its particles. Method, choices and figures: docs/collision.md.
//
// Threading: setEllipsoids() writes the collider; collide() is const, touches no shared mutable
// state and allocates nothing, so several threads may call it at once on disjoint particle ranges.
#pragma once

#include "common/math.h"
#include "proxies/ellipsoid.h"

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace drape {

enum class ContactResponse : int {
  Radial = 0,  // the paper: q = E^-1 x, move to q/|q| (radial projection in unit space)
  Exact = 1,   // closest point on the (margin-inflated) ellipsoid surface
};

struct CollisionParams {
  ContactResponse response = ContactResponse::Exact;
  float static_friction = 0.6f;   // mu_s: tangential slip below mu_s * depth is cancelled
  float kinetic_friction = 0.4f;  // mu_k: otherwise slip is reduced by mu_k * depth
  bool continuous = true;         // swept test between the substep's start and end
  bool broad_phase = true;        // grid culling; off = test every ellipsoid (same results)
  // The escape step (a particle still inside after the sequential passes) moves a particle at
  // most this far; a particle that would have to jump farther is left where the passes put it.
  // Such a particle is pinched where two body parts touch and their ellipsoids overlap: the only
  // way out is through one of the parts, which tears the cloth apart. <= 0: no limit (then every
  // particle is guaranteed outside every ellipsoid). Garments use 1 cm (GarmentSimParams).
  float max_escape_m = 0.0f;
  // Pass 0 (the discrete and swept tests) for 8 consecutive particles at once where the CPU has
  // AVX: the same tests in the same order and arithmetic per particle, so the same results
  // (bit-identical); off = one particle at a time. docs/collision.md, "Eight particles at once".
  bool batch8 = true;
  // With batch8: sixteen particles at once where the CPU has AVX-512F (the same results again;
  // fewer candidates per particle, as a batch's neighbours share their ellipsoids). docs/collision.md,
  // "Sixteen particles at once".
  bool batch16 = true;
  // The cloth solvers collide a garment's rim edges too (collideRims) after its particles.
  bool rims = true;
};

struct CollisionStats {
  uint32_t tests = 0;          // narrow-phase particle–ellipsoid tests (after the AABB reject)
  uint32_t contacts = 0;       // corrections in the first pass (discrete contacts + swept catches)
  uint32_t swept_catches = 0;  // of those, placed at a swept entry point
  uint32_t escapes = 0;        // particles still inside after kSequentialPasses (overlaps),
                               // resolved by the escape step
};

// The ellipsoid at fraction t of a substep: centre and radii interpolated linearly, rotation by
// quaternion slerp (shortest arc), then refresh().
Ellipsoid interpolateEllipsoid(const Ellipsoid& a, const Ellipsoid& b, float t);
// The same centre, radii and rotation without refresh() (to_unit and bounds left as they were
// default-constructed): all that EllipsoidCollider::setEllipsoids reads.
Ellipsoid interpolateEllipsoidPose(const Ellipsoid& a, const Ellipsoid& b, float t);

class EllipsoidCollider {
 public:
  static constexpr float kDefaultMargin = 0.004f;
  static constexpr int kGridCells = 1024;               // about this many near-cubic cells
  static constexpr int kGridMaxPerAxis = 32;
  static constexpr int kMaxGridEllipsoids = 256;        // more: broad phase off (still correct)
  static constexpr float kPenetrationTolerance = 1e-5f; // metres, guaranteed after collide()
  static constexpr int kSequentialPasses = 2;           // then the escape step

  // Ellipsoids at the start and at the end of the current substep (same count and order; only
  // centre, rotation and radii are read). Each is inflated by `margin_m` (the gap kept between a
  // particle and the surface, i.e. the cloth thickness:
  // radii + margin, see docs/collision.md for the error of that approximation), and the grid is
  // rebuilt. Allocates only when `count` grows; call once per substep. count <= 0 or null
  // pointers: no ellipsoids. A start ellipsoid equal (bit for bit) to the previous call's end
  // ellipsoid of the same index, at the same margin, reuses what that call computed for it (the
  // usual case: consecutive substeps share it), with the same result as computing it again.
  void setEllipsoids(const Ellipsoid* start, const Ellipsoid* end, int count,
                     float margin_m = kDefaultMargin);
  // setEllipsoids for one collision span of a step of several (ColliderMotion), keeping the grid
  // across the step: filling it is most of the set-up (~110 ellipsoids reach a T-shirt, each in a
  // few cells of ~2 000, five spans a frame). hold_min / hold_max (count each, inflated by the
  // margin as the collider's boxes are), given with a step's first span, are boxes that hold each
  // ellipsoid's swept box in every span of the step; the grid is built from them once and the
  // step's later spans (hold null) keep it. A span whose swept box leaves its hold box (or whose
  // count differs) gets the grid built from its own swept boxes, as setEllipsoids. The grid only
  // picks candidates for the box and narrow tests, so the contacts are the same bits either way.
  void setSpanEllipsoids(const Ellipsoid* start, const Ellipsoid* end, int count, float margin_m,
                         const Vec3* hold_min, const Vec3* hold_max);

  // positions: predicted positions at the substep end, xyz corrected in place; w = inverse mass,
  // particles with !(w > 0) (pinned) or a non-finite position are not touched.
  // previous: positions at the substep start (w ignored), used for friction and the swept test;
  // may be null (then neither). Particles are independent: the result for one particle does not
  // depend on the others or on their order.
  CollisionStats collide(Eigen::Vector4f* positions, const Eigen::Vector4f* previous, size_t count,
                         const CollisionParams& params) const;

  int count() const { return static_cast<int>(shapes_.size()); }
  // Grids built so far (setEllipsoids: one per call; setSpanEllipsoids: one per step when its
  // hold boxes hold every span), for tests and profiling.
  uint64_t gridBuilds() const { return grid_builds_; }

  // Rim edges (a[e], b[e]) of a garment's boundary loops against the end ellipsoids, after
  // collide(): an edge with an ellipsoid deep across its interior (a limb between two cuff
  // particles) is pushed off it, its two ends shared by barycentric weight and inverse mass, then
  // each moved end is collided again (discretely), so no particle is left inside. An edge meets
  // only the ellipsoids both its particles may touch (setGroups). Edges are answered in order,
  // each seeing the ones before it: callers that run them in parallel colour them (no two edges
  // of a colour share a particle). `active` (one byte per particle, or null: every edge): only
  // edges whose two particles are both active are tested. Returns the edges moved.
  // proxies/collision_rims.cpp.
  size_t collideRims(Eigen::Vector4f* positions, size_t count, const uint32_t* a, const uint32_t* b, size_t edges,
                     const CollisionParams& params, CollisionStats& stats, const uint8_t* active = nullptr) const;

  // Collision groups. ellipsoid_groups: the groups of each ellipsoid (bits 1 << body chain: one,
  // or two for the shoulder fills, proxies/proxy_builder.h), in the order setEllipsoids receives them; particle_masks: one byte per particle, the
  // groups it collides with (kept by the caller, read by collide() for particle i = masks[i]).
  // A particle never collides with an ellipsoid outside its mask. Empty groups or null masks: every
  // particle collides with every ellipsoid. Needs count() <= kMaxGridEllipsoids at collide time
  // (otherwise groups are ignored).
  void setGroups(const std::vector<uint8_t>& ellipsoid_groups, const uint8_t* particle_masks);
  // The groups setGroups received (empty: none), for the OpenCL backend's copy of the collider.
  const std::vector<uint8_t>& groups() const { return groups_; }
  float margin() const { return margin_; }
  // The inflated ellipsoid at the substep end (what a particle must end outside of).
  Ellipsoid inflatedEnd(int i) const;

 private:
  struct Frame {
    Vec3 centre = Vec3::Zero();
    Mat3 to_unit = Mat3::Identity();    // S^-1 R^T (inflated radii)
    Mat3 from_unit = Mat3::Identity();  // R S
  };
  struct Shape {
    Frame end, start;
    Mat3 rotation = Mat3::Identity();  // end rotation
    Vec3 radii = Vec3::Ones();         // end radii, inflated
    Vec3 end_min, end_max;             // AABB of the inflated end ellipsoid
    Vec3 swept_min, swept_max;         // union of the inflated start and end AABBs
    float inside_tol2 = 1.0f;          // |q|^2 below this: inside by more than the tolerance
    float graze = 0.0f;                // swept chords shallower than this (unit space) ignored
    int smallest_axis = 0;
    // The end ellipsoid's radii as setEllipsoids received them (its centre and rotation are
    // end.centre and rotation) and the box built from it (kept even when the build failed and
    // end_min / end_max were emptied): the next call's start when that is the same ellipsoid.
    Vec3 end_in_radii = Vec3::Zero();
    Vec3 end_built_min, end_built_max;
    bool end_built_ok = false;
  };
  // Hot-path copy of a shape in 16-byte lanes (w = 0): what every narrow test reads, so a test
  // is a few 4-wide multiply-adds. Shape keeps the rest for the (rarer) responses.
  struct Quick {
    Eigen::Vector4f end_c, end_u[3];      // end centre, columns of end to_unit
    Eigen::Vector4f start_c, start_u[3];  // start centre, columns of start to_unit
    Eigen::Vector4f swept_min, swept_max, end_min, end_max;
    Eigen::Vector4f radii2;               // inflated end radii squared (exact response)
    Eigen::Vector4f radii2_sqrt;          // sqrt of radii2 lane by lane (not the radii: rounding)
    float inside_tol2 = 1.0f, graze = 0.0f;
    // Pass 0's cheap rejection of the swept test (refreshQuick): a lane outside at the end whose
    // |q1|^2 sweep_keep2 > (sweep_k + sweep_gamma |x1 - x0| + kSweepRelSlack |q1|^2)^2 cannot
    // have crossed the ellipsoid during the span (sweep_keep2 = (1 - alpha)^2, 0 where 1 - alpha
    // is not positive: never rejects; NaN never rejects either).
    float sweep_keep2 = 0.0f, sweep_k = 0.0f, sweep_gamma = 0.0f;
  };
  // The rejection's slack in unit-space lengths: the swept test's float rounding is ~1e-6 of |q|^2.
  static constexpr double kSweepSlack = 1e-3;
  static constexpr float kSweepRelSlack = 1e-5f;
  using Mask = uint64_t[kMaxGridEllipsoids / 64];

  // Candidate ellipsoids for a box: the union of the masks of the cells it touches (grid) or all.
  struct Candidates {
    Mask mask;
    Eigen::Array4i lo, hi;  // cell range (w lane unused)
    bool all;
    const uint64_t* allowed;  // with `all`: only these (collision groups); null = every one
  };
  // False when the box misses every swept box. Otherwise fills c. allowed: the particle's
  // collision-group mask of ellipsoids (words_ words) or null.
  bool gather(const Vec3& lo, const Vec3& hi, bool use_grid, const uint64_t* allowed, Candidates& c) const;
  // Whether c's cells include the cell of p (then c's candidates include p's).
  bool covers(const Candidates& c, const Vec3& p) const;
  // Calls f(k) for the candidates in increasing k.
  template <class F>
  void iterate(const Candidates& c, F&& f) const;
  template <class F>
  void forCandidates(const Vec3& lo, const Vec3& hi, bool use_grid, const uint64_t* allowed, F&& f) const;
  // First ellipsoid (in index order) containing x by more than the tolerance, or -1.
  int firstContaining(const Vec3& x, bool use_grid, const uint64_t* allowed, CollisionStats& stats) const;
  void resolveParticle(Vec3& x, const Vec3& x0, bool has_prev, const CollisionParams& p,
                       const uint64_t* allowed, CollisionStats& stats) const;
  // resolveParticle after pass 0 moved x: the further sequential passes and the escape step.
  // first: pass 0's candidates for this particle, or null (then gathered where needed).
  void settle(Vec3& x, const Candidates* first, const CollisionParams& p, bool use_grid,
              const uint64_t* allowed, CollisionStats& stats) const;
  // The sequential passes' guarantee, for a particle their last pass moved: still inside an
  // ellipsoid -> the escape step.
  void escapeIfInside(Vec3& x, const CollisionParams& p, bool use_grid, const uint64_t* allowed,
                      CollisionStats& stats) const;
  // settle()'s first sequential pass for the lanes `lanes` of a batch of pass 0, whose joint
  // candidates ks[0..n) cover them; lane_masks: the lanes' collision masks (one byte each) when
  // they differ, else null (collision_batch.inc). Eight lanes (AVX) and sixteen (AVX-512F).
  void settleEight(const int* ks, int n, int lanes, const uint8_t* lane_masks, float* xx, float* xy, float* xz,
                   const CollisionParams& p, bool use_grid, size_t begin, bool grouped, CollisionStats& st) const;
  void settleSixteen(const int* ks, int n, int lanes, const uint8_t* lane_masks, float* xx, float* xy, float* xz,
                     const CollisionParams& p, bool use_grid, size_t begin, bool grouped, CollisionStats& st) const;
  // The ellipsoids a particle with collision mask `mask` may touch (allowed_'s row), and particle
  // i's row when collide() uses groups (null otherwise).
  const uint64_t* allowedRow(uint8_t mask) const {
    return &allowed_[static_cast<size_t>(mask) * (kMaxGridEllipsoids / 64)];
  }
  const uint64_t* allowedFor(bool grouped, size_t i) const {
    return grouped ? allowedRow(particle_masks_[i]) : nullptr;
  }
  // Whether particle i of collide() can touch anything (collision_internal.h).
  bool mayTouch(const Eigen::Vector4f* positions, const Eigen::Vector4f* previous, size_t i, bool swept) const;
  // collide() for particles [first, count), a batch of consecutive particles at a time: eight
  // (CollisionParams::batch8, AVX) or sixteen (with CollisionParams::batch16 too, AVX-512F).
  // Returns where it stopped (first + a multiple of the batch), the rest left to the caller:
  // first (nothing done) when the CPU lacks the width's instructions or there are more
  // ellipsoids than kMaxGridEllipsoids. collision_batch.inc.
  size_t collideEights(Eigen::Vector4f* positions, const Eigen::Vector4f* previous, size_t first, size_t count,
                       const CollisionParams& p, bool grouped, CollisionStats& st) const;
  size_t collideSixteens(Eigen::Vector4f* positions, const Eigen::Vector4f* previous, size_t first, size_t count,
                         const CollisionParams& p, bool grouped, CollisionStats& st) const;
  // collideRims' first look at sixteen rim edges [a, a + 16) at once (collision_rims.cpp): counts
  // the candidate tests each edge would make and returns the first edge that a candidate may push
  // (16 when none may: then the edges are done, nothing moved). Only where cpuHasAvx512().
  int rimScreenSixteen(const Eigen::Vector4f* positions, size_t count, const uint32_t* a, const uint32_t* b,
                       bool use_grid, bool grouped, const uint8_t* active, CollisionStats& st) const;
  // contact() for the lanes of `lanes` of a batch against ellipsoid k, where each is inside
  // (discrete contact) and the response is Exact, all lanes at once: the same arithmetic in the
  // same order per lane. Returns the lanes it answered (their x updated, st.contacts counted); the
  // rest (closest point not found in float, or a deep contact that may need the entry point) are
  // left for contact(). The arrays are the batch's lanes (8 or 16 floats each).
  int exactContactsEight(int k, int lanes, const float* q1x, const float* q1y, const float* q1z, const float* r2,
                         const float* q0x, const float* q0y, const float* q0z, const float* q0sq,
                         const float* x0x, const float* x0y, const float* x0z, bool cont, bool friction,
                         const CollisionParams& p, float* xx, float* xy, float* xz, CollisionStats& st) const;
  int exactContactsSixteen(int k, int lanes, const float* q1x, const float* q1y, const float* q1z, const float* r2,
                           const float* q0x, const float* q0y, const float* q0z, const float* q0sq,
                           const float* x0x, const float* x0y, const float* x0z, bool cont, bool friction,
                           const CollisionParams& p, float* xx, float* xy, float* xz, CollisionStats& st) const;
  Vec3 respond(const Shape& s, const Vec3& x, const Vec3& q, float r2, ContactResponse mode,
               Vec3& q_contact) const;
  void refreshQuick(int k);
  // setEllipsoids' shapes, boxes and grid_min_ / grid_max_ (no grid); false: no ellipsoid to grid.
  bool setShapes(const Ellipsoid* start, const Ellipsoid* end, int count, float margin_m);
  // The grid over box_of(k) = (min, max) pointers for the shapes setShapes put in it.
  template <class BoxOf>
  void buildGrid(int count, BoxOf box_of);
  void contact(const Shape& s, const Eigen::Vector4f& q1, float r2, const Eigen::Vector4f& q0,
               float q0sq, bool inside, bool cont, bool friction, const Vec3& x0,
               const CollisionParams& p, Vec3& x, CollisionStats& st) const;
  Vec3 slideFromEntry(const Shape& s, const Vec3& qe, const Vec3& q1, Vec3& q_contact) const;
  // Whether x4 is inside qk's end ellipsoid by more than the tolerance, its box first (a test
  // counted in `tests` when the box holds x4): firstContaining's question, which escapeIfInside
  // asks too and must answer the same.
  static bool holdsBeyondTolerance(const Quick& qk, const Eigen::Vector4f& x4, uint32_t& tests);
  // The ellipsoids containing a trapped particle (up to 8, in candidate order) and each one's
  // response target: what escape() starts from (escapeIfInside gathers them).
  static constexpr int kMaxEscapeCandidates = 8;
  struct EscapeStart {
    int m = 0;
    int containing[kMaxEscapeCandidates];
    Vec3 targets[kMaxEscapeCandidates];
  };
  void escape(Vec3& x, const EscapeStart& start, bool use_grid, const uint64_t* allowed, float max_escape,
              CollisionStats& stats) const;

  std::vector<Shape> shapes_;
  std::vector<Quick> quick_;
  std::vector<uint64_t> cells_;  // dims_ cells (x fastest) x words_ bitmask words
  int dims_[3] = {1, 1, 1};
  int words_ = 0;
  bool grid_ = false;
  Vec3 grid_min_ = Vec3::Zero(), grid_max_ = Vec3::Zero(), grid_scale_ = Vec3::Zero();
  Eigen::Array4f cell_origin_ = Eigen::Array4f::Zero(), cell_scale_ = Eigen::Array4f::Zero(),
                 cell_top_ = Eigen::Array4f::Zero();
  float margin_ = kDefaultMargin;
  // setSpanEllipsoids: the step's hold boxes (hold_count_ of them, 0: none) and whether the grid
  // now is the one built from them.
  std::vector<Vec3> hold_min_, hold_max_;
  int hold_count_ = 0;
  bool hold_built_ = false;
  uint64_t grid_builds_ = 0;
  // Collision groups (setGroups): group bit per ellipsoid, and for each of the 256 particle masks
  // the ellipsoids it may touch (kMaxGridEllipsoids / 64 words each).
  std::vector<uint8_t> groups_;
  std::vector<uint64_t> allowed_;
  const uint8_t* particle_masks_ = nullptr;
};

}  // namespace drape
