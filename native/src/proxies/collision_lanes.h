// Internal to the ellipsoid collider's batched pass 0 (collision_batch.inc, compiled in
// collision_batch.cpp as eight lanes with AVX and as sixteen with AVX-512F):
// two namespaces, lanes8 and lanes16, with the same helpers, so one body serves both widths. Each
// helper reproduces the scalar path's arithmetic lane by lane (Eigen's summation orders, no FMA),
// so that a batch gives the one-particle results bit for bit. Only for functions compiled with
// the namespace's target and called after cpuHasAvx() / cpuHasAvx512().
#pragma once

// x86-64 only: the lane masks move through 64-bit general registers (_mm_cvtsi64_si128), which
// 32-bit x86 lacks; there the collider runs one particle at a time.
#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__)
#define DRAPE_COLLISION_AVX 1
#include <immintrin.h>

#include <Eigen/Core>

#include "common/simd_transpose.h"

#include <cstdint>
#include <cstring>

// The targets of the two widths. AVX-512F brings FMA with it, and a fused multiply-add rounds
// differently from the scalar path's multiply then add: GCC gets fp-contract off (clang, the
// sanitizer build's compiler, contracts only within one expression, and each intrinsic is its own
// function there).
#define DRAPE_LANES8_TARGET __attribute__((target("avx")))
#if defined(__clang__)
#define DRAPE_LANES16_TARGET __attribute__((target("avx,avx512f")))
#else
#define DRAPE_LANES16_TARGET __attribute__((target("avx,avx512f"), optimize("fp-contract=off")))
#endif

namespace drape {
namespace collision_lanes {

// The OR of the grid cells [lo, hi] (W bitmask words each), ANDed with `allowed` when given,
// into out[0..W): the broad phase's gather with the words in registers (and written once: a
// wider load of words just stored one by one would stall on store forwarding). Plain integer
// code, inlined into either width.
template <int W>
__attribute__((always_inline)) inline void orCells(const uint64_t* cells, int dim_x, int dim_y,
                                                   const Eigen::Array4i& lo, const Eigen::Array4i& hi,
                                                   const uint64_t* allowed, uint64_t* out) {
  uint64_t acc[W] = {};
  for (int z = lo[2]; z <= hi[2]; ++z) {
    for (int y = lo[1]; y <= hi[1]; ++y) {
      const uint64_t* cell = cells + static_cast<size_t>(((z * dim_y + y) * dim_x + lo[0]) * W);
      for (int x = lo[0]; x <= hi[0]; ++x, cell += W)
        for (int w = 0; w < W; ++w) acc[w] |= cell[w];
    }
  }
  if (allowed)
    for (int w = 0; w < W; ++w) acc[w] &= allowed[w];
  for (int w = 0; w < W; ++w) out[w] = acc[w];
}

// ---------------------------------------------------------------------------------------------
// Eight lanes (AVX): V and M are both __m256 (a mask lane is all ones or all zeros).
namespace lanes8 {
#define DRAPE_LANE_FN DRAPE_LANES8_TARGET __attribute__((always_inline)) inline
constexpr int kLanes = 8;
constexpr int kAllLanes = 0xFF;
using V = __m256;
using M = __m256;
// kLanes floats, aligned for a vector load.
struct Lanes {
  alignas(32) float v[kLanes];
};
// Lane j's collision mask in byte j (0 for lanes not taking part).
struct LaneBytes {
  alignas(16) uint8_t b[kLanes];
};
DRAPE_LANE_FN V bcast(float f) { return _mm256_set1_ps(f); }
DRAPE_LANE_FN V zero() { return _mm256_setzero_ps(); }
DRAPE_LANE_FN V load(const float* p) { return _mm256_load_ps(p); }
DRAPE_LANE_FN void store(float* p, V v) { _mm256_store_ps(p, v); }
DRAPE_LANE_FN V add(V a, V b) { return _mm256_add_ps(a, b); }
DRAPE_LANE_FN V sub(V a, V b) { return _mm256_sub_ps(a, b); }
DRAPE_LANE_FN V mul(V a, V b) { return _mm256_mul_ps(a, b); }
DRAPE_LANE_FN V div(V a, V b) { return _mm256_div_ps(a, b); }
DRAPE_LANE_FN V sqrt(V a) { return _mm256_sqrt_ps(a); }
DRAPE_LANE_FN V vmin(V a, V b) { return _mm256_min_ps(a, b); }
DRAPE_LANE_FN V vmax(V a, V b) { return _mm256_max_ps(a, b); }
DRAPE_LANE_FN V absv(V a) { return _mm256_and_ps(a, _mm256_castsi256_ps(_mm256_set1_epi32(0x7FFFFFFF))); }
DRAPE_LANE_FN M lt(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_LT_OQ); }
DRAPE_LANE_FN M le(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_LE_OQ); }
DRAPE_LANE_FN M gt(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_GT_OQ); }
DRAPE_LANE_FN M ge(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_GE_OQ); }
DRAPE_LANE_FN M eq(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_EQ_OQ); }
DRAPE_LANE_FN M mand(M a, M b) { return _mm256_and_ps(a, b); }
DRAPE_LANE_FN M mor(M a, M b) { return _mm256_or_ps(a, b); }
// b and not a (as _mm256_andnot_ps(a, b)).
DRAPE_LANE_FN M mandnot(M a, M b) { return _mm256_andnot_ps(a, b); }
DRAPE_LANE_FN M noLanes() { return _mm256_setzero_ps(); }
DRAPE_LANE_FN int bits(M m) { return _mm256_movemask_ps(m); }
// v where `mask` lanes are set, else off. and/andnot/or rather than blendv: GCC 12 lowered that
// blend lane by lane here.
DRAPE_LANE_FN V select(M mask, V v, V off) { return _mm256_or_ps(_mm256_and_ps(mask, v), _mm256_andnot_ps(mask, off)); }

// All-ones int32 lanes where bit j of a nibble is set: two lookups give the eight lanes of a
// bit mask (building them lane by lane from the bits cost ~60 instructions per batch).
alignas(16) inline constexpr int32_t kNibbleLanes[16][4] = {
    {0, 0, 0, 0},   {-1, 0, 0, 0},   {0, -1, 0, 0},   {-1, -1, 0, 0},   {0, 0, -1, 0},   {-1, 0, -1, 0},
    {0, -1, -1, 0}, {-1, -1, -1, 0}, {0, 0, 0, -1},   {-1, 0, 0, -1},   {0, -1, 0, -1},  {-1, -1, 0, -1},
    {0, 0, -1, -1}, {-1, 0, -1, -1}, {0, -1, -1, -1}, {-1, -1, -1, -1}};
DRAPE_LANE_FN M maskOf(int lane_bits) {
  const __m128 lo = _mm_load_ps(reinterpret_cast<const float*>(kNibbleLanes[lane_bits & 15]));
  const __m128 hi = _mm_load_ps(reinterpret_cast<const float*>(kNibbleLanes[(lane_bits >> 4) & 15]));
  return _mm256_insertf128_ps(_mm256_castps128_ps256(lo), hi, 1);
}
DRAPE_LANE_FN float hmin(V v) {
  __m128 m = _mm_min_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  m = _mm_min_ps(m, _mm_movehl_ps(m, m));
  m = _mm_min_ss(m, _mm_shuffle_ps(m, m, 1));
  return _mm_cvtss_f32(m);
}
DRAPE_LANE_FN float hmax(V v) {
  __m128 m = _mm_max_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  m = _mm_max_ps(m, _mm_movehl_ps(m, m));
  m = _mm_max_ss(m, _mm_shuffle_ps(m, m, 1));
  return _mm_cvtss_f32(m);
}
// Eight consecutive Vec4s transposed to x, y, z, w lanes (lane j = v[j]): v[j] and v[j + 4]
// share a 256-bit register, so the 4x4 transposes run in-lane (as the XPBD kernel's gather).
DRAPE_LANE_FN void loadPositions(const Eigen::Vector4f* v, V& x, V& y, V& z, V& w) {
  __m256 r[4];
  for (int i = 0; i < 4; ++i)
    r[i] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(v[i].data())), _mm_loadu_ps(v[i + 4].data()), 1);
  simd::transpose4(r[0], r[1], r[2], r[3], x, y, z, w);
}
// The lanes' collision masks (masks[0..8)) for the lanes in `on` into out (0 elsewhere); returns
// the union of those masks in `joint` and whether they differ. The eight bytes as one word.
DRAPE_LANE_FN bool laneMasks(const uint8_t* masks, M on, LaneBytes& out, uint8_t& joint) {
  uint64_t lane_masks = 0;
  std::memcpy(&lane_masks, masks, sizeof lane_masks);
  const __m128i words = _mm_packs_epi32(_mm_castps_si128(_mm256_castps256_ps128(on)),
                                        _mm_castps_si128(_mm256_extractf128_ps(on, 1)));
  const uint64_t on_bytes = static_cast<uint64_t>(_mm_cvtsi128_si64(_mm_packs_epi16(words, _mm_setzero_si128())));
  lane_masks &= on_bytes;
  uint64_t m = lane_masks;
  m |= m >> 32;
  m |= m >> 16;
  m |= m >> 8;
  m &= 0xFFu;
  joint = static_cast<uint8_t>(m);
  std::memcpy(out.b, &lane_masks, sizeof lane_masks);
  return lane_masks != (0x0101010101010101ull * m & on_bytes);
}
// Bit j set where byte j of the lane masks (a LaneBytes) shares a bit with `group` (an ellipsoid's group): one
// multiply, one AND and one byte compare for eight lanes.
DRAPE_LANE_FN int lanesSharing(const uint8_t* lane_masks, uint8_t group) {
  uint64_t words = 0;
  std::memcpy(&words, lane_masks, sizeof words);
  const uint64_t shared = words & (0x0101010101010101ull * group);
  const int none = _mm_movemask_epi8(_mm_cmpeq_epi8(_mm_cvtsi64_si128(static_cast<long long>(shared)),
                                                     _mm_setzero_si128())) & 0xFF;
  return ~none & 0xFF;
}
#include "proxies/collision_lanes_ops.inc"
#undef DRAPE_LANE_FN
}  // namespace lanes8

// ---------------------------------------------------------------------------------------------
// Sixteen lanes (AVX-512F): V is __m512, M a 16-bit lane mask.
#if !defined(__clang__)
// GCC 12's AVX-512 intrinsics pass _mm512_undefined_ps() (a self-initialised variable) as the
// unused merge source, and -Wuninitialized reports it at each use: a known false positive.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
namespace lanes16 {
#define DRAPE_LANE_FN DRAPE_LANES16_TARGET __attribute__((always_inline)) inline
constexpr int kLanes = 16;
constexpr int kAllLanes = 0xFFFF;
using V = __m512;
using M = __mmask16;
struct Lanes {
  alignas(64) float v[kLanes];
};
struct LaneBytes {
  alignas(16) uint8_t b[kLanes];
};
DRAPE_LANE_FN V bcast(float f) { return _mm512_set1_ps(f); }
DRAPE_LANE_FN V zero() { return _mm512_setzero_ps(); }
DRAPE_LANE_FN V load(const float* p) { return _mm512_load_ps(p); }
DRAPE_LANE_FN void store(float* p, V v) { _mm512_store_ps(p, v); }
DRAPE_LANE_FN V add(V a, V b) { return _mm512_add_ps(a, b); }
DRAPE_LANE_FN V sub(V a, V b) { return _mm512_sub_ps(a, b); }
DRAPE_LANE_FN V mul(V a, V b) { return _mm512_mul_ps(a, b); }
DRAPE_LANE_FN V div(V a, V b) { return _mm512_div_ps(a, b); }
DRAPE_LANE_FN V sqrt(V a) { return _mm512_sqrt_ps(a); }
DRAPE_LANE_FN V vmin(V a, V b) { return _mm512_min_ps(a, b); }
DRAPE_LANE_FN V vmax(V a, V b) { return _mm512_max_ps(a, b); }
DRAPE_LANE_FN V absv(V a) { return _mm512_abs_ps(a); }
DRAPE_LANE_FN M lt(V a, V b) { return _mm512_cmp_ps_mask(a, b, _CMP_LT_OQ); }
DRAPE_LANE_FN M le(V a, V b) { return _mm512_cmp_ps_mask(a, b, _CMP_LE_OQ); }
DRAPE_LANE_FN M gt(V a, V b) { return _mm512_cmp_ps_mask(a, b, _CMP_GT_OQ); }
DRAPE_LANE_FN M ge(V a, V b) { return _mm512_cmp_ps_mask(a, b, _CMP_GE_OQ); }
DRAPE_LANE_FN M eq(V a, V b) { return _mm512_cmp_ps_mask(a, b, _CMP_EQ_OQ); }
DRAPE_LANE_FN M mand(M a, M b) { return static_cast<M>(a & b); }
DRAPE_LANE_FN M mor(M a, M b) { return static_cast<M>(a | b); }
DRAPE_LANE_FN M mandnot(M a, M b) { return static_cast<M>(~a & b); }
DRAPE_LANE_FN M noLanes() { return 0; }
DRAPE_LANE_FN int bits(M m) { return static_cast<int>(m); }
DRAPE_LANE_FN M maskOf(int lane_bits) { return static_cast<M>(lane_bits); }
DRAPE_LANE_FN V select(M mask, V v, V off) { return _mm512_mask_blend_ps(mask, off, v); }
// min / max are exact whatever the order (the lanes reduced are numbers or +-infinity).
DRAPE_LANE_FN float hmin(V v) {
  const __m256 h = _mm256_min_ps(_mm512_castps512_ps256(v),
                                 _mm256_castpd_ps(_mm512_extractf64x4_pd(_mm512_castps_pd(v), 1)));
  __m128 m = _mm_min_ps(_mm256_castps256_ps128(h), _mm256_extractf128_ps(h, 1));
  m = _mm_min_ps(m, _mm_movehl_ps(m, m));
  m = _mm_min_ss(m, _mm_shuffle_ps(m, m, 1));
  return _mm_cvtss_f32(m);
}
DRAPE_LANE_FN float hmax(V v) {
  const __m256 h = _mm256_max_ps(_mm512_castps512_ps256(v),
                                 _mm256_castpd_ps(_mm512_extractf64x4_pd(_mm512_castps_pd(v), 1)));
  __m128 m = _mm_max_ps(_mm256_castps256_ps128(h), _mm256_extractf128_ps(h, 1));
  m = _mm_max_ps(m, _mm_movehl_ps(m, m));
  m = _mm_max_ss(m, _mm_shuffle_ps(m, m, 1));
  return _mm_cvtss_f32(m);
}
// Sixteen consecutive Vec4s transposed to x, y, z, w lanes (lane j = v[j]): v[j], v[j + 4],
// v[j + 8] and v[j + 12] share a 512-bit register, so the 4x4 transposes run within 128-bit lanes.
DRAPE_LANE_FN void loadPositions(const Eigen::Vector4f* v, V& x, V& y, V& z, V& w) {
  __m512 r[4];
  for (int i = 0; i < 4; ++i) {
    r[i] = _mm512_castps128_ps512(_mm_loadu_ps(v[i].data()));
    r[i] = _mm512_insertf32x4(r[i], _mm_loadu_ps(v[i + 4].data()), 1);
    r[i] = _mm512_insertf32x4(r[i], _mm_loadu_ps(v[i + 8].data()), 2);
    r[i] = _mm512_insertf32x4(r[i], _mm_loadu_ps(v[i + 12].data()), 3);
  }
  simd::transpose4(r[0], r[1], r[2], r[3], x, y, z, w);
}
// lanes8::laneMasks for sixteen lanes: the bytes of the lanes not in `on` cleared through a
// 0xFF-per-lane byte mask (AVX-512F's dword-to-byte narrowing), then the union folded in one word.
DRAPE_LANE_FN bool laneMasks(const uint8_t* masks, M on, LaneBytes& out, uint8_t& joint) {
  const __m128i on_bytes = _mm512_cvtepi32_epi8(_mm512_maskz_set1_epi32(on, -1));
  const __m128i lane_masks = _mm_and_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(masks)), on_bytes);
  _mm_store_si128(reinterpret_cast<__m128i*>(out.b), lane_masks);
  uint64_t m = static_cast<uint64_t>(_mm_cvtsi128_si64(lane_masks)) |
               static_cast<uint64_t>(_mm_cvtsi128_si64(_mm_unpackhi_epi64(lane_masks, lane_masks)));
  m |= m >> 32;
  m |= m >> 16;
  m |= m >> 8;
  m &= 0xFFu;
  joint = static_cast<uint8_t>(m);
  const __m128i same = _mm_and_si128(_mm_set1_epi8(static_cast<char>(joint)), on_bytes);
  return _mm_movemask_epi8(_mm_cmpeq_epi8(same, lane_masks)) != 0xFFFF;
}
DRAPE_LANE_FN int lanesSharing(const uint8_t* lane_masks, uint8_t group) {
  const __m128i shared = _mm_and_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(lane_masks)),
                                       _mm_set1_epi8(static_cast<char>(group)));
  return ~_mm_movemask_epi8(_mm_cmpeq_epi8(shared, _mm_setzero_si128())) & 0xFFFF;
}
#include "proxies/collision_lanes_ops.inc"
#undef DRAPE_LANE_FN
}  // namespace lanes16
#if !defined(__clang__)
#pragma GCC diagnostic pop
#endif

}  // namespace collision_lanes
}  // namespace drape
#else
#define DRAPE_COLLISION_AVX 0
#endif
