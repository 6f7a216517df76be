// Small geometry vocabulary shared by every stage. Eigen does the arithmetic; these aliases keep
// signatures short and make the float/double choice in one place (float: it is what the GPU and
// the C ABI carry).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>

namespace drape {

using Vec3 = Eigen::Vector3f;
using Mat3 = Eigen::Matrix3f;
using Quat = Eigen::Quaternionf;

constexpr float kPi = 3.14159265358979323846f;

inline bool isFinite(const Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

// Whether p lies in the box [mn, mx] (bounds included; false for a NaN coordinate). The
// comparisons are combined with & as integers rather than &&: no branch per comparison (random
// particle data mispredicts), no compiler taking the & for a mistyped &&, and no Eigen array
// calls in the sanitizer build (-O1), where this runs for every particle and ellipsoid.
inline bool containsPoint(const Vec3& mn, const Vec3& mx, const Vec3& p) {
  const unsigned inside = unsigned(p.x() >= mn.x()) & unsigned(p.x() <= mx.x()) &
                          unsigned(p.y() >= mn.y()) & unsigned(p.y() <= mx.y()) &
                          unsigned(p.z() >= mn.z()) & unsigned(p.z() <= mx.z());
  return inside != 0u;
}

// Whether the boxes [lo, hi] and [mn, mx] meet (touching counts; false for a NaN coordinate), with
// & as containsPoint.
inline bool overlaps(const Vec3& lo, const Vec3& hi, const Vec3& mn, const Vec3& mx) {
  const unsigned overlap = unsigned(lo.x() <= mx.x()) & unsigned(hi.x() >= mn.x()) &
                           unsigned(lo.y() <= mx.y()) & unsigned(hi.y() >= mn.y()) &
                           unsigned(lo.z() <= mx.z()) & unsigned(hi.z() >= mn.z());
  return overlap != 0u;
}

// A unit vector perpendicular to `n` (n need not be normalised but must be non-zero).
inline Vec3 anyPerpendicular(const Vec3& n) {
  const Vec3 a = std::fabs(n.x()) < 0.9f * n.norm() ? Vec3::UnitX() : Vec3::UnitY();
  return n.cross(a).normalized();
}

// The shortest rotation taking the direction of `from` to that of `to` (neither need be unit
// length; both non-zero): Eigen's Quaternion::FromTwoVectors, compiled once in math.cpp.
Quat rotationBetween(const Vec3& from, const Vec3& to);

}  // namespace drape
