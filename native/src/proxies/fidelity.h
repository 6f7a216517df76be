// How well a set of ellipsoids stands in for the body mesh, both ways, in millimetres.
//
// body -> union: every body-mesh *vertex* is scored by its distance outside the union of the
// ellipsoids (0 inside any). Vertices, not an area sampling: the body's vertices are denser where
// rings are small (K points around a wrist as around the chest) and where rings are close
// together, so hands, feet, head and limb ends weigh more per square metre than the torso. The
// per-vertex statistics carry that bias; body_to_union_area_mean_mm removes it by weighting each
// vertex with a third of the area of its triangles.
//
// union -> body: points on each ellipsoid's surface (a Fibonacci sphere of samples_per_ellipsoid
// points mapped through the ellipsoid) that are not strictly inside another ellipsoid — i.e. on
// the boundary of the union — scored by their unsigned distance to the body mesh: where an
// ellipsoid bulges out of the body and where the union sinks below it. The Fibonacci sphere is
// uniform on the unit sphere, but the map stretches area by r0·r1·r2·|S^-1 u| (u the unit-sphere
// point, S = diag(radii)): along a long axis a sample covers less area than around the waist of
// the ellipsoid, so the ends of elongated ellipsoids are over-sampled, and each ellipsoid gets the
// same count whatever its size, so small ellipsoids are over-sampled against large ones. The
// per-sample statistics carry that bias; union_to_body_area_mean_mm weights each sample by its
// area element (the weights sum to the union's area, up to sampling error).
//
// Distance from a body sample outside an ellipsoid to the ellipsoid's surface: the exact closest
// point from closestPointOnEllipsoid (proxies/closest_point.h: Eberly's robust bisection in
// double), in the ellipsoid's frame.
// Ellipsoids whose bounding box is farther than the best distance so far are skipped, the nearest
// box first. measureFidelity refreshes its own copies of the ellipsoids, so callers need not.
#pragma once

#include "common/math.h"
#include "proxies/ellipsoid.h"
#include "proxies/mesh_bvh.h"

#include <cstdint>
#include <vector>

namespace drape {

struct FidelityReport {
  // body -> union, per body vertex (0 when inside any ellipsoid); mm. +inf with no ellipsoids.
  float body_to_union_mean_mm = 0.0f, body_to_union_p95_mm = 0.0f, body_to_union_max_mm = 0.0f;
  float body_to_union_area_mean_mm = 0.0f;  // each vertex weighted by 1/3 of its triangles' area
  float outside_fraction = 0.0f;  // fraction of body samples (vertices and triangle centroids) outside every ellipsoid by > 0.5 mm
  // union -> body: how far the union's surface samples lie outside the body mesh (0 where they
  // are inside it: those are gaps, measured by body -> union); mm.
  float union_to_body_mean_mm = 0.0f, union_to_body_p95_mm = 0.0f, union_to_body_max_mm = 0.0f;
  float union_to_body_area_mean_mm = 0.0f;  // each sample weighted by its surface area element
  int union_samples = 0;  // samples kept (on the union's boundary)
  int body_vertices = 0;  // vertices scored
};

// Distance threshold above which a vertex counts as outside (outside_fraction).
constexpr float kFidelityOutsideMm = 0.5f;

// p95 is the nearest-rank 95th percentile. `bvh` must be built over body_positions /
// body_indices (it answers the union -> body distances). Invalid input (out-of-range indices,
// count < 0, null ellipsoids with count > 0) is ignored as far as it can be: bad triangles get no
// area, a null / empty ellipsoid set scores every vertex +inf.
FidelityReport measureFidelity(const std::vector<Vec3>& body_positions,
                               const std::vector<uint32_t>& body_indices,
                               const Ellipsoid* ellipsoids, int count, const TriangleBvh& bvh,
                               int samples_per_ellipsoid = 256);

// Distance from p to the union of ellipsoids[0, count) but `skip` (SIZE_MAX: none), metres: 0 when
// p is inside one of them, +inf when none is left. The ellipsoids' bounds must be current
// (refresh()); `box_scratch` is resized as needed (pass the same vector to reuse its memory). The
// per-sample distance of measureFidelity's body -> union direction, for callers that measure
// parts of a union (tests of the fills).
float distanceOutsideUnion(const Ellipsoid* ellipsoids, size_t count, const Vec3& p, std::vector<float>& box_scratch,
                           size_t skip = SIZE_MAX);

// Closest point on the ellipsoid's surface to p (inside or outside), and the unsigned distance.
// closestPointOnEllipsoid (proxies/closest_point.h) in the ellipsoid frame. Reads only centre, rotation and radii (no refresh()
// needed). Radii that are not all positive and finite give the centre and |p - centre|.
struct EllipsoidSurfacePoint {
  Vec3 point = Vec3::Zero();
  float distance = 0.0f;
};
EllipsoidSurfacePoint ellipsoidSurfacePoint(const Ellipsoid& e, const Vec3& p);

// i-th of n points of the Fibonacci (golden-angle) sphere, unit length.
Vec3 fibonacciSpherePoint(int i, int n);

}  // namespace drape
