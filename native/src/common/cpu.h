// What the CPU the library runs on can do, checked once at run time: the 8-wide AVX kernels (XPBD
// projection, collision pass 0) and the 16-wide AVX-512 one (XPBD projection) are chosen per call,
// so one build runs on every x86-64. Also the inlining hints those hot loops share.
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
// AVX-512 Foundation (Zen 4 and later, Intel since Skylake-SP): the 16-lane XPBD kernel.
inline bool cpuHasAvx512() {
  static const bool avx512 = __builtin_cpu_supports("avx512f");
  return avx512;
}
#else
inline bool cpuHasAvx() { return false; }
inline bool cpuHasAvx512() { return false; }
#endif

}  // namespace drape
