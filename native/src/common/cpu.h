// What the CPU the library runs on can do, checked once at run time: the 8-wide AVX kernels (XPBD
// projection, collision pass 0) are chosen per call, so one build runs on every x86-64. Also the
// inlining hints those hot loops share.
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
#else
inline bool cpuHasAvx() { return false; }
#endif

}  // namespace drape
