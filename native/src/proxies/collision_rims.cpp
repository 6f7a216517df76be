// EllipsoidCollider::collideRims: a garment's rim edges (its boundary loops: cuffs, hems, collar)
// against the ellipsoids, after the particles (docs/collision.md, "Rim edges").
//
// Why: the particle pass keeps every particle outside every ellipsoid, not the cloth between
// them. Where a rim's particles lie farther apart than a limb is thick (a 1 000-particle long
// sleeve's cuff: 16 particles, edges stretched to 6-9 cm round a 6 cm forearm), the limb slips
// between two of them, each pushed out on its own side, and the sleeve is off the arm through
// its own rim. Only rims are tested: there an edge with a limb across it has nothing beyond it to
// hold the limb back, and rims are few (about 150 edges on a 2 000-particle T-shirt).
#include "proxies/collision_internal.h"
#include "proxies/collision_lanes.h"

#include "common/cpu.h"

#include <algorithm>
#include <cmath>

namespace drape {
using namespace collision_internal;

namespace {
// Only an edge whose interior runs this deep (|q|^2 in the inflated ellipsoid's unit space: its
// closest point nearer the centre than 0.87 of the way to the surface) is pushed: a limb lying
// across the edge, not a short chord grazing the surface, which the margin already covers and
// which the particles' own contacts answer. Measured over the 240-run quality matrix at 800-2 500
// particles (docs/garments.md, "Rim edges"): deeper thresholds (0.5) kept fewer sleeves on at low
// resolutions, shallower ones (1.0) moved the default resolutions' figures.
constexpr float kRimDeep2 = 0.75f;
// The edge's closest point within this fraction of an end: the end particle's own contact.
constexpr float kRimEndT = 0.02f;
// An ellipsoid whose longest radius is this many times its middle one is a limb's (or a long
// torso segment's): rims are pushed across its long axis, not along it.
constexpr float kLimbElongation = 1.5f;

// Whether rim edge (ia, ib) takes part at all (its ends in range and distinct, both gated on,
// not both pinned, finite), and the collision mask its ends share (both may touch; 0xFF without
// groups: particle_masks null): the scalar pass and the sixteen-edge screen skip the same edges.
bool rimEdgeTakesPart(const Eigen::Vector4f* positions, size_t count, uint32_t ia, uint32_t ib,
                      const uint8_t* active, const uint8_t* particle_masks, uint8_t& mask) {
  if (ia >= count || ib >= count || ia == ib) return false;
  if (active && !(active[ia] && active[ib])) return false;
  const Eigen::Vector4f& pa = positions[ia];
  const Eigen::Vector4f& pb = positions[ib];
  if (!(pa.w() > 0.0f) && !(pb.w() > 0.0f)) return false;
  if (!pa.head<3>().allFinite() || !pb.head<3>().allFinite()) return false;
  mask = particle_masks ? static_cast<uint8_t>(particle_masks[ia] & particle_masks[ib]) : 0xFF;
  return mask != 0;
}
}  // namespace

size_t EllipsoidCollider::collideRims(Eigen::Vector4f* positions, size_t count, const uint32_t* a,
                                      const uint32_t* b, size_t edges, const CollisionParams& p,
                                      CollisionStats& st, const uint8_t* active) const {
  if (!positions || !a || !b || shapes_.empty()) return 0;
  const bool use_grid = p.broad_phase && grid_;
  const bool grouped = particle_masks_ != nullptr && !allowed_.empty() && groups_.size() == shapes_.size() &&
                       shapes_.size() <= static_cast<size_t>(kMaxGridEllipsoids);
  // One edge the scalar way; true when it was pushed.
  const auto edge = [&](size_t e) {
    const uint32_t ia = a[e], ib = b[e];
    // The ellipsoids both particles may touch: a sleeve's cuff meets the arm, not the torso.
    uint8_t mask = 0;
    if (!rimEdgeTakesPart(positions, count, ia, ib, active, grouped ? particle_masks_ : nullptr, mask)) return false;
    Eigen::Vector4f& pa = positions[ia];
    Eigen::Vector4f& pb = positions[ib];
    const float wa = pa.w() > 0.0f ? pa.w() : 0.0f, wb = pb.w() > 0.0f ? pb.w() : 0.0f;
    const uint64_t* allowed = grouped ? allowedRow(mask) : nullptr;
    Vec3 xa = pa.head<3>(), xb = pb.head<3>();
    Candidates c;
    if (!gather(xa.cwiseMin(xb), xa.cwiseMax(xb), use_grid, allowed, c)) return false;
    bool moved = false;
    // The edge's box against each candidate's end box (the Quick copy: 4 lanes, one branch),
    // re-taken after a push moves the ends.
    Vec4 lo4 = lift(xa.cwiseMin(xb)), hi4 = lift(xa.cwiseMax(xb));
    iterate(c, [&](int k) {
      const Quick& qk = quick_[static_cast<size_t>(k)];
      if (!overlaps4(lo4, hi4, qk.end_min, qk.end_max)) return;
      const Shape& s = shapes_[static_cast<size_t>(k)];
      ++st.tests;
      const Vec3 q0 = s.end.to_unit * (xa - s.end.centre), q1 = s.end.to_unit * (xb - s.end.centre);
      const Vec3 d = q1 - q0;
      const float dd = d.squaredNorm();
      if (!(dd > 1e-12f)) return;
      const float t = std::clamp(-q0.dot(d) / dd, 0.0f, 1.0f);
      if (t <= kRimEndT || t >= 1.0f - kRimEndT) return;
      const Vec3 q = q0 + t * d;
      const float r2 = q.squaredNorm();
      if (!(r2 < kRimDeep2) || !(r2 > 1e-12f)) return;
      // The edge's deepest point to the surface, shared by the ends by their barycentric weights
      // and inverse masses so that the point itself lands there (as a point-on-edge XPBD
      // contact). Out along its direction from the centre in unit space, except along a limb's
      // own axis: a cuff across a forearm near one end of its ellipsoid would be pushed along the
      // arm into the next ellipsoid of the chain and on, off the hand (a trouser hem off the
      // foot); across the limb instead, keeping its place along it.
      Vec3 target = q * (1.0f / std::sqrt(r2));
      int axis = 0;
      s.radii.maxCoeff(&axis);
      const float longest = s.radii[axis];
      const float middle = std::max(s.radii[(axis + 1) % 3], s.radii[(axis + 2) % 3]);
      if (longest > kLimbElongation * middle) {
        Vec3 across = q;
        across[axis] = 0.0f;
        const float a2 = across.squaredNorm();
        if (!(a2 > 1e-8f)) return;  // on the axis: no side to prefer (the next substep moves it)
        target = across * std::sqrt((1.0f - q[axis] * q[axis]) / a2);
        target[axis] = q[axis];
      }
      const Vec3 delta = s.end.from_unit * (target - q);
      const float ca = wa * (1.0f - t), cb = wb * t;
      const float den = ca * (1.0f - t) + cb * t;
      if (!(den > 0.0f)) return;
      xa += (ca / den) * delta;
      xb += (cb / den) * delta;
      lo4 = lift(xa.cwiseMin(xb)), hi4 = lift(xa.cwiseMax(xb));
      moved = true;
      ++st.contacts;
    });
    if (!moved) return false;
    // The ends may now touch an ellipsoid (another of the limb's, or this one near the end): they
    // get the particle pass's discrete answer, so no particle is left inside.
    const auto settleEnd = [&](Vec3& x, float w, uint32_t i) {
      if (w == 0.0f) return;
      resolveParticle(x, x, false, p, grouped ? allowedRow(particle_masks_[i]) : nullptr, st);
      positions[i].head<3>() = x;
    };
    settleEnd(xa, wa, ia);
    settleEnd(xb, wb, ib);
    return true;
  };
  size_t pushed = 0, e = 0;
#if DRAPE_COLLISION_AVX
  // Sixteen edges at a time first: most edges touch nothing, and the screen answers those
  // together (their tests counted); from the first edge a candidate may push on, the scalar way
  // (a push moves particles the next edges share).
  if (edges >= 16 && p.batch8 && p.batch16 && cpuHasAvx512() &&
      shapes_.size() <= static_cast<size_t>(kMaxGridEllipsoids)) {
    for (; e + 16 <= edges; e += 16) {
      const int first = rimScreenSixteen(positions, count, a + e, b + e, use_grid, grouped, active, st);
      for (size_t j = static_cast<size_t>(first); j < 16; ++j) pushed += edge(e + j) ? 1 : 0;
    }
  }
#endif
  for (; e < edges; ++e) pushed += edge(e) ? 1 : 0;
  return pushed;
}

#if DRAPE_COLLISION_AVX
#if !defined(__clang__)
// GCC 12's AVX-512 intrinsics pass _mm512_undefined_ps() (a self-initialised variable) as the
// unused merge source, and -Wuninitialized reports it where they are inlined: a known false positive.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
// The screen: for each of the sixteen edges the same candidates the scalar pass tests (its own
// gather's, allowed for both ends' masks, whose end box meets the edge's box: the batch gathers
// for the edges' joint box and mask, a superset, and narrows per lane; an ellipsoid whose end box
// meets the edge's box is in the edge's own cells, as it is marked in every cell its box meets),
// each counted as a test. Whether a candidate may push is asked with room to spare: the scalar
// pass pushes only where the edge's closest point to the centre has |q|^2 < kRimDeep2 (and more);
// here |q|^2 from this arithmetic (not the scalar's bit for bit) is compared with 1.001 kRimDeep2
// + 1e-6, a near-degenerate edge (|d|^2 <= 2e-12 in unit space) and any NaN count as "may", and
// so "may not" here means the scalar pass would not push either: those edges are done, the same
// bits and the same counts as one at a time. An edge the scalar pass skips before its gather (an
// index out of range, both ends pinned, a gate or a mask that leaves it out, a non-finite end)
// takes no part.
DRAPE_LANES16_TARGET int EllipsoidCollider::rimScreenSixteen(const Eigen::Vector4f* positions, size_t count,
                                                             const uint32_t* a, const uint32_t* b, bool use_grid,
                                                             bool grouped, const uint8_t* active,
                                                             CollisionStats& st) const {
  using namespace collision_lanes::lanes16;
  alignas(64) float ax[kLanes], ay[kLanes], az[kLanes], bx[kLanes], by[kLanes], bz[kLanes];
  LaneBytes masks{};
  int on = 0;
  for (int j = 0; j < kLanes; ++j) {
    ax[j] = ay[j] = az[j] = bx[j] = by[j] = bz[j] = 0.0f;
    if (!rimEdgeTakesPart(positions, count, a[j], b[j], active, grouped ? particle_masks_ : nullptr, masks.b[j]))
      continue;
    const Eigen::Vector4f& pa = positions[a[j]];
    const Eigen::Vector4f& pb = positions[b[j]];
    ax[j] = pa.x(), ay[j] = pa.y(), az[j] = pa.z();
    bx[j] = pb.x(), by[j] = pb.y(), bz[j] = pb.z();
    on |= 1 << j;
  }
  if (on == 0) return kLanes;
  const V XA = load(ax), YA = load(ay), ZA = load(az), XB = load(bx), YB = load(by), ZB = load(bz);
  const V lox = vmin(XA, XB), loy = vmin(YA, YB), loz = vmin(ZA, ZB);
  const V hix = vmax(XA, XB), hiy = vmax(YA, YB), hiz = vmax(ZA, ZB);
  const M onm = maskOf(on);
  const V inf = bcast(std::numeric_limits<float>::infinity()), minf = bcast(-std::numeric_limits<float>::infinity());
  const Vec3 lo(hmin(select(onm, lox, inf)), hmin(select(onm, loy, inf)), hmin(select(onm, loz, inf)));
  const Vec3 hi(hmax(select(onm, hix, minf)), hmax(select(onm, hiy, minf)), hmax(select(onm, hiz, minf)));
  uint8_t joint = 0;
  for (int j = 0; j < kLanes; ++j) joint = static_cast<uint8_t>(joint | masks.b[j]);
  Candidates c;
  if (!gather(lo, hi, use_grid, grouped ? allowedRow(joint) : nullptr, c)) return kLanes;  // no edge's box meets one
  int ks[kMaxGridEllipsoids];
  int n = 0;
  iterate(c, [&](int k) { ks[n++] = k; });
  const V thr = bcast(1.001f * kRimDeep2 + 1e-6f), dd_min = bcast(2e-12f), one = bcast(1.0f), z0 = zero();
  V tests = z0;
  int may = 0;
  for (int m = 0; m < n; ++m) {
    const int k = ks[m];
    const Quick& qk = quick_[static_cast<size_t>(k)];
    int lanes = on;
    if (grouped) lanes &= lanesSharing(masks.b, groups_[static_cast<size_t>(k)]);
    lanes &= bits(boxes(lox, loy, loz, hix, hiy, hiz, qk.end_min, qk.end_max));
    if (!lanes) continue;
    const M lm = maskOf(lanes);
    tests = select(lm, add(tests, one), tests);
    V q0x, q0y, q0z, q1x, q1y, q1z;
    unitSpace(qk.end_u, qk.end_c, XA, YA, ZA, q0x, q0y, q0z);
    unitSpace(qk.end_u, qk.end_c, XB, YB, ZB, q1x, q1y, q1z);
    const V dx = sub(q1x, q0x), dy = sub(q1y, q0y), dz = sub(q1z, q0z);
    const V dd = dot(dx, dy, dz, dx, dy, dz);
    const V tn = sub(z0, dot(q0x, q0y, q0z, dx, dy, dz));
    const V t = vmin(vmax(div(tn, dd), z0), one);
    const V qx = add(q0x, mul(t, dx)), qy = add(q0y, mul(t, dy)), qz = add(q0z, mul(t, dz));
    const V r2 = dot(qx, qy, qz, qx, qy, qz);
    // "May not" only where both are certainly clear (ordered compares: a NaN counts as "may").
    const M clear = mand(ge(r2, thr), gt(dd, dd_min));
    may |= lanes & ~bits(clear);
  }
  const int first = may ? __builtin_ctz(static_cast<unsigned>(may)) : kLanes;
  // The tests of the edges before `first` (the scalar pass counts its own from there on).
  alignas(64) float counts[kLanes];
  store(counts, tests);
  for (int j = 0; j < first; ++j) st.tests += static_cast<uint32_t>(counts[j]);
  return first;
}
#if !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#endif

}  // namespace drape
