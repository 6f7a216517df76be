// drape-replay's measure of layered garments (--under): of the outer garment's vertices that lie
// over the inner garment, the share that lie under it instead (docs/garments.md, "Layered
// garments"; the same measure as tests/native/test_garment_layers.cpp, through the C ABI only).
#pragma once

#include <drape/drape.h>

#include <cstdint>
#include <vector>

namespace replay {

struct LayerCrossing {
  uint64_t over = 0;   // outer vertices with an inner vertex on the same ellipsoid within 3 cm
  uint64_t under = 0;  // of those, nearer that ellipsoid than the nearest such inner vertex by > 1 mm
  uint32_t frames = 0;
  double underShare() const { return over > 0 ? static_cast<double>(under) / static_cast<double>(over) : 0.0; }
  // addLayerCrossing's scratch (each inner vertex's ellipsoid and distance, the inner vertices by
  // ellipsoid), kept so that a frame allocates nothing once the sizes settle.
  std::vector<int> inner_host;
  std::vector<float> inner_dist;
  std::vector<uint32_t> by_ellipsoid_start, by_ellipsoid;
};

// Each vertex lies on the ellipsoid it is deepest in or nearest to (the smallest |q| in its unit
// space), at its distance outside it ((|q| - 1) / |grad |q||, 0 inside): the library's
// ClothShell measure. Adds one frame's outer / inner vertices (non-finite ones skipped).
void addLayerCrossing(const std::vector<drape_vec3>& outer, const std::vector<drape_vec3>& inner,
                      const std::vector<drape_ellipsoid>& ellipsoids, LayerCrossing& crossing);

}  // namespace replay
