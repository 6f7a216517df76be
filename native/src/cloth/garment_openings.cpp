#include "cloth/garment_openings.h"
#include "cloth/garment_topology.h"
#include "common/plain3.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace drape {

namespace {

// Gauss linking integral of segments p1 -> p2 and p3 -> p4: the signed solid angle one subtends
// seen along the other, over 4 pi (Klenin & Langowski 2000, eq. 15-16; exact for straight
// segments). Computed in double: the arcsines of nearly parallel normals lose float precision.
// Plain doubles (common/plain3.h): the opening count runs this for every loop edge against every
// body segment on every measured frame.
double segmentLinking(const Vec3& p1f, const Vec3& p2f, const Vec3& p3f, const Vec3& p4f) {
  using D3 = Plain3<double>;
  const D3 p1 = plain3<double>(p1f), p2 = plain3<double>(p2f), p3 = plain3<double>(p3f), p4 = plain3<double>(p4f);
  const D3 r13 = p3 - p1, r14 = p4 - p1, r23 = p3 - p2, r24 = p4 - p2, r12 = p2 - p1, r34 = p4 - p3;
  auto unit = [](const D3& v, bool& ok) {
    const double n = norm(v);
    ok = ok && n > 1e-15;
    return ok ? D3{v.x / n, v.y / n, v.z / n} : D3{0.0, 0.0, 0.0};
  };
  bool ok = true;
  const D3 n1 = unit(cross(r13, r14), ok), n2 = unit(cross(r14, r24), ok), n3 = unit(cross(r24, r23), ok),
           n4 = unit(cross(r23, r13), ok);
  if (!ok) return 0.0;  // touching or collinear segments: no solid angle
  auto asinc = [](double x) { return std::asin(std::clamp(x, -1.0, 1.0)); };
  const double omega = asinc(dot(n1, n2)) + asinc(dot(n2, n3)) + asinc(dot(n3, n4)) + asinc(dot(n4, n1));
  const double side = dot(cross(r34, r12), r13);
  return (side > 0.0 ? omega : side < 0.0 ? -omega : 0.0) / (4.0 * static_cast<double>(kPi));
}

}  // namespace

float loopLinking(const std::vector<Vec3>& loop, const std::vector<Vec3>& polyline) {
  const size_t n = loop.size();
  if (n < 3 || polyline.size() < 2) return 0.0f;
  double sum = 0.0;
  for (size_t k = 0; k < n; ++k)
    for (size_t s = 0; s + 1 < polyline.size(); ++s)
      sum += segmentLinking(loop[k], loop[(k + 1) % n], polyline[s], polyline[s + 1]);
  return static_cast<float>(sum);
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
void GarmentOpenings::forEachOn(const Eigen::Vector4f* x, size_t n, const BodyModel& body, F&& f,
                                bool limbs_only) const {
  if (openings_.empty()) return;
  // Scratch kept between calls: the rim gate runs this every step (GarmentSim::runStepFrame).
  std::vector<std::vector<Vec3>>& parts = parts_scratch_;
  std::vector<Vec3>& at = loop_scratch_;
  bodyPolylines(body, parts);
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
  forEachOn(x, n, body, [&](const Opening&, bool on) {
    if (!on) ++c.off;
  });
  return c;
}

void GarmentOpenings::markOn(const Eigen::Vector4f* x, size_t n, const BodyModel& body, std::vector<uint8_t>& on) const {
  on.assign(n, 0);
  forEachOn(x, n, body, [&](const Opening& o, bool is_on) {
    if (is_on)
      for (uint32_t i : o.loop) on[i] = 1;
  }, /*limbs_only=*/true);
}

}  // namespace drape
