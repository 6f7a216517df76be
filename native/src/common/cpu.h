// What the CPU the library runs on can do, checked once at run time: the 8-wide AVX kernels (XPBD
// projection, collision pass 0, the fused update) and the AVX-512 ones (the same three, 16 or 4
// wide) are chosen per call, so one build runs on every x86-64. Also the inlining hints those hot
// loops share.
#pragma once

#if defined(__GNUC__)
#define DRAPE_ALWAYS_INLINE __attribute__((always_inline)) inline
#define DRAPE_LAMBDA_INLINE __attribute__((always_inline))
#else
#define DRAPE_ALWAYS_INLINE inline
#define DRAPE_LAMBDA_INLINE
#endif

namespace drape {

#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
inline bool cpuHasAvx() {
  static const bool avx = __builtin_cpu_supports("avx");
  return avx;
}
// AVX-512 Foundation (Zen 4 and later, Intel since Skylake-SP): the 16-lane kernels.
inline bool cpuHasAvx512() {
  static const bool avx512 = __builtin_cpu_supports("avx512f");
  return avx512;
}
#else
inline bool cpuHasAvx() { return false; }
inline bool cpuHasAvx512() { return false; }
#endif

}  // namespace drape
