#include "cloth/garment_openings.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace drape {

std::vector<std::vector<uint32_t>> boundaryLoops(const std::vector<uint32_t>& triangles, size_t vertex_count) {
  // Undirected edge -> uses; a boundary edge keeps the direction its one triangle gives it, so
  // every loop runs the same way round relative to the surface.
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  for (size_t t = 0; t + 2 < triangles.size(); t += 3)
    for (int e = 0; e < 3; ++e) {
      const uint32_t i = triangles[t + static_cast<size_t>(e)], j = triangles[t + static_cast<size_t>((e + 1) % 3)];
      if (i == j || i >= vertex_count || j >= vertex_count) continue;
      ++uses[{std::min(i, j), std::max(i, j)}];
    }
  std::multimap<uint32_t, uint32_t> next;  // boundary half-edges i -> j
  for (size_t t = 0; t + 2 < triangles.size(); t += 3)
    for (int e = 0; e < 3; ++e) {
      const uint32_t i = triangles[t + static_cast<size_t>(e)], j = triangles[t + static_cast<size_t>((e + 1) % 3)];
      if (i == j || i >= vertex_count || j >= vertex_count) continue;
      if (uses[{std::min(i, j), std::max(i, j)}] == 1) next.emplace(i, j);
    }
  std::vector<std::vector<uint32_t>> loops;
  while (!next.empty()) {
    const uint32_t first = next.begin()->first;
    std::vector<uint32_t> loop{first};
    uint32_t at = first;
    for (;;) {
      const auto it = next.find(at);
      if (it == next.end()) break;  // an open chain (non-manifold input): dropped below
      at = it->second;
      next.erase(it);
      if (at == first) break;
      loop.push_back(at);
    }
    if (at == first && loop.size() >= 3) loops.push_back(std::move(loop));
  }
  return loops;
}

namespace {

// Gauss linking integral of segments p1 -> p2 and p3 -> p4: the signed solid angle one subtends
// seen along the other, over 4 pi (Klenin & Langowski 2000, eq. 15-16; exact for straight
// segments). Computed in double: the arcsines of nearly parallel normals lose float precision.
double segmentLinking(const Vec3& p1f, const Vec3& p2f, const Vec3& p3f, const Vec3& p4f) {
  using V = Eigen::Vector3d;
  const V p1 = p1f.cast<double>(), p2 = p2f.cast<double>(), p3 = p3f.cast<double>(), p4 = p4f.cast<double>();
  const V r13 = p3 - p1, r14 = p4 - p1, r23 = p3 - p2, r24 = p4 - p2, r12 = p2 - p1, r34 = p4 - p3;
  auto unit = [](const V& v, bool& ok) {
    const double n = v.norm();
    ok = ok && n > 1e-15;
    return ok ? V(v / n) : V::Zero();
  };
  bool ok = true;
  const V n1 = unit(r13.cross(r14), ok), n2 = unit(r14.cross(r24), ok), n3 = unit(r24.cross(r23), ok),
          n4 = unit(r23.cross(r13), ok);
  if (!ok) return 0.0;  // touching or collinear segments: no solid angle
  auto asinc = [](double x) { return std::asin(std::clamp(x, -1.0, 1.0)); };
  const double omega = asinc(n1.dot(n2)) + asinc(n2.dot(n3)) + asinc(n3.dot(n4)) + asinc(n4.dot(n1));
  const double side = r34.cross(r12).dot(r13);
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
  auto centres = [&](Chain c, std::vector<Vec3>& into) {
    const int first = body.chainFirstRing(c), count = body.chainRingCount(c);
    for (int i = 0; i < count; ++i) into.push_back(body.rings()[static_cast<size_t>(first + i)].centre);
  };
  std::vector<Vec3> spine;
  centres(Chain::Torso, spine);
  if (spine.size() >= 2) {
    const Vec3 down = spine[0] - spine[1];
    if (down.norm() > 1e-6f) spine.insert(spine.begin(), spine[0] + down.normalized() * kSpineExtensionM);
  }
  centres(Chain::Head, spine);
  out.push_back(std::move(spine));
  for (Chain c : {Chain::ArmL, Chain::ArmR, Chain::LegL, Chain::LegR}) {
    std::vector<Vec3> limb;
    centres(c, limb);
    // A leg starts kLegExtensionM above its thigh ring, in the pelvis.
    const bool leg = c == Chain::LegL || c == Chain::LegR;
    if (leg && limb.size() >= 2) {
      const Vec3 up = limb[0] - limb[1];
      if (up.norm() > 1e-6f) limb.insert(limb.begin(), limb[0] + up.normalized() * kLegExtensionM);
    }
    out.push_back(std::move(limb));
  }
  return out;
}

void GarmentOpenings::bind(const std::vector<uint32_t>& triangles, const std::vector<Vec3>& positions,
                           const BodyModel& body_rest) {
  loops_ = boundaryLoops(triangles, positions.size());
  pairs_.clear();
  const std::vector<std::vector<Vec3>> parts = bodyPolylines(body_rest);
  std::vector<Vec3> loop;
  for (size_t l = 0; l < loops_.size(); ++l) {
    loop.clear();
    for (uint32_t i : loops_[l]) loop.push_back(positions[i]);
    // The body part it goes round most (the spine for a hem round the hips and both legs).
    float best = 0.0f;
    size_t best_part = 0;
    for (size_t p = 0; p < parts.size(); ++p) {
      const float linking = loopLinking(loop, parts[p]);
      if (std::fabs(linking) > std::fabs(best)) {
        best = linking;
        best_part = p;
      }
    }
    if (std::fabs(best) >= kBindLinking)
      pairs_.push_back({static_cast<uint32_t>(l), static_cast<uint32_t>(best_part), best > 0.0f ? 1 : -1});
  }
}

OpeningCount GarmentOpenings::count(const Eigen::Vector4f* x, size_t n, const BodyModel& body) const {
  OpeningCount c;
  c.tracked = static_cast<uint32_t>(pairs_.size());
  if (pairs_.empty()) return c;
  const std::vector<std::vector<Vec3>> parts = bodyPolylines(body);
  std::vector<Vec3> loop;
  for (const Pair& pair : pairs_) {
    loop.clear();
    bool in_range = true;
    for (uint32_t i : loops_[pair.loop]) {
      if (i >= n) {
        in_range = false;
        break;
      }
      loop.push_back(x[i].head<3>());
    }
    const float linking = in_range && pair.polyline < parts.size() ? loopLinking(loop, parts[pair.polyline]) : 0.0f;
    if (!(linking * static_cast<float>(pair.sign) >= kOffLinking)) ++c.off;
  }
  return c;
}

}  // namespace drape
