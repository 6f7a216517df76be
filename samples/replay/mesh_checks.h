// Checks drape-replay runs on every body mesh it reads: finiteness, watertightness, volume.
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

// Enclosed volume in cubic metres by the divergence theorem: sum over triangles of
// p0 . (p1 x p2) / 6, in double. Positive for a closed mesh wound counter-clockwise seen from
// outside (as Drape's is).
double enclosedVolumeM3(const std::vector<drape_vec3>& positions, const std::vector<uint32_t>& indices);

}  // namespace replay
