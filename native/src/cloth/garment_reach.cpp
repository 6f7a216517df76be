#include "cloth/garment_reach.h"

#include "cloth/garment_sim.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <queue>
#include <utility>

namespace drape {

std::vector<ReachSphere> garmentReach(const GarmentSim& garment, const ReachParams& params) {
  const GarmentTopology& topo = garment.topology();
  const GarmentMesh& mesh = garment.mesh();
  const std::vector<uint8_t>& masks = garment.particleMasks();
  const size_t n = topo.particleCount();
  constexpr float kUnreached = std::numeric_limits<float>::infinity();

  // Multi-source Dijkstra from the attached particles over the mesh edges (the stretch
  // constraints are every edge, with its rest length).
  std::vector<std::vector<std::pair<uint32_t, float>>> adjacency(n);
  const DistanceConstraints& edges = topo.stretch;
  for (size_t e = 0; e < edges.size(); ++e) {
    adjacency[edges.a[e]].push_back({edges.b[e], edges.rest[e]});
    adjacency[edges.b[e]].push_back({edges.a[e], edges.rest[e]});
  }
  std::vector<float> dist(n, kUnreached);
  std::vector<int> source(n, -1);  // attachment (index into mesh.pinned) a particle is nearest to
  using Item = std::pair<float, uint32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  for (size_t k = 0; k < mesh.pinned.size(); ++k) {
    const uint32_t p = mesh.pinned[k];
    if (p >= n) continue;
    dist[p] = 0.0f;
    source[p] = static_cast<int>(k);
    open.push({0.0f, p});
  }
  while (!open.empty()) {
    const auto [d, p] = open.top();
    open.pop();
    if (d > dist[p]) continue;
    for (const auto& [q, len] : adjacency[p]) {
      if (d + len < dist[q]) {
        dist[q] = d + len;
        source[q] = source[p];
        open.push({dist[q], q});
      }
    }
  }

  // One sphere per (ring, mask): the farthest particle of that mask anchored on that ring, plus
  // the farthest attachment from the ring's centre.
  std::map<std::pair<int, uint8_t>, float> far;  // (ring, mask) -> geodesic distance
  std::map<int, float> pinOffset;                 // ring -> max |pin_local|
  uint8_t loose = 0;                              // masks of particles with no attachment
  for (size_t i = 0; i < n; ++i) {
    const uint8_t m = i < masks.size() ? masks[i] : 0xFF;
    if (source[i] < 0) {
      loose |= m;
      continue;
    }
    const int ring = mesh.pin_ring[static_cast<size_t>(source[i])];
    float& f = far[{ring, m}];
    f = std::max(f, dist[i]);
  }
  for (size_t k = 0; k < mesh.pinned.size(); ++k) {
    float& o = pinOffset[mesh.pin_ring[k]];
    o = std::max(o, mesh.pin_local[k].norm());
  }
  std::vector<ReachSphere> out;
  for (const auto& [key, d] : far) {
    ReachSphere s;
    s.ring = key.first;
    s.groups = key.second;
    s.radius_m = pinOffset[key.first] + params.stretch_allowance * d + params.margin_m;
    out.push_back(s);
  }
  if (loose != 0) out.push_back(ReachSphere{-1, loose, kUnreached});
  return out;
}

std::vector<float> ellipsoidBoundRadii(const BodyModel& body, const std::vector<Ellipsoid>& ellipsoids,
                                       const std::vector<ProxySource>& sources, float scale, float pad_m) {
  std::vector<float> out(ellipsoids.size(), 0.0f);
  const auto& rings = body.rings();
  for (size_t k = 0; k < ellipsoids.size() && k < sources.size(); ++k) {
    const int r = std::clamp(sources[k].first_ring, 0, static_cast<int>(rings.size()) - 1);
    const float reach = (ellipsoids[k].centre - rings[static_cast<size_t>(r)].centre).norm() +
                        ellipsoids[k].radii.maxCoeff();
    out[k] = scale * reach + pad_m;
  }
  return out;
}

void markReachable(const std::vector<ReachSphere>& spheres, const std::vector<RingPose>& rings,
                   const std::vector<ProxySource>& sources, const std::vector<float>& bound_radii,
                   std::vector<uint8_t>& reach) {
  const int ringCount = static_cast<int>(rings.size());
  for (size_t k = 0; k < reach.size() && k < sources.size(); ++k) {
    if (reach[k]) continue;
    uint8_t bits = collisionGroups(sources[k]);
    // A leg's ellipsoids may meet torso cloth over that leg (GarmentSim::setLegsTrusted): reach
    // counts them as if trusted, so a leg trusted again finds them built.
    if (bits & chainGroup(Chain::LegL)) bits = static_cast<uint8_t>(bits | kTorsoOverLegL);
    if (bits & chainGroup(Chain::LegR)) bits = static_cast<uint8_t>(bits | kTorsoOverLegR);
    const int r = std::clamp(sources[k].first_ring, 0, ringCount - 1);
    const Vec3& c = rings[static_cast<size_t>(r)].centre;
    const float bound = k < bound_radii.size() ? bound_radii[k] : std::numeric_limits<float>::infinity();
    for (const ReachSphere& s : spheres) {
      if (!(s.groups & bits)) continue;
      if (s.ring < 0 || s.ring >= ringCount ||
          (c - rings[static_cast<size_t>(s.ring)].centre).norm() < s.radius_m + bound) {
        reach[k] = 1;
        break;
      }
    }
  }
}

}  // namespace drape
