#include "cloth/cloth_stats.h"

#include "common/plain3.h"

#include <algorithm>
#include <cmath>

namespace drape {

StretchStats stretchStats(const GarmentTopology& topology, const Eigen::Vector4f* positions,
                          std::vector<float>& scratch) {
  StretchStats s;
  const DistanceConstraints& c = topology.stretch;
  const size_t n = c.size();
  if (n == 0 || positions == nullptr) return s;
  scratch.resize(n);
  double sum = 0.0;
  float mx = -1.0f;
  for (size_t k = 0; k < n; ++k) {
    // Plain3 (common/plain3.h): the same bits, and no Eigen calls in the sanitizer build, which
    // measures every edge of every garment on every measured frame.
    const float len = norm(plain3(positions[c.a[k]]) - plain3(positions[c.b[k]]));
    const float r = c.rest[k] > 0.0f ? len / c.rest[k] - 1.0f : 0.0f;
    scratch[k] = r;
    mx = std::max(mx, r);
    sum += static_cast<double>(r);
  }
  // Nearest rank: the smallest value with at least 99 % of the edges at or below it.
  const size_t rank = static_cast<size_t>(std::ceil(0.99 * static_cast<double>(n)));
  const size_t idx = rank == 0 ? 0 : rank - 1;
  std::nth_element(scratch.begin(), scratch.begin() + static_cast<std::ptrdiff_t>(idx),
                   scratch.end());
  s.max = mx;
  s.p99 = scratch[idx];
  s.mean = static_cast<float>(sum / static_cast<double>(n));
  return s;
}

EnergyStats clothEnergy(const GarmentTopology& topology, const Eigen::Vector4f* positions,
                        const Eigen::Vector4f* velocities, const Vec3& gravity) {
  EnergyStats e;
  for (size_t i = 0; i < topology.particleCount(); ++i) {
    if (topology.inverse_mass[i] == 0.0f) continue;
    const double m = static_cast<double>(topology.mass[i]);
    e.kinetic += 0.5 * m * static_cast<double>(velocities[i].head<3>().squaredNorm());
    e.potential -= m * static_cast<double>(gravity.dot(positions[i].head<3>()));
  }
  return e;
}

float maxSpeed(const Eigen::Vector4f* velocities, size_t count) {
  float m = 0.0f;
  for (size_t i = 0; i < count; ++i) m = std::max(m, velocities[i].head<3>().norm());
  return m;
}

}  // namespace drape
