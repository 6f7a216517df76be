// Internal to the ellipsoid collider's eight-lane code (collision_eight.cpp,
// collision_eight_contacts.cpp): AVX helpers, each reproducing the scalar path's arithmetic lane by
// lane (Eigen's summation orders, no FMA), so that eight lanes give the one-particle results bit
// for bit. Only for functions compiled with target("avx") and called after cpuHasAvx().
#pragma once

// x86-64 only: the lane masks move through 64-bit general registers (_mm_cvtsi64_si128), which
// 32-bit x86 lacks; there the collider runs one particle at a time.
#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__)
#define DRAPE_COLLISION_AVX 1
#include <immintrin.h>

#include <Eigen/Core>

#include <cstdint>

namespace drape {
namespace collision_avx {

#define DRAPE_AVX_INLINE __attribute__((target("avx"), always_inline)) inline
// The 8 lanes of v.
struct Lanes {
  alignas(32) float v[8];
};
DRAPE_AVX_INLINE __m256 bcast(float f) { return _mm256_set1_ps(f); }
// q = U (p - c) per lane, as mulq: (u0 * d.x + u1 * d.y) + u2 * d.z per component.
DRAPE_AVX_INLINE void unitSpace8(const Eigen::Vector4f* u, const Eigen::Vector4f& cen, __m256 px, __m256 py, __m256 pz, __m256& qx,
                                 __m256& qy, __m256& qz) {
  const __m256 dx = _mm256_sub_ps(px, bcast(cen.x())), dy = _mm256_sub_ps(py, bcast(cen.y())),
               dz = _mm256_sub_ps(pz, bcast(cen.z()));
  qx = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(bcast(u[0].x()), dx), _mm256_mul_ps(bcast(u[1].x()), dy)),
                     _mm256_mul_ps(bcast(u[2].x()), dz));
  qy = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(bcast(u[0].y()), dx), _mm256_mul_ps(bcast(u[1].y()), dy)),
                     _mm256_mul_ps(bcast(u[2].y()), dz));
  qz = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(bcast(u[0].z()), dx), _mm256_mul_ps(bcast(u[1].z()), dy)),
                     _mm256_mul_ps(bcast(u[2].z()), dz));
}
// a.b as Eigen sums a 4-lane packet with w = 0 (SSE predux): (x + z) + y.
DRAPE_AVX_INLINE __m256 dot8(__m256 ax, __m256 ay, __m256 az, __m256 bx, __m256 by, __m256 bz) {
  return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(ax, bx), _mm256_mul_ps(az, bz)), _mm256_mul_ps(ay, by));
}
// Eight consecutive Vec4s transposed to x, y, z, w lanes (lane j = v[j]): v[j] and v[j + 4]
// share a 256-bit register, so the 4x4 transposes run in-lane (as the XPBD kernel's gather).
DRAPE_AVX_INLINE void load8(const Eigen::Vector4f* v, __m256& x, __m256& y, __m256& z, __m256& w) {
  __m256 r[4];
  for (int i = 0; i < 4; ++i)
    r[i] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(v[i].data())), _mm_loadu_ps(v[i + 4].data()), 1);
  const __m256 t0 = _mm256_unpacklo_ps(r[0], r[1]), t1 = _mm256_unpackhi_ps(r[0], r[1]);
  const __m256 t2 = _mm256_unpacklo_ps(r[2], r[3]), t3 = _mm256_unpackhi_ps(r[2], r[3]);
  x = _mm256_shuffle_ps(t0, t2, 0x44);
  y = _mm256_shuffle_ps(t0, t2, 0xEE);
  z = _mm256_shuffle_ps(t1, t3, 0x44);
  w = _mm256_shuffle_ps(t1, t3, 0xEE);
}
// All three coordinates finite, per lane (v - v is 0 for finite v, NaN for NaN and infinities).
DRAPE_AVX_INLINE __m256 finite8(__m256 x, __m256 y, __m256 z) {
  const __m256 zero = _mm256_setzero_ps();
  return _mm256_and_ps(_mm256_and_ps(_mm256_cmp_ps(_mm256_sub_ps(x, x), zero, _CMP_EQ_OQ),
                                     _mm256_cmp_ps(_mm256_sub_ps(y, y), zero, _CMP_EQ_OQ)),
                       _mm256_cmp_ps(_mm256_sub_ps(z, z), zero, _CMP_EQ_OQ));
}
// All-ones int32 lanes where bit j of a nibble is set: two lookups give the eight lanes of a
// bit mask (building them lane by lane from the bits cost ~60 instructions per batch).
alignas(16) inline constexpr int32_t kNibbleLanes[16][4] = {
    {0, 0, 0, 0},   {-1, 0, 0, 0},   {0, -1, 0, 0},   {-1, -1, 0, 0},   {0, 0, -1, 0},   {-1, 0, -1, 0},
    {0, -1, -1, 0}, {-1, -1, -1, 0}, {0, 0, 0, -1},   {-1, 0, 0, -1},   {0, -1, 0, -1},  {-1, -1, 0, -1},
    {0, 0, -1, -1}, {-1, 0, -1, -1}, {0, -1, -1, -1}, {-1, -1, -1, -1}};
DRAPE_AVX_INLINE __m256 laneMask8(int bits) {
  const __m128 lo = _mm_load_ps(reinterpret_cast<const float*>(kNibbleLanes[bits & 15]));
  const __m128 hi = _mm_load_ps(reinterpret_cast<const float*>(kNibbleLanes[(bits >> 4) & 15]));
  return _mm256_insertf128_ps(_mm256_castps128_ps256(lo), hi, 1);
}
// 0xFF in byte j where lane j of `lanes` (a laneMask8) is all ones.
DRAPE_AVX_INLINE uint64_t byteMask8(__m256 lanes) {
  const __m128i words = _mm_packs_epi32(_mm_castps_si128(_mm256_castps256_ps128(lanes)),
                                        _mm_castps_si128(_mm256_extractf128_ps(lanes, 1)));
  return static_cast<uint64_t>(_mm_cvtsi128_si64(_mm_packs_epi16(words, _mm_setzero_si128())));
}
// a + (b + c): how Eigen sums three terms (a 3-vector's dot product and squared norm; its
// unrolled reduction splits a length-3 sum as 1 + 2).
DRAPE_AVX_INLINE __m256 sum3(__m256 a, __m256 b, __m256 c) { return _mm256_add_ps(a, _mm256_add_ps(b, c)); }
// (m0 v0 + m1 v1) + m2 v2 for a row (m0, m1, m2) of a matrix broadcast: collision.cpp's mulv,
// m.col(0) v.x + m.col(1) v.y + m.col(2) v.z, left to right.
DRAPE_AVX_INLINE __m256 row3(float m0, float m1, float m2, __m256 v0, __m256 v1, __m256 v2) {
  return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(bcast(m0), v0), _mm256_mul_ps(bcast(m1), v1)),
                       _mm256_mul_ps(bcast(m2), v2));
}
// m0 v0 + (m1 v1 + m2 v2): a column of a matrix dotted with v (collision.cpp's mulvT).
DRAPE_AVX_INLINE __m256 col3(float m0, float m1, float m2, __m256 v0, __m256 v1, __m256 v2) {
  return sum3(_mm256_mul_ps(bcast(m0), v0), _mm256_mul_ps(bcast(m1), v1), _mm256_mul_ps(bcast(m2), v2));
}
// Bit j set where byte j of lane_masks (lane j's collision mask) shares a bit with `group`
// (an ellipsoid's group): one multiply, one AND and one byte compare for eight lanes.
DRAPE_AVX_INLINE int lanesSharing(uint64_t lane_masks, uint8_t group) {
  const uint64_t shared = lane_masks & (0x0101010101010101ull * group);
  const int none = _mm_movemask_epi8(_mm_cmpeq_epi8(_mm_cvtsi64_si128(static_cast<long long>(shared)),
                                                     _mm_setzero_si128())) & 0xFF;
  return ~none & 0xFF;
}
// v where `mask` lanes are all ones, else off.
DRAPE_AVX_INLINE __m256 select8(__m256 mask, __m256 v, __m256 off) {
  return _mm256_or_ps(_mm256_and_ps(mask, v), _mm256_andnot_ps(mask, off));
}
DRAPE_AVX_INLINE float hmin8(__m256 v) {
  __m128 m = _mm_min_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  m = _mm_min_ps(m, _mm_movehl_ps(m, m));
  m = _mm_min_ss(m, _mm_shuffle_ps(m, m, 1));
  return _mm_cvtss_f32(m);
}
DRAPE_AVX_INLINE float hmax8(__m256 v) {
  __m128 m = _mm_max_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  m = _mm_max_ps(m, _mm_movehl_ps(m, m));
  m = _mm_max_ss(m, _mm_shuffle_ps(m, m, 1));
  return _mm_cvtss_f32(m);
}
// lo <= mx and hi >= mn on each axis, per lane.
DRAPE_AVX_INLINE __m256 boxes8(__m256 lox, __m256 loy, __m256 loz, __m256 hix, __m256 hiy, __m256 hiz,
                               const Eigen::Vector4f& mn, const Eigen::Vector4f& mx) {
  return _mm256_and_ps(
      _mm256_and_ps(_mm256_and_ps(_mm256_cmp_ps(lox, bcast(mx.x()), _CMP_LE_OQ), _mm256_cmp_ps(hix, bcast(mn.x()), _CMP_GE_OQ)),
                    _mm256_and_ps(_mm256_cmp_ps(loy, bcast(mx.y()), _CMP_LE_OQ), _mm256_cmp_ps(hiy, bcast(mn.y()), _CMP_GE_OQ))),
      _mm256_and_ps(_mm256_cmp_ps(loz, bcast(mx.z()), _CMP_LE_OQ), _mm256_cmp_ps(hiz, bcast(mn.z()), _CMP_GE_OQ)));
}

}  // namespace collision_avx
}  // namespace drape
#else
#define DRAPE_COLLISION_AVX 0
#endif
