// A tracking ellipsoid (paper §3.2): the shape cloth collides with instead of the body's
// triangles. World point p maps to the ellipsoid's unit space by q = S^-1 R^T (p - c); the
// ellipsoid is |q| <= 1 (paper eq. 7-8). The inverse is cached when the ellipsoid is rebuilt each
// frame, so a collision test is one 3x3 multiply and a dot product.
#pragma once

#include "common/math.h"

namespace drape {

struct Ellipsoid {
  Vec3 centre = Vec3::Zero();
  Mat3 rotation = Mat3::Identity();  // columns: the x (forward), y (along the bone), z axes
  Vec3 radii = Vec3::Ones();         // semi-axes along those columns, metres, > 0

  // Cached by refresh(): world -> unit space linear part (S^-1 R^T), and a world AABB.
  Mat3 to_unit = Mat3::Identity();
  Vec3 bounds_min = Vec3::Zero();
  Vec3 bounds_max = Vec3::Zero();

  // Recomputes to_unit and the bounds from centre, rotation, radii.
  void refresh() {
    to_unit = radii.cwiseInverse().asDiagonal() * rotation.transpose();
    // Half extent along world axis i of an oriented ellipsoid: sqrt(sum_j (R_ij r_j)^2).
    const Mat3 scaled = rotation * radii.asDiagonal();
    const Vec3 half = scaled.rowwise().norm();
    bounds_min = centre - half;
    bounds_max = centre + half;
  }

  Vec3 toUnit(const Vec3& p) const { return to_unit * (p - centre); }
  Vec3 fromUnit(const Vec3& q) const { return centre + rotation * radii.cwiseProduct(q); }
  // Implicit value |q|^2 - 1: negative inside.
  float implicit(const Vec3& p) const { return toUnit(p).squaredNorm() - 1.0f; }
};

}  // namespace drape
