// Garment topology: what the cloth solvers need from a triangle mesh, built once per garment.
// Structure of arrays, constraints sorted by graph colour so that every colour group can be solved
// in parallel (one work-item per constraint in an OpenCL port) while the solver stays
// Gauss–Seidel across colours. Method and choices: docs/cloth-solver.md.
//
// Constraint kinds (all are distance constraints, one kernel for all):
//  - stretch: every mesh edge (quads split by the caller, so quad diagonals are edges too);
//  - shear:   across an interior edge that is the longest edge of both its triangles (the diagonal
//             of a split quad), the distance between the two opposite vertices (the quad's other
//             diagonal);
//  - bend:    across every other interior edge, the distance between the two opposite vertices
//             ("bending distance", as PhysX / NvCloth bend constraints). Not dihedral-angle and not
//             isometric (Bergou/Wardetzky) bending: see docs/cloth-solver.md;
//  - tether:  each free particle to its nearest pinned particles (NvCloth long-range attachment):
//             an inequality, |x - anchor| <= scale * rest, rest = Euclidean distance at rest.
//
// Building never throws and never asserts: bad input returns false with a message and leaves the
// output untouched (it sits behind the C ABI).
#pragma once

#include "common/math.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace drape {

// A set of two-particle constraints, sorted by colour: colour c owns the index range
// [colour_offsets[c], colour_offsets[c + 1]). Within one colour no two constraints share a
// particle that the solver writes (for tethers the anchor is pinned and only read, so tethers
// are coloured by their free particle `a` alone).
struct DistanceConstraints {
  std::vector<uint32_t> a, b;
  std::vector<float> rest;
  std::vector<uint32_t> colour_offsets{0};

  size_t size() const { return a.size(); }
  size_t colours() const { return colour_offsets.size() - 1; }
};

struct TopologyParams {
  float area_density = 0.2f;        // kg/m^2 (light cotton shirt ~0.1-0.2)
  std::vector<uint32_t> pinned;     // vertex indices attached to the body (inverse mass 0)
  int max_tethers_per_particle = 2; // nearest pinned particles in the same connected piece; 0: none
};

struct GarmentTopology {
  std::vector<Vec3> rest_positions;  // metres
  std::vector<float> mass;           // kg, lumped (each triangle's mass split in thirds)
  std::vector<float> inverse_mass;   // 1/mass, 0 for pinned particles
  std::vector<uint32_t> pinned;      // pinned vertex indices, sorted, unique
  std::vector<uint32_t> triangles;   // 3 indices per triangle (as given)
  DistanceConstraints stretch, shear, bend, tether;
  // The edges of the mesh's closed boundary loops (boundaryLoops: cuffs, hems, collar), coloured
  // like the constraints; rest = rest length. Not constraints: the solvers collide them as edges
  // (EllipsoidCollider::collideRims).
  DistanceConstraints rims;

  size_t particleCount() const { return rest_positions.size(); }
};

// positions: vertex_count xyz triples (metres); indices: index_count = 3 * triangles.
// Rejects: no vertices or no triangles, index_count not a multiple of 3, an index out of range,
// a non-finite position, a degenerate triangle (repeated index or area below 1e-12 m^2),
// a non-positive or non-finite density, a pinned index out of range, a vertex used by no triangle,
// negative max_tethers_per_particle.
bool buildGarmentTopology(const float* positions, size_t vertex_count, const uint32_t* indices,
                          size_t index_count, const TopologyParams& params, GarmentTopology& out,
                          std::string& error);

// The closed boundary loops of a triangle mesh, each in order along the loop (its direction is
// the walk's, not the faces'). Boundary edges (used by one triangle) are walked as an undirected
// graph, so a flipped face beside a pinch vertex (the MakeHuman elegant suit's lapel) does not
// break a loop; an open chain (an odd-degree vertex) is no loop and is dropped, as are loops of
// fewer than three vertices. Triangles with an index >= vertex_count and degenerate edges are
// ignored. Loops come in the order of their first edge, (min, max) index pairs sorted.
std::vector<std::vector<uint32_t>> boundaryLoops(const std::vector<uint32_t>& triangles, size_t vertex_count);

// Greedy deterministic colouring: constraints are visited in order, each takes the smallest colour
// used by none of its particles (only `a` when `colour_b` is false); the set is then stably sorted
// by colour and colour_offsets filled. Exposed for tests.
void colourConstraints(DistanceConstraints& c, size_t particle_count, bool colour_b);

// A rectangular grid of nx * ny particles spanning width x height, in the plane spanned by the
// unit axes `u` (along x index) and `v` (along y index) from `origin`; quads split along the
// (i, j) - (i+1, j+1) diagonal. For tests, benchmarks and samples.
void makeClothGrid(int nx, int ny, float width, float height, const Vec3& origin, const Vec3& u,
                   const Vec3& v, std::vector<float>& positions, std::vector<uint32_t>& indices);

}  // namespace drape
