// Checks drape-replay runs on the body mesh it reads: finiteness and watertightness.
#pragma once

#include <drape/drape.h>

#include <cstdint>
#include <vector>

namespace replay {

// Number of NaN/Inf components in `v` (each of x, y, z counts once).
uint64_t countNonFinite(const std::vector<drape_vec3>& v);

// True when the triangle list is closed: every index is below vertex_count, no triangle repeats a
// vertex, and every undirected edge is shared by exactly two triangles.
bool isWatertight(const std::vector<uint32_t>& indices, uint32_t vertex_count);

}  // namespace replay
