// Three-component vectors spelled out in scalars, for hot loops over small fixed-size vectors:
// the operations follow Eigen's evaluation order for a fixed 3-vector (a sum of three as
// x + (y + z), Eigen's unrolled reduction; Eigen's cross product), so an optimised build computes
// the same bits as the Eigen expressions they replace. Why: the sanitizer build (-O1) leaves
// Eigen's expression templates as calls, and in loops run for every triangle, segment or particle
// those calls were most of the sanitizer tests' time (docs/robustness.md, "CI time").
#pragma once

#include "common/math.h"

#include <cmath>

namespace drape {

template <class T>
struct Plain3 {
  T x, y, z;
};

template <class T>
inline Plain3<T> plain3(const Vec3& v) {
  return {static_cast<T>(v.x()), static_cast<T>(v.y()), static_cast<T>(v.z())};
}
template <class T>
inline Plain3<T> operator-(const Plain3<T>& a, const Plain3<T>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class T>
inline T dot(const Plain3<T>& a, const Plain3<T>& b) {
  return a.x * b.x + (a.y * b.y + a.z * b.z);
}
template <class T>
inline Plain3<T> cross(const Plain3<T>& a, const Plain3<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T>
inline T norm(const Plain3<T>& a) {
  return std::sqrt(dot(a, a));
}

}  // namespace drape
