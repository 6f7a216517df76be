// Closest point on an axis-aligned ellipsoid x²/a² + y²/b² + z²/c² = 1 to a point given in the
// ellipsoid's own frame (D. Eberly, "Distance from a Point to an Ellipse, an Ellipsoid, or a
// Hyperellipsoid", 2013). The point may be inside, outside, on the surface, on an axis or at the
// centre; the computation is in double. See docs/collision.md.
#pragma once

#include "common/math.h"

namespace drape {

// Reference: Eberly's algorithm with pure bisection on the root of
// F(s) = sum_i (r_i z_i / (s + r_i))^2 - 1, run until the bracket stops shrinking in double.
// `radii` must be positive and finite; otherwise (and for a non-finite point) `local_point` is
// returned unchanged with distance 0. `distance` (optional) receives |result - local_point| >= 0.
Vec3 closestPointOnEllipsoid(const Vec3& radii, const Vec3& local_point, float* distance = nullptr);

// Same algorithm and result (distances agree to ~1e-6 relative), with the root found by Halley
// steps safeguarded by the bisection bracket: 2-3 evaluations for the points a collision test
// produces (within a few millimetres of the surface) instead of ~60 to ~1100. This is what the
// collider's Exact response uses.
Vec3 closestPointOnEllipsoidFast(const Vec3& radii, const Vec3& local_point, float* distance = nullptr);

}  // namespace drape
