// Internal to the ellipsoid collider (collision.cpp and collision_batch.cpp): the small vector
// helpers both share, and the broad phase's candidate machinery (gather, covers, iterate), defined
// here so that both translation units inline it.
#pragma once

#include "common/cpu.h"
#include "proxies/collision.h"

#include <cstdint>

#if defined(_MSC_VER)
#include <intrin.h>
#endif
#if defined(__SSE2__) || defined(_M_X64)
#include <emmintrin.h>
#endif


namespace drape {
namespace collision_internal {

// A swept contact is answered at the entry point when the discrete response would land more
// than 45 degrees (round the unit sphere) away from it.
constexpr float kDeepContactCos = 0.70710678f;

// The exact contact's float Newton iteration (closestInsideFloat and its batch) stops at |F| below
// this: the point on the surface to 5e-6 of its radius (opencl/collide.cl's closest_inside_float
// holds the same value as a literal).
constexpr float kExactConvergedF = 1e-5f;

inline int lowestBit(uint64_t m) {
#if defined(_MSC_VER)
  unsigned long index = 0;
  _BitScanForward64(&index, m);
  return static_cast<int>(index);
#else
  return __builtin_ctzll(m);
#endif
}

// Cell coordinates of a point (4-wide: the w lane is ignored), clamped to the grid. Monotone in
// each coordinate, so a point inside two boxes lies in a cell both boxes' cell ranges include.
// SSE spelled out as Eigen's packet code has it (max(x, 0) as _mm_max_ps(0, x), min(x, top) as
// _mm_min_ps(top, x), truncating cast): the same bits, and no calls into Eigen's expression
// templates in the sanitizer build (-O1), where they were 8 % of GarmentOnCloseRange's time (perf).
inline Eigen::Array4i cellsOf(const Vec3& p, const Eigen::Array4f& origin, const Eigen::Array4f& scale,
                              const Eigen::Array4f& top) {
#if defined(__SSE2__) || defined(_M_X64)
  const __m128 v = _mm_setr_ps(p.x(), p.y(), p.z(), 0.0f);
  const __m128 scaled = _mm_mul_ps(_mm_sub_ps(v, _mm_loadu_ps(origin.data())), _mm_loadu_ps(scale.data()));
  const __m128 clamped = _mm_min_ps(_mm_loadu_ps(top.data()), _mm_max_ps(_mm_setzero_ps(), scaled));
  Eigen::Array4i out;
  _mm_storeu_si128(reinterpret_cast<__m128i*>(out.data()), _mm_cvttps_epi32(clamped));
  return out;
#else
  const Eigen::Array4f v(p.x(), p.y(), p.z(), 0.0f);
  return ((v - origin) * scale).max(Eigen::Array4f::Zero()).min(top).cast<int>();
#endif
}

using Vec4 = Eigen::Vector4f;
// xyz0 built in registers: going through a 12-byte store and a 16-byte load stalls on store
// forwarding (it cost more than the narrow test itself).
#if defined(__SSE2__) || defined(_M_X64)
inline Vec4 lift(const Vec3& v) {
  const __m128 xy = _mm_unpacklo_ps(_mm_set_ss(v.x()), _mm_set_ss(v.y()));
  Vec4 out;
  _mm_store_ps(out.data(), _mm_movelh_ps(xy, _mm_set_ss(v.z())));
  return out;
}
#else
inline Vec4 lift(const Vec3& v) { return Vec4(v.x(), v.y(), v.z(), 0.0f); }
#endif
// q = U d for U given by its columns (w lanes 0).
inline Vec4 mulq(const Vec4* u, const Vec4& d) {
  return u[0] * d.x() + u[1] * d.y() + u[2] * d.z();
}
// Box tests on 4 lanes (w lanes are 0 on both sides, so they always pass), one branch.
#if defined(__SSE2__) || defined(_M_X64)
inline bool overlaps4(const Vec4& lo, const Vec4& hi, const Vec4& mn, const Vec4& mx) {
  const __m128 in = _mm_and_ps(_mm_cmple_ps(_mm_load_ps(lo.data()), _mm_load_ps(mx.data())),
                               _mm_cmpge_ps(_mm_load_ps(hi.data()), _mm_load_ps(mn.data())));
  return _mm_movemask_ps(in) == 0xF;
}
inline bool contains4(const Vec4& mn, const Vec4& mx, const Vec4& p) {
  return overlaps4(p, p, mn, mx);
}
#else
inline bool overlaps4(const Vec4& lo, const Vec4& hi, const Vec4& mn, const Vec4& mx) {
  return ((lo.array() <= mx.array()).cast<int>() * (hi.array() >= mn.array()).cast<int>()).sum() == 4;
}
inline bool contains4(const Vec4& mn, const Vec4& mx, const Vec4& p) {
  return overlaps4(p, p, mn, mx);
}
#endif


}  // namespace collision_internal

// The broad phase's candidates (declared in collision.h).
DRAPE_ALWAYS_INLINE bool EllipsoidCollider::gather(const Vec3& lo, const Vec3& hi, bool use_grid,
                                                   const uint64_t* allowed, Candidates& c) const {
  if (!overlaps(lo, hi, grid_min_, grid_max_)) return false;  // outside every swept box
  c.all = !use_grid;
  c.allowed = allowed;
  if (c.all) return true;
  c.lo = collision_internal::cellsOf(lo, cell_origin_, cell_scale_, cell_top_);
  c.hi = collision_internal::cellsOf(hi, cell_origin_, cell_scale_, cell_top_);
  if ((c.lo == c.hi).all()) {  // the usual case: one cell
    const uint64_t* cell =
        &cells_[static_cast<size_t>(((c.lo[2] * dims_[1] + c.lo[1]) * dims_[0] + c.lo[0]) * words_)];
    if (allowed) {
      for (int w = 0; w < words_; ++w) c.mask[w] = cell[w] & allowed[w];
    } else {
      for (int w = 0; w < words_; ++w) c.mask[w] = cell[w];
    }
    return true;
  }
  for (int w = 0; w < words_; ++w) c.mask[w] = 0;
  for (int z = c.lo[2]; z <= c.hi[2]; ++z) {
    for (int y = c.lo[1]; y <= c.hi[1]; ++y) {
      for (int x = c.lo[0]; x <= c.hi[0]; ++x) {
        const uint64_t* cell = &cells_[static_cast<size_t>(((z * dims_[1] + y) * dims_[0] + x) * words_)];
        for (int w = 0; w < words_; ++w) c.mask[w] |= cell[w];
      }
    }
  }
  if (allowed)
    for (int w = 0; w < words_; ++w) c.mask[w] &= allowed[w];
  return true;
}

inline bool EllipsoidCollider::covers(const Candidates& c, const Vec3& p) const {
  if (c.all) return true;
  const Eigen::Array4i i = collision_internal::cellsOf(p, cell_origin_, cell_scale_, cell_top_);
  return (i >= c.lo).all() && (i <= c.hi).all();
}

template <class F>
void EllipsoidCollider::iterate(const Candidates& c, F&& f) const {
  if (c.all) {
    const int n = count();
    for (int k = 0; k < n; ++k)
      if (!c.allowed || ((c.allowed[k >> 6] >> (k & 63)) & 1u)) f(k);
    return;
  }
  for (int w = 0; w < words_; ++w) {
    uint64_t m = c.mask[w];
    while (m) {
      const int k = (w << 6) + collision_internal::lowestBit(m);
      m &= m - 1;
      f(k);
    }
  }
}

// Collide()'s cheap rejections before anything else: a pinned particle (w <= 0), one nowhere near
// any ellipsoid's (swept) box, one not finite. NaN fails every comparison and is rejected by the
// box test too, unless the previous position is finite.
inline bool EllipsoidCollider::mayTouch(const Eigen::Vector4f* positions, const Eigen::Vector4f* previous,
                                        size_t i, bool swept) const {
  if (!(positions[i].w() > 0.0f)) return false;
  const Vec3 x = positions[i].head<3>();
  if (!containsPoint(grid_min_, grid_max_, x)) {
    if (!swept) return false;
    const Vec3 p0 = previous[i].head<3>();
    if (!overlaps(x.cwiseMin(p0), x.cwiseMax(p0), grid_min_, grid_max_)) return false;
  }
  return isFinite(x);
}

}  // namespace drape
