#include "cloth/garment_openings.h"
#include "cloth/garment_topology.h"
#include "common/plain3.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace drape {

namespace {

using D3 = Plain3<double>;

// det(a, b, c) = a . (b x c).
double det3(const D3& a, const D3& b, const D3& c) { return dot(a, cross(b, c)); }

// A side or solid-angle numerator this small against the product of the three distances (its
// largest possible size) is rounding: the point is in the plane. Real garments put polyline points
// there exactly: a pinned collar's opposite points are mirror images through the neck ring's
// centre, which the spine passes through, so that centre lies on the fan edge from the loop's first
// point to its opposite one, where one triangle's side came out 0 and its neighbour's 8e-22
// (Ges04, test GarmentOpeningsGeometry.PolylinePointOnASharedFanEdge).
constexpr double kPlaneTolerance = 1e-12;

// sign(side(p, P, Q, R)), 0 within the tolerance.
int sideSign(const D3& p, const D3& P, const D3& Q, const D3& R) {
  const D3 a = P - p, b = Q - p, c = R - p;
  const double v = det3(a, b, c), tol = kPlaneTolerance * norm(a) * norm(b) * norm(c);
  return v > tol ? 1 : v < -tol ? -1 : 0;
}

// Signed solid angle of the triangle (P, Q, R) seen from p (Van Oosterom & Strackee 1983):
// in (-2 pi, 2 pi), positive from below (the side its counter-clockwise normal points away from),
// jumping by -4 pi where p goes up through the triangle's interior. A point in the triangle's
// plane gives 0: outside the triangle that is its value, inside it is the mean of the two sides.
double solidAngle(const D3& p, const D3& P, const D3& Q, const D3& R) {
  const D3 a = P - p, b = Q - p, c = R - p;
  const double num = det3(a, b, c);
  const double la = norm(a), lb = norm(b), lc = norm(c);
  if (std::fabs(num) <= kPlaneTolerance * la * lb * lc) return 0.0;  // as sideSign's 0
  const double den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
  return 2.0 * std::atan2(num, den);
}

}  // namespace

// The loop is the boundary of a fan of triangles (v0, vk, vk+1), k = 1 .. n - 2; the sum of their
// solid angles seen from a point, Omega(p), changes continuously along the polyline except by
// -4 pi where it passes up through a fan triangle. Gauss's integral of the loop and a segment
// a -> b is the continuous change of Omega over 4 pi, so the polyline's linking telescopes to
// (Omega(end) - Omega(start)) / 4 pi plus the count of its upward crossings of the fan (minus the
// downward ones): two solid angles per fan triangle and a crossing test per segment and triangle,
// against four arcsines per loop edge and segment for the pairwise sum (Klenin & Langowski 2000),
// which gives the same value (test GarmentOpeningsGeometry.FanLinkingEqualsThePairwiseSum) at a
// tenth of the cost or less: the rim gate evaluates it every step (GarmentSim::runStepFrame).
// Computed in double. The fan starts at a loop point, not at the loop's centre, where a limb's
// centre line passes.
float loopLinking(const std::vector<Vec3>& loop, const std::vector<Vec3>& polyline) {
  const size_t n = loop.size();
  if (n < 3 || polyline.size() < 2) return 0.0f;
  auto v = [&](size_t k) { return plain3<double>(loop[k]); };
  const D3 apex = v(0);
  const D3 start = plain3<double>(polyline.front()), end = plain3<double>(polyline.back());
  double omega = 0.0;
  for (size_t k = 1; k + 1 < n; ++k) omega += solidAngle(end, apex, v(k), v(k + 1)) - solidAngle(start, apex, v(k), v(k + 1));
  // Half crossings where an end lies in a triangle's plane, to match the solid angle's 0 there.
  double crossings = 0.0;
  for (size_t s = 0; s + 1 < polyline.size(); ++s) {
    const D3 a = plain3<double>(polyline[s]), b = plain3<double>(polyline[s + 1]), d = b - a;
    // The line a -> b passes through the triangle (P, Q, R) when d . ((X - a) x (Y - a)) has one
    // sign on its three edges X -> Y. The fan edge apex -> vk is shared by triangles k - 1 and k:
    // its sign is taken once (0 counted as positive), so a line through it is in exactly one.
    auto edgeSign = [&](const D3& X, const D3& Y) { return det3(d, X - a, Y - a); };
    bool shared_pos = edgeSign(apex, v(1)) >= 0.0;
    for (size_t k = 1; k + 1 < n; ++k) {
      const bool next_pos = edgeSign(apex, v(k + 1)) >= 0.0;
      const bool in = shared_pos != next_pos;  // edge vk+1 -> apex is the reverse of apex -> vk+1
      const bool pos = shared_pos;
      shared_pos = next_pos;
      if (!in) continue;
      const double rim = edgeSign(v(k), v(k + 1));
      if (rim != 0.0 && (rim > 0.0) != pos) continue;
      crossings += 0.5 * static_cast<double>(sideSign(a, apex, v(k), v(k + 1)) - sideSign(b, apex, v(k), v(k + 1)));
    }
  }
  return static_cast<float>(omega / (4.0 * static_cast<double>(kPi)) + crossings);
}

std::vector<std::vector<Vec3>> GarmentOpenings::bodyPolylines(const BodyModel& body) {
  std::vector<std::vector<Vec3>> out;
  bodyPolylines(body, out);
  return out;
}

void GarmentOpenings::bodyPolylines(const BodyModel& body, std::vector<std::vector<Vec3>>& out) {
  auto centres = [&](Chain c, std::vector<Vec3>& into) {
    const int first = body.chainFirstRing(c), count = body.chainRingCount(c);
    for (int i = 0; i < count; ++i) into.push_back(body.rings()[static_cast<size_t>(first + i)].centre);
  };
  out.resize(5);  // spine, then ArmL, ArmR, LegL, LegR; the vectors keep their capacity
  std::vector<Vec3>& spine = out[0];
  spine.clear();
  centres(Chain::Torso, spine);
  if (spine.size() >= 2) {
    const Vec3 down = spine[0] - spine[1];
    if (down.norm() > 1e-6f) spine.insert(spine.begin(), spine[0] + down.normalized() * kSpineExtensionM);
  }
  centres(Chain::Head, spine);
  spine.push_back(body.apex(Chain::Head));
  size_t p = 1;
  for (Chain c : {Chain::ArmL, Chain::ArmR, Chain::LegL, Chain::LegR}) {
    std::vector<Vec3>& limb = out[p++];
    limb.clear();
    centres(c, limb);
    // A leg starts kLegExtensionM above its thigh ring, in the pelvis.
    const bool leg = c == Chain::LegL || c == Chain::LegR;
    if (leg && limb.size() >= 2) {
      const Vec3 up = limb[0] - limb[1];
      if (up.norm() > 1e-6f) limb.insert(limb.begin(), limb[0] + up.normalized() * kLegExtensionM);
    }
    limb.push_back(body.apex(c));
  }
}

void GarmentOpenings::bind(const std::vector<uint32_t>& triangles, const std::vector<Vec3>& positions,
                           const BodyModel& body_rest) {
  openings_.clear();
  const std::vector<std::vector<Vec3>> parts = bodyPolylines(body_rest);
  std::vector<Vec3> at;
  for (std::vector<uint32_t>& loop : boundaryLoops(triangles, positions.size())) {
    at.clear();
    for (uint32_t i : loop) at.push_back(positions[i]);
    // The body part it goes round most (the spine for a hem round the hips and both legs).
    float best = 0.0f;
    uint32_t best_part = 0;
    for (size_t p = 0; p < parts.size(); ++p) {
      const float linking = loopLinking(at, parts[p]);
      if (std::fabs(linking) > std::fabs(best)) {
        best = linking;
        best_part = static_cast<uint32_t>(p);
      }
    }
    if (std::fabs(best) >= kBindLinking) openings_.push_back({std::move(loop), best_part, best > 0.0f ? 1 : -1});
  }
}

template <class F>
void GarmentOpenings::forEachOn(const Eigen::Vector4f* x, size_t n, const std::vector<std::vector<Vec3>>& parts,
                                F&& f, bool limbs_only) const {
  // Scratch kept between calls: the rim gate runs this every step (GarmentSim::runStepFrame).
  std::vector<Vec3>& at = loop_scratch_;
  for (const Opening& o : openings_) {
    if (limbs_only && o.part == 0) continue;  // bodyPolylines' first: the spine
    at.clear();
    for (uint32_t i : o.loop)
      if (i < n) at.push_back(x[i].head<3>());
    const bool whole = at.size() == o.loop.size() && o.part < parts.size();
    const float linking = whole ? loopLinking(at, parts[o.part]) : 0.0f;
    f(o, linking * static_cast<float>(o.sign) >= kOffLinking);
  }
}

OpeningCount GarmentOpenings::count(const Eigen::Vector4f* x, size_t n, const BodyModel& body) const {
  OpeningCount c;
  c.tracked = static_cast<uint32_t>(openings_.size());
  if (openings_.empty()) return c;
  bodyPolylines(body, parts_scratch_);
  forEachOn(x, n, parts_scratch_, [&](const Opening&, bool on) {
    if (!on) ++c.off;
  });
  return c;
}

void GarmentOpenings::markOn(const Eigen::Vector4f* x, size_t n, const BodyModel& body, std::vector<uint8_t>& on) const {
  on.assign(n, 0);
  if (openings_.empty()) return;
  bodyPolylines(body, parts_scratch_);
  forEachOn(x, n, parts_scratch_, [&](const Opening& o, bool is_on) {
    if (is_on)
      for (uint32_t i : o.loop) on[i] = 1;
  }, /*limbs_only=*/true);
}

}  // namespace drape
