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
}  // namespace

size_t EllipsoidCollider::collideRims(Eigen::Vector4f* positions, size_t count, const uint32_t* a,
                                      const uint32_t* b, size_t edges, const CollisionParams& p,
                                      CollisionStats& st, const uint8_t* active) const {
  if (!positions || !a || !b || shapes_.empty()) return 0;
  const bool use_grid = p.broad_phase && grid_;
  const bool grouped = particle_masks_ != nullptr && !allowed_.empty() && groups_.size() == shapes_.size() &&
                       shapes_.size() <= static_cast<size_t>(kMaxGridEllipsoids);
  size_t pushed = 0;
  for (size_t e = 0; e < edges; ++e) {
    const uint32_t ia = a[e], ib = b[e];
    if (ia >= count || ib >= count || ia == ib) continue;
    if (active && !(active[ia] && active[ib])) continue;
    Eigen::Vector4f& pa = positions[ia];
    Eigen::Vector4f& pb = positions[ib];
    const float wa = pa.w() > 0.0f ? pa.w() : 0.0f, wb = pb.w() > 0.0f ? pb.w() : 0.0f;
    if (wa == 0.0f && wb == 0.0f) continue;
    if (!pa.head<3>().allFinite() || !pb.head<3>().allFinite()) continue;
    // The ellipsoids both particles may touch: a sleeve's cuff meets the arm, not the torso.
    const uint8_t mask = grouped ? static_cast<uint8_t>(particle_masks_[ia] & particle_masks_[ib]) : 0xFF;
    if (grouped && mask == 0) continue;
    const uint64_t* allowed = grouped ? allowedRow(mask) : nullptr;
    Vec3 xa = pa.head<3>(), xb = pb.head<3>();
    Candidates c;
    if (!gather(xa.cwiseMin(xb), xa.cwiseMax(xb), use_grid, allowed, c)) continue;
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
    if (!moved) continue;
    // The ends may now touch an ellipsoid (another of the limb's, or this one near the end): they
    // get the particle pass's discrete answer, so no particle is left inside.
    const auto settleEnd = [&](Vec3& x, float w, uint32_t i) {
      if (w == 0.0f) return;
      resolveParticle(x, x, false, p, grouped ? allowedRow(particle_masks_[i]) : nullptr, st);
      positions[i].head<3>() = x;
    };
    settleEnd(xa, wa, ia);
    settleEnd(xb, wb, ib);
    ++pushed;
  }
  return pushed;
}

}  // namespace drape
