// A bounding volume hierarchy over the body's triangles: exact closest point, signed distance.
//
// Drape collides cloth with ellipsoids (paper §3.3); this structure exists to measure what the
// ellipsoids replace — the body mesh itself — and to score how well the ellipsoids fit it
// (proxies/fidelity.h). It is a plain CPU structure, rebuilt or refitted every frame.
//
// Tree: axis-aligned boxes, binary, built top-down by a median split of the triangle centroids
// along the widest centroid axis, at most kLeafSize triangles per leaf. The median split keeps the
// depth at ceil(log2(n / kLeafSize)) + 1, so a fixed traversal stack of kStackSize entries is
// always enough and no query recurses. Nodes are stored depth first (a node's children come after
// it), so refit is one backward sweep. Triangle corners are copied in leaf order for locality.
//
// Queries are const and keep no state (depthsInside's scratch is the calling thread's), so several
// threads may query one tree at once (not while it is being built or refitted).
//
// Refit: the body's topology is fixed and only its vertices move, so every frame after the first
// rewrites the corner copies, face / edge / vertex pseudo-normals and node boxes in place without
// allocating. The tree's split structure stays the one chosen at build time. Answers stay exact
// whatever the pose (the boxes are recomputed from the moved triangles); only the query speed can
// degrade when the mesh is deformed far from the build pose. The body's rings move with their
// bones, so triangles grouped together at build time stay close together.
//
// Signed distance (Baerentzen & Aanaes, "Signed distance computation using the angle weighted
// pseudonormal", IEEE TVCG 11(3), 2005). The sign of p is the sign of (p - c) · n where c is the
// closest point on the mesh and n the pseudo-normal of the feature c lies on:
//   - face interior: the face normal;
//   - edge interior: the normalised sum of the two adjacent face normals;
//   - vertex: the angle-weighted sum of the incident face normals (each weighted by the face's
//     interior angle at the vertex), normalised.
// For a closed, consistently wound (outward), non-self-intersecting 2-manifold the sign is
// provably correct for every point that is not on the surface, including points whose closest
// point is an edge or a vertex, where the face normal of whichever triangle the search happened
// to return would be wrong. Where the mesh intersects itself no local rule is correct: a point
// whose closest point lies on surface buried inside another part of the solid gets the sign of
// that buried sheet. The body mesh does intersect itself — in the default rest pose 24 of its
// 3 134 triangles (the shoulder stitch into the first arm ring, and the crotch bridge into the
// first leg rings) lie inside the body — and there the generalised winding number
// (body/mesh_metrics.h) is the reference; tests/native/test_mesh_bvh.cpp counts how often it
// matters (10 of its 3 000 probe points around the body). Degenerate (zero-area) triangles
// contribute nothing to the pseudo-normals.
#pragma once

#include "common/math.h"

#include <cstdint>
#include <limits>
#include <vector>

namespace drape {

// Which feature of triangle (a, b, c) a closest point lies on.
enum class TriangleFeature : int8_t { Face = 0, EdgeAB, EdgeBC, EdgeCA, VertexA, VertexB, VertexC };

// Closest point on triangle (a, b, c) to p (Ericson, "Real-Time Collision Detection", 5.1.5,
// Voronoi regions of the triangle's features). Exact up to float rounding; never divides by zero
// for a non-degenerate triangle and returns a point of the triangle for a degenerate one.
Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                            TriangleFeature* feature = nullptr);

class TriangleBvh {
 public:
  static constexpr int kLeafSize = 4;
  static constexpr int kStackSize = 64;

  struct Hit {
    Vec3 point = Vec3::Zero();       // closest point on the mesh
    float distance = std::numeric_limits<float>::infinity();  // |p - point|
    int triangle = -1;               // index into indices / 3; -1 when nothing within range
    Vec3 normal = Vec3::Zero();      // the triangle's outward unit face normal
    Vec3 pseudo_normal = Vec3::Zero();  // unit pseudo-normal of the feature `point` lies on
    TriangleFeature feature = TriangleFeature::Face;
  };

  // Builds the tree over positions / indices (counter-clockwise = outward). When the index buffer
  // and vertex count equal the previous build's and allow_refit is true, this is a refit (no
  // allocation). Returns false, leaving an empty tree, when the input is unusable: index count
  // not a multiple of 3, an index out of range, a non-finite position, or more than 2^31
  // triangles. An empty tree answers every query with a miss.
  bool build(const std::vector<Vec3>& positions, const std::vector<uint32_t>& indices,
             bool allow_refit = true);

  // Same topology, moved vertices: recomputes corner copies, pseudo-normals and boxes. No
  // allocation. Returns false (and changes nothing) when positions.size() differs from the build.
  bool refit(const std::vector<Vec3>& positions);

  // Closest point on the mesh to p among triangles closer than max_distance. A miss has
  // triangle == -1, distance == +inf and point == p.
  Hit closest(const Vec3& p, float max_distance = std::numeric_limits<float>::infinity()) const;

  // The same answer without the tree: every triangle tested (O(m)), for measurement and tests.
  Hit closestBruteForce(const Vec3& p) const;

  // Signed distance to the mesh, negative inside; +inf for an empty tree. The sign is the local
  // pseudo-normal rule above: wrong near surface buried inside another part of the solid.
  float signedDistance(const Vec3& p) const;

  // Winding number of the (closed, outward-wound) mesh around p: 0 outside, 1 inside, 2 where two
  // overlapping parts of the solid both contain p. Counted as the signed crossings of a ray from p
  // (+1 where it leaves through a face, -1 where it enters), so a buried sheet crossed on the way
  // out counts once each way and cancels: the answer is the generalised winding number's
  // (body/mesh_metrics.h) rounded, at the cost of a ray query instead of a sum over every
  // triangle. The first ray is the one of six fixed directions that leaves the tree's box soonest
  // (the fewest boxes to pass). A ray that passes within a rounding tolerance of an edge or a
  // vertex is discarded for another direction; after four such rays the solid-angle sum decides.
  // 0 for an empty tree or a non-finite p.
  int winding(const Vec3& p) const;
  // Depth of p inside the solid the mesh bounds: its distance to the mesh where winding(p) >= 1,
  // else 0. Unlike -signedDistance, a point outside the solid whose closest point lies on a buried
  // sheet (the body's shoulder stitch, crotch bridge) is not inside; a point inside whose closest
  // point is on such a sheet is, with its distance to that sheet (a lower bound of the depth to
  // the outer surface). 0 for an empty tree or a non-finite p.
  float depthInside(const Vec3& p) const;
  // depthInside of n points at once, out[i] for points[i]: on a closed mesh (the body's) the same
  // answers, to the float, for less (drape_garment_measure at 1 809 particles ~1.1 ms instead of
  // ~1.75: docs/body-mesh-collision.md); on a mesh with holes (e.g. refitted to a non-finite
  // vertex) rays along other directions may count otherwise: an answer, finite and >= 0, not
  // necessarily depthInside's. Every ray goes along one fixed direction; instead of the tree, a grid over the plane across that direction, built once per
  // call, lists the triangles whose projection's box covers each cell, and a triangle is passed to
  // the same double-precision crossing test only when the ray's point lies within 0.1 mm of its
  // projection (a ray crosses it, or grazes it closely enough to be ambiguous, only inside that).
  // A point whose ray is ambiguous goes the one-point way (other directions, the solid angles).
  // The grid lives in scratch memory of the calling thread, kept between calls: several threads
  // may still query one tree at once.
  void depthsInside(const Vec3* points, size_t n, float* out) const;
  // Sign of a hit as described above: +1 outside (or on the surface), -1 inside.
  static float hitSign(const Vec3& p, const Hit& h) {
    return (p - h.point).dot(h.pseudo_normal) < 0.0f ? -1.0f : 1.0f;
  }

  bool empty() const { return nodes_.empty(); }
  int triangleCount() const { return static_cast<int>(tris_.size()); }
  int nodeCount() const { return static_cast<int>(nodes_.size()); }
  int depth() const { return depth_; }
  const std::vector<Vec3>& vertexPseudoNormals() const { return vertex_normals_; }

 private:
  struct Node {
    Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
    uint32_t first = 0;  // leaf: first triangle slot; inner: index of the right child
    uint32_t count = 0;  // leaf: triangle count (> 0); inner: 0 (left child = this + 1)
  };
  struct Tri {
    uint32_t v[3];  // vertex indices
    uint32_t e[3];  // edge ids of (v0 v1), (v1 v2), (v2 v0)
    uint32_t id;    // original triangle index
  };

  void clear();
  uint32_t buildNode(uint32_t begin, uint32_t end, std::vector<Vec3>& centroids, int level);
  void updateGeometry(const std::vector<Vec3>& positions);
  void refitBoxes();
  void testTriangle(uint32_t slot, const Vec3& p, float& best2, Hit& hit) const;
  void finishHit(const Vec3& p, Hit& hit) const;
  // Signed crossings of the ray p + t d, t > 0, with the mesh; false when the ray passes too close
  // to an edge or a vertex, or along a face's plane, to count them reliably.
  bool rayCrossings(const Vec3& p, const Eigen::Vector3d& d, int& crossings) const;

  std::vector<Node> nodes_;
  std::vector<Tri> tris_;          // leaf order
  std::vector<Vec3> corners_;      // 3 per slot, leaf order
  std::vector<Vec3> face_normals_;  // per slot
  std::vector<Vec3> edge_normals_;  // per edge id
  std::vector<Vec3> vertex_normals_;  // per vertex
  std::vector<uint32_t> indices_;  // copy of the built index buffer (refit detection)
  size_t vertex_count_ = 0;
  int depth_ = 0;
};

}  // namespace drape
