// The 4 x 4 transpose within each 128-bit lane that the SIMD kernels use to turn Vec4s (xyzw) into
// x, y, z, w registers and back: the XPBD projection's gathers and scatters (cloth/xpbd_solver.cpp)
// and the collider's batch loads (proxies/collision_lanes.h), 8 lanes (AVX) and 16 (AVX-512F). Only
// for functions compiled with that target and called after cpuHasAvx() / cpuHasAvx512().
#pragma once

#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
#include <immintrin.h>

namespace drape {
namespace simd {

// Group k (128-bit lane k) of a, b, c, d holds four Vec4s' xyzw; out: group k of x holds their x
// (a's, b's, c's, d's), of y their y, and so on. The same operations transpose back: (x, y, z, w)
// in gives the Vec4s out, so the gathers and the scatters both call this.
__attribute__((target("avx"), always_inline)) inline void transpose4(__m256 a, __m256 b, __m256 c, __m256 d,
                                                                    __m256& x, __m256& y, __m256& z, __m256& w) {
  const __m256 t0 = _mm256_unpacklo_ps(a, b), t1 = _mm256_unpackhi_ps(a, b);
  const __m256 t2 = _mm256_unpacklo_ps(c, d), t3 = _mm256_unpackhi_ps(c, d);
  x = _mm256_shuffle_ps(t0, t2, 0x44);
  y = _mm256_shuffle_ps(t0, t2, 0xEE);
  z = _mm256_shuffle_ps(t1, t3, 0x44);
  w = _mm256_shuffle_ps(t1, t3, 0xEE);
}

#if !defined(__clang__)
// GCC 12's AVX-512 intrinsics pass _mm512_undefined_ps() (a self-initialised variable) as the
// unused merge source, and -Wuninitialized reports it at each use: a known false positive.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
__attribute__((target("avx,avx512f"), always_inline)) inline void transpose4(__m512 a, __m512 b, __m512 c, __m512 d,
                                                                            __m512& x, __m512& y, __m512& z,
                                                                            __m512& w) {
  const __m512 t0 = _mm512_unpacklo_ps(a, b), t1 = _mm512_unpackhi_ps(a, b);
  const __m512 t2 = _mm512_unpacklo_ps(c, d), t3 = _mm512_unpackhi_ps(c, d);
  x = _mm512_shuffle_ps(t0, t2, 0x44);
  y = _mm512_shuffle_ps(t0, t2, 0xEE);
  z = _mm512_shuffle_ps(t1, t3, 0x44);
  w = _mm512_shuffle_ps(t1, t3, 0xEE);
}
#if !defined(__clang__)
#pragma GCC diagnostic pop
#endif

}  // namespace simd
}  // namespace drape
#endif
