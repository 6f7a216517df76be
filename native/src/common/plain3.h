// Three-component vectors spelled out in scalars, for hot loops over small fixed-size vectors:
// the operations follow Eigen's evaluation order for a fixed 3-vector (a sum of three as
// x + (y + z), Eigen's unrolled reduction; Eigen's cross product; component-wise scaling and
// division), so an optimised build computes the same bits as the Eigen expressions they replace.
// Why: the sanitizer build (-O1) leaves Eigen's expression templates as calls, and in loops run for
// every spring, triangle, segment or particle those calls were most of the sanitizer tests' time
// (docs/robustness.md, "CI time"). Always inlined, so that build does not call these either.
#pragma once

#include "common/cpu.h"
#include "common/math.h"

#include <cmath>

namespace drape {

template <class T>
struct Plain3 {
  T x, y, z;
};

template <class T>
DRAPE_ALWAYS_INLINE Plain3<T> plain3(const Vec3& v) {
  return {static_cast<T>(v.x()), static_cast<T>(v.y()), static_cast<T>(v.z())};
}
// xyz of a particle (w, the inverse mass, left out).
DRAPE_ALWAYS_INLINE Plain3<float> plain3(const Eigen::Vector4f& v) { return {v.x(), v.y(), v.z()}; }
DRAPE_ALWAYS_INLINE Vec3 toVec3(const Plain3<float>& v) { return Vec3(v.x, v.y, v.z); }

template <class T>
DRAPE_ALWAYS_INLINE Plain3<T> operator-(const Plain3<T>& a, const Plain3<T>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class T>
DRAPE_ALWAYS_INLINE Plain3<T> operator*(T s, const Plain3<T>& a) {
  return {s * a.x, s * a.y, s * a.z};
}
template <class T>
DRAPE_ALWAYS_INLINE Plain3<T> operator/(const Plain3<T>& a, T s) {
  return {a.x / s, a.y / s, a.z / s};
}
template <class T>
DRAPE_ALWAYS_INLINE T dot(const Plain3<T>& a, const Plain3<T>& b) {
  return a.x * b.x + (a.y * b.y + a.z * b.z);
}
template <class T>
DRAPE_ALWAYS_INLINE Plain3<T> cross(const Plain3<T>& a, const Plain3<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T>
DRAPE_ALWAYS_INLINE T norm(const Plain3<T>& a) {
  return std::sqrt(dot(a, a));
}

// to += a and to -= a on the xyz of an Eigen vector (Vec3 or a particle's Vector4f).
template <class V>
DRAPE_ALWAYS_INLINE void addTo(V& to, const Plain3<float>& a) {
  float* t = to.data();
  t[0] += a.x;
  t[1] += a.y;
  t[2] += a.z;
}
template <class V>
DRAPE_ALWAYS_INLINE void subtractFrom(V& to, const Plain3<float>& a) {
  float* t = to.data();
  t[0] -= a.x;
  t[1] -= a.y;
  t[2] -= a.z;
}

}  // namespace drape
