#include "mesh_checks.h"

#include <algorithm>
#include <cmath>

namespace replay {

uint64_t countNonFinite(const std::vector<drape_vec3>& v) {
  uint64_t n = 0;
  for (const drape_vec3& p : v)
    n += static_cast<uint64_t>(!std::isfinite(p.x)) + static_cast<uint64_t>(!std::isfinite(p.y)) +
         static_cast<uint64_t>(!std::isfinite(p.z));
  return n;
}

bool isWatertight(const std::vector<uint32_t>& indices, uint32_t vertex_count) {
  if (indices.empty() || indices.size() % 3 != 0) return false;
  // Each undirected edge as a 64-bit key (smaller index high); sorted, every key must occur
  // exactly twice.
  std::vector<uint64_t> edges;
  edges.reserve(indices.size());
  for (size_t t = 0; t < indices.size(); t += 3) {
    const uint32_t v[3] = {indices[t], indices[t + 1], indices[t + 2]};
    if (v[0] >= vertex_count || v[1] >= vertex_count || v[2] >= vertex_count) return false;
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) return false;
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = v[e], b = v[(e + 1) % 3];
      edges.push_back((static_cast<uint64_t>(std::min(a, b)) << 32) | std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i != 2) return false;
    i = j;
  }
  return true;
}

}  // namespace replay
