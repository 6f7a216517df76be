// Cloth statistics shared by both solvers and the tests: stretch per structural edge and energy.
#pragma once

#include "cloth/garment_topology.h"

#include <cstddef>
#include <vector>

namespace drape {

struct StretchStats {
  float max = 0.0f;   // max over structural edges of |len| / rest - 1 (negative: compressed)
  float p99 = 0.0f;   // 99th percentile (nearest rank) of the same
  float mean = 0.0f;
};

// positions: particleCount() entries, xyz used. `scratch` is resized to the edge count (pass the
// same vector each call to avoid allocation).
StretchStats stretchStats(const GarmentTopology& topology, const Eigen::Vector4f* positions,
                          std::vector<float>& scratch);

struct EnergyStats {
  double kinetic = 0.0;    // J, sum 0.5 m |v|^2 over free particles
  double potential = 0.0;  // J, sum -m g.x over free particles (zero at the origin)
  double total() const { return kinetic + potential; }
};

// Pinned particles (inverse mass 0) are left out: their motion is prescribed.
EnergyStats clothEnergy(const GarmentTopology& topology, const Eigen::Vector4f* positions,
                        const Eigen::Vector4f* velocities, const Vec3& gravity);

// Largest |v| over all particles.
float maxSpeed(const Eigen::Vector4f* velocities, size_t count);

}  // namespace drape
