// Checks and measures on a triangle mesh: closedness, winding, degeneracy, volume, inside tests.
// Used by the body stage's statistics and by the tests.
#pragma once

#include "common/math.h"

#include <cstdint>
#include <string>
#include <vector>

namespace drape {

struct MeshCheck {
  bool watertight = false;        // every undirected edge in exactly two triangles
  bool consistent_winding = false;  // ... traversed once in each direction
  int boundary_edges = 0;         // edges used once
  int nonmanifold_edges = 0;      // edges used three times or more
  int degenerate_triangles = 0;   // area below min_area or repeated vertex indices
  std::string first_problem;      // human-readable, empty when clean
};

MeshCheck checkMesh(const std::vector<Vec3>& positions, const std::vector<uint32_t>& indices,
                    float min_area_m2 = 1e-9f);

// Signed enclosed volume (m^3); positive for outward (counter-clockwise) winding.
double signedVolume(const std::vector<Vec3>& positions, const std::vector<uint32_t>& indices);

// Generalised winding number of a closed mesh around a point: ~1 inside, ~0 outside.
double windingNumber(const std::vector<Vec3>& positions, const std::vector<uint32_t>& indices,
                     const Vec3& point);
// Signed solid angle of triangle (a, b, c) seen from point p (Van Oosterom & Strackee), in
// steradians: windingNumber sums it over the triangles and divides by 4 pi.
double triangleSolidAngle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// Area-weighted vertex normals into `normals` (resized by the caller to positions.size()).
void vertexNormals(const std::vector<Vec3>& positions, const std::vector<uint32_t>& indices,
                   std::vector<Vec3>& normals);

// Perimeter of a closed polygon.
float polygonPerimeter(const Vec3* points, int count);

}  // namespace drape
