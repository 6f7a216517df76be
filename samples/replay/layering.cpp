#include "layering.h"

#include <cmath>
#include <limits>

namespace replay {

namespace {

constexpr float kNearM = 0.03f;    // an inner vertex this near lies under (or over) the outer one
constexpr float kUnderM = 0.001f;  // nearer its ellipsoid than that inner vertex by more: under it

struct Host {
  int k = -1;
  float d = 0.0f;
};

Host hostOf(const drape_vec3& p, const std::vector<drape_ellipsoid>& e) {
  Host h;
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return h;
  float best = std::numeric_limits<float>::infinity();
  float bq[3] = {0, 0, 0};
  for (size_t k = 0; k < e.size(); ++k) {
    const drape_ellipsoid& ek = e[k];
    const float d[3] = {p.x - ek.centre.x, p.y - ek.centre.y, p.z - ek.centre.z};
    const drape_vec3* axes[3] = {&ek.axis_x, &ek.axis_y, &ek.axis_z};
    const float r[3] = {ek.radii.x, ek.radii.y, ek.radii.z};
    float q[3], q2 = 0.0f;
    for (int a = 0; a < 3; ++a) {
      q[a] = (axes[a]->x * d[0] + axes[a]->y * d[1] + axes[a]->z * d[2]) / r[a];
      q2 += q[a] * q[a];
    }
    if (q2 < best) {
      best = q2;
      h.k = static_cast<int>(k);
      for (int a = 0; a < 3; ++a) bq[a] = q[a];
    }
  }
  if (h.k >= 0 && best > 1.0f) {
    // grad |q| = to_unit^T q / |q|, to_unit = diag(1 / r) R^T: its norm is |(q_a / r_a)_a| / |q|.
    const drape_ellipsoid& ek = e[static_cast<size_t>(h.k)];
    const float r[3] = {ek.radii.x, ek.radii.y, ek.radii.z};
    const float s = std::sqrt(best);
    float g2 = 0.0f;
    for (int a = 0; a < 3; ++a) g2 += (bq[a] / r[a]) * (bq[a] / r[a]);
    const float g = std::sqrt(g2) / s;
    h.d = g > 0.0f ? (s - 1.0f) / g : std::numeric_limits<float>::infinity();
  }
  return h;
}

}  // namespace

void addLayerCrossing(const std::vector<drape_vec3>& outer, const std::vector<drape_vec3>& inner,
                      const std::vector<drape_ellipsoid>& ellipsoids, LayerCrossing& crossing) {
  // The inner vertices by ellipsoid (a counting sort), so that an outer vertex looks at those on
  // its own only.
  std::vector<int>& hk = crossing.inner_host;
  std::vector<float>& hd = crossing.inner_dist;
  std::vector<uint32_t>& start = crossing.by_ellipsoid_start;
  std::vector<uint32_t>& items = crossing.by_ellipsoid;
  hk.resize(inner.size());
  hd.resize(inner.size());
  start.assign(ellipsoids.size() + 1, 0);
  for (size_t j = 0; j < inner.size(); ++j) {
    const Host h = hostOf(inner[j], ellipsoids);
    hk[j] = h.k;
    hd[j] = h.d;
    if (h.k >= 0) ++start[static_cast<size_t>(h.k) + 1];
  }
  for (size_t k = 0; k < ellipsoids.size(); ++k) start[k + 1] += start[k];
  items.resize(start[ellipsoids.size()]);
  // Each bucket in ascending j (start[k] advances to the bucket's end, then all shift back), so
  // the nearest inner vertex is the first of equals, as a scan over every inner vertex finds it.
  for (size_t j = 0; j < inner.size(); ++j)
    if (hk[j] >= 0) items[start[static_cast<size_t>(hk[j])]++] = static_cast<uint32_t>(j);
  for (size_t k = ellipsoids.size(); k > 0; --k) start[k] = start[k - 1];
  start[0] = 0;
  for (const drape_vec3& p : outer) {
    const Host h = hostOf(p, ellipsoids);
    if (h.k < 0) continue;
    float nearest = kNearM * kNearM;
    int jn = -1;
    for (uint32_t t = start[static_cast<size_t>(h.k)]; t < start[static_cast<size_t>(h.k) + 1]; ++t) {
      const uint32_t j = items[t];
      const float dx = inner[j].x - p.x, dy = inner[j].y - p.y, dz = inner[j].z - p.z;
      const float d2 = dx * dx + dy * dy + dz * dz;
      if (d2 < nearest) {
        nearest = d2;
        jn = static_cast<int>(j);
      }
    }
    if (jn < 0) continue;
    ++crossing.over;
    if (h.d < hd[static_cast<size_t>(jn)] - kUnderM) ++crossing.under;
  }
  ++crossing.frames;
}

}  // namespace replay
