#include "cloth/xpbd_solver.h"

#include "common/cpu.h"
#include "common/simd_transpose.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#if defined(__SSE2__) || defined(_M_X64)
#include <emmintrin.h>
#define DRAPE_XPBD_SSE 1
#endif
#if DRAPE_XPBD_SSE && (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
#include <immintrin.h>
#define DRAPE_XPBD_AVX 1  // an 8-lane AVX kernel, chosen at run time (no FMA: same results)
#endif

namespace drape {
namespace {

using Vec4 = Eigen::Vector4f;
// Groups are padded to this: one AVX-512 batch, two AVX batches or four SSE batches. (Padding to
// 16 rather than 8 adds dummy constraints on the dummy particle: the default T-shirt's 10 434
// distance constraints in 20 colour groups take 10 608 entries, 10 512 at 8, +0.9 %; the order of
// real constraints, and so every result, is the same.)
constexpr size_t kLanes = 16;

bool finite(const Vec3& v) { return isFinite(v); }
bool finite(float f) { return std::isfinite(f); }

using Clock = std::chrono::steady_clock;
double nsBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::nano>(b - a).count();
}

// The entries [g0, g1) of one colour group of `c` in the order appendPadded stores them: first
// `*quad_batches` batches of kLanes whose lanes q, q + 4, q + 8, q + 12 hold four constraints
// (a, b), (a + 1, b + 1), (a + 2, b + 2), (a + 3, b + 3) (a "quad": both ends four consecutive
// particles, as a template's rows of edges are), for q = 0..3; then the rest in the colour's order.
// quad_b false (tethers, whose b is an anchor the kernels only read): a quad needs consecutive a
// alone.
// Then, with quad_b, `*pair_batches` batches whose lanes q, q + 4, q + 8, q + 12 hold (p, p + 1),
// (p + 2, p + 3), (p + 4, p + 5), (p + 6, p + 7) (a "pair octet": a row's edges every other one,
// which never form quads, consecutive edges sharing a particle).
// Within a colour no two constraints share a particle that either writes, so this order gives the
// same bits as any other; it lets the AVX-512 kernel load and store a quad's four particles as one
// 64-byte vector (Batches::quad_runs) and an octet's eight as two (Batches::wide_runs).
std::vector<uint32_t> quadOrder(const DistanceConstraints& c, uint32_t g0, uint32_t g1, uint32_t particles,
                                bool quad_b, std::vector<int32_t>& entry_of_a, size_t* quad_batches,
                                size_t* pair_batches) {
  std::vector<uint32_t> by_a(g1 - g0);
  for (uint32_t k = g0; k < g1; ++k) by_a[k - g0] = k;
  std::sort(by_a.begin(), by_a.end(), [&](uint32_t i, uint32_t j) { return c.a[i] < c.a[j]; });
  // A particle is `a` of at most one constraint of a colour (a writes), so `a` finds its entry.
  for (uint32_t k = g0; k < g1; ++k) entry_of_a[c.a[k]] = static_cast<int32_t>(k);
  std::vector<uint8_t> used(g1 - g0, 0);
  // Runs of four free entries whose `a` step by `stride` from entry k's, in order of a, each entry
  // of a run passing fits(entry, k, j) (j its place in the run): four entries per run.
  const auto takeRuns = [&](uint32_t stride, auto fits) {
    std::vector<uint32_t> runs;
    for (uint32_t k : by_a) {
      if (used[k - g0] || !fits(k, k, 0u)) continue;
      uint32_t e[4] = {k, 0, 0, 0};
      bool run = true;
      for (uint32_t j = 1; j < 4 && run; ++j) {
        const uint32_t aj = c.a[k] + stride * j;
        const int32_t ej = aj < particles ? entry_of_a[aj] : -1;
        run = ej >= 0 && !used[static_cast<uint32_t>(ej) - g0] && fits(static_cast<uint32_t>(ej), k, j);
        if (run) e[j] = static_cast<uint32_t>(ej);
      }
      if (!run) continue;
      for (uint32_t ej : e) {
        used[ej - g0] = 1;
        runs.push_back(ej);
      }
    }
    return runs;
  };
  std::vector<uint32_t> order;
  order.reserve(g1 - g0);
  // Every four runs a batch, run q in lanes q, q + 4, q + 8, q + 12; the runs of a part batch are
  // freed again. Returns the batches.
  const auto appendBatches = [&](const std::vector<uint32_t>& runs) {
    const size_t batches = runs.size() / kLanes;
    for (size_t batch = 0; batch < batches; ++batch) {
      const uint32_t* q = runs.data() + batch * kLanes;  // the batch's four runs
      for (size_t lane = 0; lane < kLanes; ++lane) order.push_back(q[(lane % 4) * 4 + lane / 4]);
    }
    for (size_t i = batches * kLanes; i < runs.size(); ++i) used[runs[i] - g0] = 0;
    return batches;
  };
  *quad_batches = appendBatches(takeRuns(1, [&](uint32_t e, uint32_t k, uint32_t j) {
    return !quad_b || c.b[e] == c.b[k] + j;  // (a, b), (a + 1, b + 1), ...
  }));
  // Pair octets among the rest (quads left over from a part batch among them).
  *pair_batches = quad_b ? appendBatches(takeRuns(2, [&](uint32_t e, uint32_t, uint32_t) {
                             return c.b[e] == c.a[e] + 1;  // (p, p + 1), (p + 2, p + 3), ...
                           }))
                         : 0;
  for (uint32_t k = g0; k < g1; ++k) entry_of_a[c.a[k]] = -1;
  for (uint32_t k = g0; k < g1; ++k)
    if (!used[k - g0]) order.push_back(k);
  return order;
}

// Appends the colour groups of `c` to `out`, each padded to a multiple of kLanes with dummy
// constraints on particle `dummy` (= the particle count), each in quadOrder, with the entries of
// its quad batches added to `quad_runs` ([begin, end)) and its quad and pair batches to
// `wide_runs`, in order.
void appendPadded(const DistanceConstraints& c, bool quad_b, float compliance, uint32_t dummy,
                  std::vector<uint8_t>* kinds, uint8_t kind,
                  std::vector<uint32_t>& a, std::vector<uint32_t>& b, std::vector<float>& rest,
                  std::vector<float>& comp, std::vector<uint32_t>& offsets,
                  std::vector<std::pair<uint32_t, uint32_t>>& quad_runs,
                  std::vector<XpbdSolver::WideRun>& wide_runs) {
  std::vector<int32_t> entry_of_a(dummy, -1);
  for (size_t g = 0; g < c.colours(); ++g) {
    size_t quad_batches = 0, pair_batches = 0;
    const uint32_t start = static_cast<uint32_t>(a.size());
    for (uint32_t k : quadOrder(c, c.colour_offsets[g], c.colour_offsets[g + 1], dummy, quad_b, entry_of_a,
                                &quad_batches, &pair_batches)) {
      a.push_back(c.a[k]);
      b.push_back(c.b[k]);
      rest.push_back(c.rest[k]);
      comp.push_back(compliance);
      if (kinds) kinds->push_back(kind);
    }
    const uint32_t pairs_at = static_cast<uint32_t>(start + quad_batches * kLanes);
    if (quad_batches > 0) {
      quad_runs.emplace_back(start, pairs_at);
      wide_runs.push_back({start, pairs_at, XpbdSolver::RunKind::Quads});
    }
    if (pair_batches > 0)
      wide_runs.push_back(
          {pairs_at, static_cast<uint32_t>(pairs_at + pair_batches * kLanes), XpbdSolver::RunKind::Pairs});
    while (a.size() % kLanes != 0) {
      a.push_back(dummy);
      b.push_back(dummy);
      rest.push_back(0.0f);
      comp.push_back(0.0f);
      if (kinds) kinds->push_back(3);
    }
    if (a.size() != offsets.back()) offsets.push_back(static_cast<uint32_t>(a.size()));
  }
}

#if DRAPE_XPBD_SSE
// Loads particles i0..i3 (xyzw each) and transposes them to x, y, z, w across the four lanes.
__attribute__((always_inline)) inline void gather4(const Vec4* x, const uint32_t* idx, __m128& px, __m128& py, __m128& pz,
                    __m128& pw) {
  __m128 r0 = _mm_load_ps(x[idx[0]].data()), r1 = _mm_load_ps(x[idx[1]].data());
  __m128 r2 = _mm_load_ps(x[idx[2]].data()), r3 = _mm_load_ps(x[idx[3]].data());
  _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
  px = r0; py = r1; pz = r2; pw = r3;
}
__attribute__((always_inline)) inline void scatter4(Vec4* x, const uint32_t* idx, __m128 px, __m128 py, __m128 pz, __m128 pw) {
  _MM_TRANSPOSE4_PS(px, py, pz, pw);
  _mm_store_ps(x[idx[0]].data(), px);
  _mm_store_ps(x[idx[1]].data(), py);
  _mm_store_ps(x[idx[2]].data(), pz);
  _mm_store_ps(x[idx[3]].data(), pw);
}
#endif

// How a batch list is projected: Equality, C = |d| - rest (distance constraints); Tether, C =
// max(|d| - rest * scale, 0) with only a moving (b is a pinned anchor); Limit, the same
// inequality with both ends moving (the strain limit, XpbdParams::strain_limit).
enum class Kind { Equality, Tether, Limit };

// One XPBD iteration (lambda from 0) over a batch list: for each constraint, with
// C = |d| - rest, d = a - b, and inv_w = 1 / (w_a + w_b + alpha~) (precomputed per step, 0 for
// padding):  a -= w_a inv_w (C/|d|) d,  b += w_b inv_w (C/|d|) d.
// Tethers: only a is written (b is a pinned anchor, w_b = 0), rest is scaled by `scale` and only
// C > 0 acts (inequality); Limit the same inequality on both ends. Constraints of a batch share
// no particle.
// 1/|d|: rsqrt estimate + one Newton step (relative error ~1e-7, the size of float rounding in
// |d| itself): the divider (sqrt + div per batch) was the bottleneck.
template <Kind kKind>
void projectBatches(Vec4* x, const uint32_t* A, const uint32_t* B, const float* rest,
                    const float* inv_w, size_t m, float scale) {
#if DRAPE_XPBD_SSE
  const __m128 vscale = _mm_set1_ps(scale), zero = _mm_setzero_ps();
  const __m128 tiny2 = _mm_set1_ps(1e-18f), half = _mm_set1_ps(0.5f), three = _mm_set1_ps(3.0f);
  const __m128 one = _mm_set1_ps(1.0f);
  for (size_t k = 0; k < m; k += 4) {
    __m128 ax, ay, az, aw, bx, by, bz, bw;
    gather4(x, A + k, ax, ay, az, aw);
    gather4(x, B + k, bx, by, bz, bw);
    const __m128 dx = _mm_sub_ps(ax, bx), dy = _mm_sub_ps(ay, by), dz = _mm_sub_ps(az, bz);
    const __m128 len2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
    const __m128 ok = _mm_cmpgt_ps(len2, tiny2);
    __m128 y = _mm_rsqrt_ps(len2);
    y = _mm_mul_ps(_mm_mul_ps(half, y), _mm_sub_ps(three, _mm_mul_ps(len2, _mm_mul_ps(y, y))));
    const __m128 r = _mm_loadu_ps(rest + k);
    __m128 s;
    if (kKind != Kind::Equality) {
      const __m128 c = _mm_max_ps(_mm_sub_ps(_mm_mul_ps(len2, y), _mm_mul_ps(r, vscale)), zero);
      s = _mm_mul_ps(_mm_mul_ps(c, y), _mm_loadu_ps(inv_w + k));
    } else {
      s = _mm_mul_ps(_mm_sub_ps(one, _mm_mul_ps(r, y)), _mm_loadu_ps(inv_w + k));
    }
    s = _mm_and_ps(ok, s);
    const __m128 sa = _mm_mul_ps(aw, s);
    ax = _mm_sub_ps(ax, _mm_mul_ps(sa, dx));
    ay = _mm_sub_ps(ay, _mm_mul_ps(sa, dy));
    az = _mm_sub_ps(az, _mm_mul_ps(sa, dz));
    scatter4(x, A + k, ax, ay, az, aw);
    if (kKind != Kind::Tether) {
      const __m128 sb = _mm_mul_ps(bw, s);
      bx = _mm_add_ps(bx, _mm_mul_ps(sb, dx));
      by = _mm_add_ps(by, _mm_mul_ps(sb, dy));
      bz = _mm_add_ps(bz, _mm_mul_ps(sb, dz));
      scatter4(x, B + k, bx, by, bz, bw);
    }
  }
#else
  for (size_t k = 0; k < m; ++k) {
    Vec4& pa = x[A[k]];
    Vec4& pb = x[B[k]];
    const Vec3 d = pa.head<3>() - pb.head<3>();
    const float len = std::sqrt(d.squaredNorm());
    if (!(len > 1e-9f)) continue;
    const float c = kKind != Kind::Equality ? std::max(len - rest[k] * scale, 0.0f) : len - rest[k];
    const float s = c / len * inv_w[k];
    pa.head<3>() -= (pa.w() * s) * d;
    if (kKind != Kind::Tether) pb.head<3>() += (pb.w() * s) * d;
  }
#endif
}

#if DRAPE_XPBD_AVX
// The same kernel 8 constraints at a time. Particles i and i+4 share one 256-bit register, so
// the 4x4 transposes run in-lane (AVX1 shuffles) and cost the same as for 4 constraints.
// Particles are addressed by byte offsets (index * 16, Batches::a_off): an index would need a
// shift before every one of the 32 loads and stores of a batch (x86 scales addresses by at most 8),
// a sixth of the kernel's instructions. The helpers are always_inline: -O3 inlines them anyway,
// the sanitizer build (-O1) called them: 9 % of GarmentOnCloseRange's time there (perf).
__attribute__((target("avx"), always_inline)) inline float* at(Vec4* x, uint32_t off) {
  return reinterpret_cast<float*>(reinterpret_cast<char*>(x) + off);
}
__attribute__((target("avx"), always_inline)) inline __m256 pair8(Vec4* x, const uint32_t* off, int i) {
  return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(at(x, off[i]))), _mm_load_ps(at(x, off[i + 4])), 1);
}
// kQuads: a quad batch (Batches::quad_runs): lanes i and i + 4 are consecutive particles, one
// 32-byte load (store) instead of two 16-byte ones.
template <bool kQuads>
__attribute__((target("avx"), always_inline)) inline void gather8(Vec4* x, const uint32_t* off, __m256& px,
                                                                  __m256& py, __m256& pz, __m256& pw) {
  __m256 r[4];
  for (int i = 0; i < 4; ++i) r[i] = kQuads ? _mm256_loadu_ps(at(x, off[i])) : pair8(x, off, i);
  simd::transpose4(r[0], r[1], r[2], r[3], px, py, pz, pw);
}
template <bool kQuads>
__attribute__((target("avx"), always_inline)) inline void scatter8(Vec4* x, const uint32_t* off, __m256 px,
                                                                   __m256 py, __m256 pz, __m256 pw) {
  __m256 r[4];
  simd::transpose4(px, py, pz, pw, r[0], r[1], r[2], r[3]);
  for (int i = 0; i < 4; ++i) {
    if (kQuads) {
      _mm256_storeu_ps(at(x, off[i]), r[i]);
      continue;
    }
    _mm_store_ps(at(x, off[i]), _mm256_castps256_ps128(r[i]));
    _mm_store_ps(at(x, off[i + 4]), _mm256_extractf128_ps(r[i], 1));
  }
}

// One batch of 8 constraints (entries A[0..8), ...).
template <Kind kKind, bool kQuads>
__attribute__((target("avx"), always_inline)) inline void projectBatch8(Vec4* x, const uint32_t* A,
                                                                        const uint32_t* B, const float* rest,
                                                                        const float* inv_w, __m256 vscale) {
  const __m256 zero = _mm256_setzero_ps();
  const __m256 tiny2 = _mm256_set1_ps(1e-18f), half = _mm256_set1_ps(0.5f);
  const __m256 three = _mm256_set1_ps(3.0f), one = _mm256_set1_ps(1.0f);
  const __m256 inf = _mm256_set1_ps(std::numeric_limits<float>::infinity());
  __m256 ax, ay, az, aw, bx, by, bz, bw;
  gather8<kQuads>(x, A, ax, ay, az, aw);
  gather8<kQuads && kKind != Kind::Tether>(x, B, bx, by, bz, bw);  // a tether's quad is its a side
  const __m256 dx = _mm256_sub_ps(ax, bx), dy = _mm256_sub_ps(ay, by), dz = _mm256_sub_ps(az, bz);
  const __m256 len2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)),
                                    _mm256_mul_ps(dz, dz));
  const __m256 ok = _mm256_cmp_ps(len2, tiny2, _CMP_GT_OQ);
  __m256 y = _mm256_rsqrt_ps(len2);
  y = _mm256_mul_ps(_mm256_mul_ps(half, y), _mm256_sub_ps(three, _mm256_mul_ps(len2, _mm256_mul_ps(y, y))));
  const __m256 r = _mm256_loadu_ps(rest);
  __m256 s;
  if (kKind != Kind::Equality) {
    const __m256 c = _mm256_max_ps(_mm256_sub_ps(_mm256_mul_ps(len2, y), _mm256_mul_ps(r, vscale)), zero);
    // Most tethers, and nearly every edge against the strain limit, are slack (inactive
    // inequalities): when every lane's violation is zero and its d finite, the stores would
    // write back what was read; skip them (same bits), before inv_w is read. A lane whose
    // correction comes out zero anyway (inv_w 0: both ends pinned) writes back its own bits.
    const __m256 acts = _mm256_or_ps(_mm256_cmp_ps(_mm256_and_ps(ok, c), zero, _CMP_NEQ_UQ),
                                     _mm256_cmp_ps(len2, inf, _CMP_NLT_UQ));
    if (_mm256_movemask_ps(acts) == 0) return;
    s = _mm256_mul_ps(_mm256_mul_ps(c, y), _mm256_loadu_ps(inv_w));
  } else {
    s = _mm256_mul_ps(_mm256_sub_ps(one, _mm256_mul_ps(r, y)), _mm256_loadu_ps(inv_w));
  }
  s = _mm256_and_ps(ok, s);
  const __m256 sa = _mm256_mul_ps(aw, s);
  ax = _mm256_sub_ps(ax, _mm256_mul_ps(sa, dx));
  ay = _mm256_sub_ps(ay, _mm256_mul_ps(sa, dy));
  az = _mm256_sub_ps(az, _mm256_mul_ps(sa, dz));
  scatter8<kQuads>(x, A, ax, ay, az, aw);
  if (kKind != Kind::Tether) {
    const __m256 sb = _mm256_mul_ps(bw, s);
    bx = _mm256_add_ps(bx, _mm256_mul_ps(sb, dx));
    by = _mm256_add_ps(by, _mm256_mul_ps(sb, dy));
    bz = _mm256_add_ps(bz, _mm256_mul_ps(sb, dz));
    scatter8<kQuads>(x, B, bx, by, bz, bw);
  }
}

// Entries [first, m) of the lists, quad runs as projectBatchesAvx512.
template <Kind kKind>
__attribute__((target("avx"))) void projectBatchesAvx(Vec4* x, const uint32_t* A, const uint32_t* B,
                                                      const float* rest, const float* inv_w, size_t first,
                                                      size_t m, float scale,
                                                      const std::pair<uint32_t, uint32_t>* quad_runs,
                                                      size_t run_count) {
  const __m256 vscale = _mm256_set1_ps(scale);
  size_t k = first;
  for (size_t r = 0; r < run_count; ++r) {
    if (quad_runs[r].first < first) continue;
    for (; k < quad_runs[r].first; k += 8)
      projectBatch8<kKind, false>(x, A + k, B + k, rest + k, inv_w + k, vscale);
    for (; k < quad_runs[r].second; k += 8)
      projectBatch8<kKind, true>(x, A + k, B + k, rest + k, inv_w + k, vscale);
  }
  for (; k < m; k += 8) projectBatch8<kKind, false>(x, A + k, B + k, rest + k, inv_w + k, vscale);
}
#endif

#if DRAPE_XPBD_AVX
// The same kernel 16 constraints at a time (AVX-512F, Zen 4 and later): particles i, i+4, i+8 and
// i+12 share one 512-bit register, so the transposes stay within 128-bit lanes as in the AVX
// kernel, and a batch costs the same shuffles as eight constraints there. The same operations per
// lane in the same order, and 1/|d| from the AVX estimate on each 256-bit half (AVX-512's own
// rsqrt14 is a different estimate), so the same bits as the AVX and SSE kernels (test
// ClothXpbd.WideProjectionMatchesEightLanesBitForBit). fp-contract off: AVX-512F has FMA, and a
// fused multiply-add would round differently.
// (Clang, the sanitizer build's compiler, contracts only within one expression, and each
// intrinsic is its own function there: no attribute needed, and it has none of that name.)
#if defined(__clang__)
#define DRAPE_AVX512_FN __attribute__((target("avx,avx512f")))
#else
#define DRAPE_AVX512_FN __attribute__((target("avx,avx512f"), optimize("fp-contract=off")))
// GCC 12's AVX-512 intrinsics pass _mm512_undefined_ps() (a self-initialised variable) as the
// unused merge source, and -Wuninitialized reports it at each use: a known false positive.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
DRAPE_AVX512_FN __attribute__((always_inline)) inline __m512 quad16(Vec4* x, const uint32_t* off, int i) {
  __m512 r = _mm512_castps128_ps512(_mm_load_ps(at(x, off[i])));
  r = _mm512_insertf32x4(r, _mm_load_ps(at(x, off[i + 4])), 1);
  r = _mm512_insertf32x4(r, _mm_load_ps(at(x, off[i + 8])), 2);
  return _mm512_insertf32x4(r, _mm_load_ps(at(x, off[i + 12])), 3);
}
// kQuads: the batch is a quad batch (Batches::quad_runs), lanes i, i + 4, i + 8, i + 12 four
// consecutive particles from off[i]: one 64-byte load (store) instead of four 16-byte ones.
template <bool kQuads>
DRAPE_AVX512_FN __attribute__((always_inline)) inline void gather16(Vec4* x, const uint32_t* off, __m512& px,
                                                                    __m512& py, __m512& pz, __m512& pw) {
  __m512 r[4];
  for (int i = 0; i < 4; ++i) r[i] = kQuads ? _mm512_loadu_ps(at(x, off[i])) : quad16(x, off, i);
  simd::transpose4(r[0], r[1], r[2], r[3], px, py, pz, pw);
}
template <bool kQuads>
DRAPE_AVX512_FN __attribute__((always_inline)) inline void scatter16(Vec4* x, const uint32_t* off, __m512 px,
                                                                     __m512 py, __m512 pz, __m512 pw) {
  __m512 r[4];
  simd::transpose4(px, py, pz, pw, r[0], r[1], r[2], r[3]);
  for (int i = 0; i < 4; ++i) {
    if (kQuads) {
      _mm512_storeu_ps(at(x, off[i]), r[i]);
      continue;
    }
    _mm_store_ps(at(x, off[i]), _mm512_castps512_ps128(r[i]));
    _mm_store_ps(at(x, off[i + 4]), _mm512_extractf32x4_ps(r[i], 1));
    _mm_store_ps(at(x, off[i + 8]), _mm512_extractf32x4_ps(r[i], 2));
    _mm_store_ps(at(x, off[i + 12]), _mm512_extractf32x4_ps(r[i], 3));
  }
}
// _mm256_rsqrt_ps on each half: the AVX and SSE kernels' estimate, bit for bit.
DRAPE_AVX512_FN __attribute__((always_inline)) inline __m512 rsqrtAsAvx(__m512 v) {
  const __m256 lo = _mm256_rsqrt_ps(_mm512_castps512_ps256(v));
  const __m256 hi = _mm256_rsqrt_ps(_mm256_castpd_ps(_mm512_extractf64x4_pd(_mm512_castps_pd(v), 1)));
  return _mm512_castpd_ps(_mm512_insertf64x4(_mm512_castps_pd(_mm512_castps256_ps512(lo)), _mm256_castps_pd(hi), 1));
}

// A pair batch (Batches::wide_runs, RunKind::Pairs): lanes i, i + 4, i + 8, i + 12 hold (p, p + 1) ... (p + 6, p + 7)
// from off[i] = p. The octet's eight particles are two 64-byte loads; one permute each picks the a
// sides (p, p + 2, p + 4, p + 6: 128-bit groups 0 and 2 of both) and the b sides (groups 1 and 3).
DRAPE_AVX512_FN __attribute__((always_inline)) inline void gatherPairs16(Vec4* x, const uint32_t* off, __m512 (&a)[4],
                                                                         __m512 (&b)[4]) {
  const __m512i even = _mm512_setr_epi32(0, 1, 2, 3, 8, 9, 10, 11, 16, 17, 18, 19, 24, 25, 26, 27);
  const __m512i odd = _mm512_setr_epi32(4, 5, 6, 7, 12, 13, 14, 15, 20, 21, 22, 23, 28, 29, 30, 31);
  for (int i = 0; i < 4; ++i) {
    const float* p = at(x, off[i]);
    const __m512 lo = _mm512_loadu_ps(p), hi = _mm512_loadu_ps(p + 16);
    a[i] = _mm512_permutex2var_ps(lo, even, hi);
    b[i] = _mm512_permutex2var_ps(lo, odd, hi);
  }
}
// ... and back: the a and b sides interleaved again, two 64-byte stores per octet.
DRAPE_AVX512_FN __attribute__((always_inline)) inline void scatterPairs16(Vec4* x, const uint32_t* off,
                                                                          const __m512 (&a)[4], const __m512 (&b)[4]) {
  const __m512i lo_idx = _mm512_setr_epi32(0, 1, 2, 3, 16, 17, 18, 19, 4, 5, 6, 7, 20, 21, 22, 23);
  const __m512i hi_idx = _mm512_setr_epi32(8, 9, 10, 11, 24, 25, 26, 27, 12, 13, 14, 15, 28, 29, 30, 31);
  for (int i = 0; i < 4; ++i) {
    float* p = at(x, off[i]);
    _mm512_storeu_ps(p, _mm512_permutex2var_ps(a[i], lo_idx, b[i]));
    _mm512_storeu_ps(p + 16, _mm512_permutex2var_ps(a[i], hi_idx, b[i]));
  }
}

// How a batch's particles are laid out: any (one 16-byte load per particle), a quad batch
// (Batches::quad_runs) or a pair batch (RunKind::Pairs in Batches::wide_runs, distance
// constraints only).
enum class BatchLayout { Any, Quads, Pairs };

// One batch of 16 constraints (entries A[0..16), ...).
template <Kind kKind, BatchLayout kLayout>
DRAPE_AVX512_FN __attribute__((always_inline)) inline void projectBatch16(Vec4* x, const uint32_t* A,
                                                                          const uint32_t* B, const float* rest,
                                                                          const float* inv_w, __m512 vscale) {
  static_assert(kLayout != BatchLayout::Pairs || kKind != Kind::Tether, "tethers make no pair batches");
  constexpr bool kQuads = kLayout == BatchLayout::Quads;
  const __m512 zero = _mm512_setzero_ps();
  const __m512 tiny2 = _mm512_set1_ps(1e-18f), half = _mm512_set1_ps(0.5f);
  const __m512 three = _mm512_set1_ps(3.0f), one = _mm512_set1_ps(1.0f);
  const __m512 inf = _mm512_set1_ps(std::numeric_limits<float>::infinity());
  __m512 ax, ay, az, aw, bx, by, bz, bw;
  if (kLayout == BatchLayout::Pairs) {
    __m512 ra[4], rb[4];
    gatherPairs16(x, A, ra, rb);
    simd::transpose4(ra[0], ra[1], ra[2], ra[3], ax, ay, az, aw);
    simd::transpose4(rb[0], rb[1], rb[2], rb[3], bx, by, bz, bw);
  } else {
    gather16<kQuads>(x, A, ax, ay, az, aw);
    gather16<kQuads && kKind != Kind::Tether>(x, B, bx, by, bz, bw);  // a tether's quad is its a side
  }
  const __m512 dx = _mm512_sub_ps(ax, bx), dy = _mm512_sub_ps(ay, by), dz = _mm512_sub_ps(az, bz);
  const __m512 len2 = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(dx, dx), _mm512_mul_ps(dy, dy)),
                                    _mm512_mul_ps(dz, dz));
  const __mmask16 ok = _mm512_cmp_ps_mask(len2, tiny2, _CMP_GT_OQ);
  __m512 y = rsqrtAsAvx(len2);
  y = _mm512_mul_ps(_mm512_mul_ps(half, y), _mm512_sub_ps(three, _mm512_mul_ps(len2, _mm512_mul_ps(y, y))));
  const __m512 r = _mm512_loadu_ps(rest);
  __m512 s;
  if (kKind != Kind::Equality) {
    const __m512 c = _mm512_max_ps(_mm512_sub_ps(_mm512_mul_ps(len2, y), _mm512_mul_ps(r, vscale)), zero);
    // As the AVX kernel: a batch of slack inequalities (and finite d) writes nothing.
    const __mmask16 acts = _mm512_cmp_ps_mask(_mm512_maskz_mov_ps(ok, c), zero, _CMP_NEQ_UQ) |
                           _mm512_cmp_ps_mask(len2, inf, _CMP_NLT_UQ);
    if (acts == 0) return;
    s = _mm512_mul_ps(_mm512_mul_ps(c, y), _mm512_loadu_ps(inv_w));
  } else {
    s = _mm512_mul_ps(_mm512_sub_ps(one, _mm512_mul_ps(r, y)), _mm512_loadu_ps(inv_w));
  }
  s = _mm512_maskz_mov_ps(ok, s);  // +0 where |d| is too small, as the AVX kernel's _mm256_and_ps
  const __m512 sa = _mm512_mul_ps(aw, s);
  ax = _mm512_sub_ps(ax, _mm512_mul_ps(sa, dx));
  ay = _mm512_sub_ps(ay, _mm512_mul_ps(sa, dy));
  az = _mm512_sub_ps(az, _mm512_mul_ps(sa, dz));
  if (kLayout == BatchLayout::Pairs) {
    const __m512 sb = _mm512_mul_ps(bw, s);
    bx = _mm512_add_ps(bx, _mm512_mul_ps(sb, dx));
    by = _mm512_add_ps(by, _mm512_mul_ps(sb, dy));
    bz = _mm512_add_ps(bz, _mm512_mul_ps(sb, dz));
    __m512 ra[4], rb[4];
    simd::transpose4(ax, ay, az, aw, ra[0], ra[1], ra[2], ra[3]);
    simd::transpose4(bx, by, bz, bw, rb[0], rb[1], rb[2], rb[3]);
    scatterPairs16(x, A, ra, rb);
    return;
  }
  scatter16<kQuads>(x, A, ax, ay, az, aw);
  if (kKind != Kind::Tether) {
    const __m512 sb = _mm512_mul_ps(bw, s);
    bx = _mm512_add_ps(bx, _mm512_mul_ps(sb, dx));
    by = _mm512_add_ps(by, _mm512_mul_ps(sb, dy));
    bz = _mm512_add_ps(bz, _mm512_mul_ps(sb, dz));
    scatter16<kQuads>(x, B, bx, by, bz, bw);
  }
}

// Entries [first, m) of the lists; the runs (Batches::wide_runs, sorted, each within one colour
// group, so each lies wholly before or after `first`, a group's start) take the 64-byte paths.
template <Kind kKind>
DRAPE_AVX512_FN void projectBatchesAvx512(Vec4* x, const uint32_t* A, const uint32_t* B, const float* rest,
                                          const float* inv_w, size_t first, size_t m, float scale,
                                          const XpbdSolver::WideRun* runs, size_t run_count) {
  const __m512 vscale = _mm512_set1_ps(scale);
  size_t k = first;
  for (size_t r = 0; r < run_count; ++r) {
    if (runs[r].begin < first) continue;
    for (; k < runs[r].begin; k += 16)
      projectBatch16<kKind, BatchLayout::Any>(x, A + k, B + k, rest + k, inv_w + k, vscale);
    if constexpr (kKind != Kind::Tether) {  // tethers make no pair runs
      if (runs[r].kind == XpbdSolver::RunKind::Pairs) {
        for (; k < runs[r].end; k += 16)
          projectBatch16<kKind, BatchLayout::Pairs>(x, A + k, B + k, rest + k, inv_w + k, vscale);
        continue;
      }
    }
    for (; k < runs[r].end; k += 16)
      projectBatch16<kKind, BatchLayout::Quads>(x, A + k, B + k, rest + k, inv_w + k, vscale);
  }
  for (; k < m; k += 16) projectBatch16<kKind, BatchLayout::Any>(x, A + k, B + k, rest + k, inv_w + k, vscale);
}

// inv_w[k] = 1 / (w_ab[k] + comp[k] inv_h2) (0 where that is not positive) for whole sixteens of
// [first, end): the scalar loop's operations (a product, then a sum, then the division), so the
// same bits. Returns where it stopped (the caller's scalar loop does the rest). XpbdSolver::substep
// runs it over the compliant runs whenever h changes (every frame of a host whose frame times vary).
DRAPE_AVX512_FN uint32_t refreshInvWAvx512(const float* w_ab, const float* comp, float* inv_w, uint32_t first,
                                           uint32_t end, float inv_h2) {
  const __m512 h = _mm512_set1_ps(inv_h2), zero = _mm512_setzero_ps(), one = _mm512_set1_ps(1.0f);
  uint32_t k = first;
  for (; k + 16 <= end; k += 16) {
    const __m512 wsum = _mm512_add_ps(_mm512_loadu_ps(w_ab + k), _mm512_mul_ps(_mm512_loadu_ps(comp + k), h));
    const __mmask16 pos = _mm512_cmp_ps_mask(wsum, zero, _CMP_GT_OQ);
    _mm512_storeu_ps(inv_w + k, _mm512_maskz_div_ps(pos, one, wsum));
  }
  return k;
}
#if !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#endif

// A, B: particle indices; A_off, B_off: the same as byte offsets (empty when they would not fit
// 32 bits: then the SSE kernel).
// Entries [first, end) of the lists (first a multiple of the batch width: a colour group's start).
template <Kind kKind>
void project(Vec4* x, const std::vector<uint32_t>& A, const std::vector<uint32_t>& B,
             const std::vector<uint32_t>& A_off, const std::vector<uint32_t>& B_off, const float* rest,
             const float* inv_w, float scale, const std::vector<std::pair<uint32_t, uint32_t>>& quad_runs,
             const std::vector<XpbdSolver::WideRun>& wide_runs, size_t first = 0, bool wide = true) {
  const size_t m = A.size();
  if (first >= m) return;
#if DRAPE_XPBD_AVX
  if (wide && cpuHasAvx512() && A_off.size() == m && B_off.size() == m)
    return projectBatchesAvx512<kKind>(x, A_off.data(), B_off.data(), rest, inv_w, first, m, scale,
                                       wide_runs.data(), wide_runs.size());
  if (cpuHasAvx() && A_off.size() == m && B_off.size() == m)
    return projectBatchesAvx<kKind>(x, A_off.data(), B_off.data(), rest, inv_w, first, m, scale,
                                    quad_runs.data(), quad_runs.size());
#endif
  (void)A_off, (void)B_off, (void)wide, (void)quad_runs, (void)wide_runs;
  projectBatches<kKind>(x, A.data() + first, B.data() + first, rest + first, inv_w + first, m - first, scale);
}

#if DRAPE_XPBD_AVX
// a . a of each particle (xyzw) of a pair in one 256-bit register, in all four lanes of its
// half, summed as Eigen's SSE squaredNorm sums a packet: (x + z) + (y + w).
__attribute__((target("avx"), always_inline)) inline __m256 squaredNorms2(__m256 a) {
  const __m256 t = _mm256_mul_ps(a, a);
  const __m256 u = _mm256_add_ps(t, _mm256_permute_ps(t, _MM_SHUFFLE(1, 0, 3, 2)));  // x+z, y+w, z+x, w+y
  return _mm256_add_ps(u, _mm256_permute_ps(u, _MM_SHUFFLE(2, 3, 0, 1)));
}

// The fused velocity update + next prediction of XpbdSolver::substep for two particles at a
// time, from `i` on (AoS: one 256-bit register holds particles i and i + 1; unaligned loads and
// stores, the arrays are 16-byte aligned): the same operations per lane in the same order as the
// scalar loop, so the same bits. Returns where it stopped: n, or the first particle of a pair the
// speed clamp would act on (the caller runs that pair the scalar way, then calls again) or the
// odd last particle.
__attribute__((target("avx"))) size_t fusedPairsAvx(Vec4* x, Vec4* prev, Vec4* vel, Vec4* capture,
                                                     size_t i, size_t n, float scale, const Vec4& hg,
                                                     const Vec4& wind, float h_drag, float h,
                                                     float max_speed2) {
  const __m256 vscale = _mm256_set1_ps(scale), vh = _mm256_set1_ps(h), vdrag = _mm256_set1_ps(h_drag);
  const __m256 vhg = _mm256_broadcast_ps(reinterpret_cast<const __m128*>(hg.data()));
  const __m256 vwind = _mm256_broadcast_ps(reinterpret_cast<const __m128*>(wind.data()));
  const __m256 limit = _mm256_set1_ps(max_speed2), zero = _mm256_setzero_ps();
  const bool clamp = max_speed2 > 0.0f;
  for (; i + 2 <= n; i += 2) {
    const __m256 xi = _mm256_loadu_ps(x[i].data());
    __m256 v = _mm256_mul_ps(_mm256_sub_ps(xi, _mm256_loadu_ps(prev[i].data())), vscale);
    const __m256 vp = _mm256_add_ps(v, _mm256_add_ps(vhg, _mm256_mul_ps(vdrag, _mm256_sub_ps(vwind, v))));
    if (clamp && _mm256_movemask_ps(_mm256_or_ps(_mm256_cmp_ps(squaredNorms2(v), limit, _CMP_GT_OQ),
                                                 _mm256_cmp_ps(squaredNorms2(vp), limit, _CMP_GT_OQ))))
      return i;
    // Pinned particles (w = 0) keep their position and the first velocity.
    const __m256 pinned = _mm256_permute_ps(_mm256_cmp_ps(xi, zero, _CMP_EQ_OQ), _MM_SHUFFLE(3, 3, 3, 3));
    if (capture) _mm256_storeu_ps(capture[i].data(), xi);
    _mm256_storeu_ps(prev[i].data(), xi);
    // and/andnot/or rather than blendv: GCC lowered that blend lane by lane here.
    _mm256_storeu_ps(vel[i].data(), _mm256_or_ps(_mm256_and_ps(pinned, v), _mm256_andnot_ps(pinned, vp)));
    const __m256 moved = _mm256_add_ps(xi, _mm256_mul_ps(vh, vp));
    _mm256_storeu_ps(x[i].data(), _mm256_or_ps(_mm256_and_ps(pinned, xi), _mm256_andnot_ps(pinned, moved)));
  }
  return i;
}

#if !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
// squaredNorms2 for four particles (one per 128-bit lane).
DRAPE_AVX512_FN __attribute__((always_inline)) inline __m512 squaredNorms4(__m512 a) {
  const __m512 t = _mm512_mul_ps(a, a);
  const __m512 u = _mm512_add_ps(t, _mm512_permute_ps(t, _MM_SHUFFLE(1, 0, 3, 2)));
  return _mm512_add_ps(u, _mm512_permute_ps(u, _MM_SHUFFLE(2, 3, 0, 1)));
}
// fusedPairsAvx four particles at a time (AVX-512F): the same operations per lane, so the same
// bits. Returns where it stopped: the first particle of a quad the speed clamp would act on, or
// where fewer than four are left (the caller goes on with fusedPairsAvx from there).
DRAPE_AVX512_FN size_t fusedQuadsAvx512(Vec4* x, Vec4* prev, Vec4* vel, Vec4* capture, size_t i, size_t n,
                                        float scale, const Vec4& hg, const Vec4& wind, float h_drag, float h,
                                        float max_speed2) {
  const __m512 vscale = _mm512_set1_ps(scale), vh = _mm512_set1_ps(h), vdrag = _mm512_set1_ps(h_drag);
  const __m512 vhg = _mm512_broadcast_f32x4(_mm_loadu_ps(hg.data()));
  const __m512 vwind = _mm512_broadcast_f32x4(_mm_loadu_ps(wind.data()));
  const __m512 limit = _mm512_set1_ps(max_speed2), zero = _mm512_setzero_ps();
  const bool clamp = max_speed2 > 0.0f;
  for (; i + 4 <= n; i += 4) {
    const __m512 xi = _mm512_loadu_ps(x[i].data());
    const __m512 v = _mm512_mul_ps(_mm512_sub_ps(xi, _mm512_loadu_ps(prev[i].data())), vscale);
    const __m512 vp = _mm512_add_ps(v, _mm512_add_ps(vhg, _mm512_mul_ps(vdrag, _mm512_sub_ps(vwind, v))));
    if (clamp && (_mm512_cmp_ps_mask(squaredNorms4(v), limit, _CMP_GT_OQ) |
                  _mm512_cmp_ps_mask(squaredNorms4(vp), limit, _CMP_GT_OQ)))
      return i;
    // Pinned particles (w = 0) keep their position and the first velocity: each particle's w
    // lane's bit (3, 7, 11, 15) spread to its four lanes.
    unsigned pinned = _mm512_cmp_ps_mask(xi, zero, _CMP_EQ_OQ) & 0x8888u;
    pinned |= pinned >> 1;
    pinned |= pinned >> 2;
    const __mmask16 keep = static_cast<__mmask16>(pinned);
    if (capture) _mm512_storeu_ps(capture[i].data(), xi);
    _mm512_storeu_ps(prev[i].data(), xi);
    _mm512_storeu_ps(vel[i].data(), _mm512_mask_blend_ps(keep, vp, v));
    const __m512 moved = _mm512_add_ps(xi, _mm512_mul_ps(vh, vp));
    _mm512_storeu_ps(x[i].data(), _mm512_mask_blend_ps(keep, moved, xi));
  }
  return i;
}
#if !defined(__clang__)
#pragma GCC diagnostic pop
#endif

// c0 d.x + (c1 d.y + c2 d.z) for each 128-bit half's d (c0..c2: a 3 x 3 matrix's columns), the
// order Eigen's unrolled sum of three products takes (it splits a length-3 sum as 1 + 2).
__attribute__((target("avx"), always_inline)) inline __m256 rotatePair(__m256 c0, __m256 c1, __m256 c2, __m256 d) {
  return _mm256_add_ps(_mm256_mul_ps(c0, _mm256_permute_ps(d, 0x00)),
                       _mm256_add_ps(_mm256_mul_ps(c1, _mm256_permute_ps(d, 0x55)),
                                     _mm256_mul_ps(c2, _mm256_permute_ps(d, 0xAA))));
}

// XpbdSolver::transform's rigid map for particles [0, n - n % 2), two per 256-bit register:
// x = R (x - pivot) + shift and prev likewise, v = s (R v), each product as Eigen's 3 x 3 times
// 3-vector sums it, R_i0 d_x + (R_i1 d_y + R_i2 d_z) (no FMA; s R_ik for v), and the w lanes kept:
// the same bits. Returns how many particles it did.
__attribute__((target("avx"))) size_t transformPairsAvx(Vec4* x, Vec4* prev, Vec4* vel, size_t n, const Mat3& R,
                                                        const Vec3& pivot, const Vec3& shift, float velocity_scale) {
  const __m256 c0 = _mm256_setr_ps(R(0, 0), R(1, 0), R(2, 0), 0.0f, R(0, 0), R(1, 0), R(2, 0), 0.0f);
  const __m256 c1 = _mm256_setr_ps(R(0, 1), R(1, 1), R(2, 1), 0.0f, R(0, 1), R(1, 1), R(2, 1), 0.0f);
  const __m256 c2 = _mm256_setr_ps(R(0, 2), R(1, 2), R(2, 2), 0.0f, R(0, 2), R(1, 2), R(2, 2), 0.0f);
  const __m256 vpivot = _mm256_setr_ps(pivot.x(), pivot.y(), pivot.z(), 0.0f, pivot.x(), pivot.y(), pivot.z(), 0.0f);
  const __m256 vshift = _mm256_setr_ps(shift.x(), shift.y(), shift.z(), 0.0f, shift.x(), shift.y(), shift.z(), 0.0f);
  // Eigen folds the scalar of s (R v) into the matrix: (s R_ik) v_k, summed as above.
  const __m256 vs = _mm256_set1_ps(velocity_scale);
  const __m256 s0 = _mm256_mul_ps(vs, c0), s1 = _mm256_mul_ps(vs, c1), s2 = _mm256_mul_ps(vs, c2);
  // Lanes x, y, z of each particle (w from the input).
  const __m256 xyz = _mm256_castsi256_ps(_mm256_setr_epi32(-1, -1, -1, 0, -1, -1, -1, 0));
  size_t i = 0;
  for (; i + 2 <= n; i += 2) {
    for (Vec4* p : {x, prev}) {
      const __m256 a = _mm256_loadu_ps(p[i].data());
      const __m256 moved = _mm256_add_ps(rotatePair(c0, c1, c2, _mm256_sub_ps(a, vpivot)), vshift);
      _mm256_storeu_ps(p[i].data(), _mm256_or_ps(_mm256_and_ps(xyz, moved), _mm256_andnot_ps(xyz, a)));
    }
    const __m256 v = _mm256_loadu_ps(vel[i].data());
    const __m256 turned = rotatePair(s0, s1, s2, v);
    _mm256_storeu_ps(vel[i].data(), _mm256_or_ps(_mm256_and_ps(xyz, turned), _mm256_andnot_ps(xyz, v)));
  }
  return i;
}
#endif

}  // namespace

XpbdSolver::XpbdSolver(GarmentTopology topology) : topology_(std::move(topology)) {
  const size_t n = topology_.particleCount();
  x_.resize(n + 1);
  v_.assign(n + 1, Vec4::Zero());
  for (size_t i = 0; i < n; ++i) {
    const Vec3& p = topology_.rest_positions[i];
    x_[i] = Vec4(p.x(), p.y(), p.z(), topology_.inverse_mass[i]);
  }
  x_[n] = Vec4::Zero();  // the dummy particle padding constraints point at (w = 0: never moves)
  prev_ = x_;
  pin_start_.resize(topology_.pinned.size());
  pin_target_.resize(topology_.pinned.size());
  for (size_t k = 0; k < topology_.pinned.size(); ++k)
    pin_target_[k] = topology_.rest_positions[topology_.pinned[k]];
  buildBatches();
}

void XpbdSolver::buildBatches() {
  const uint32_t dummy = static_cast<uint32_t>(topology_.particleCount());
  distance_ = Batches{};
  tethers_ = Batches{};
  distance_kind_.clear();
  // kDistanceKindOrder (xpbd_solver.h): stretch after shear and bend, so that a substep's pass
  // leaves the structural edges as close to their rest lengths as one Gauss–Seidel pass gets
  // them (only the tethers, inequalities that act on few particles, come after).
  const DistanceConstraints* kinds[3] = {&topology_.stretch, &topology_.shear, &topology_.bend};
  for (uint8_t k : kDistanceKindOrder) {
    if (k == 0) stretch_first_ = distance_.a.size();  // where the stretch colour groups start
    appendPadded(*kinds[k], true, 0.0f, dummy, &distance_kind_, k, distance_.a, distance_.b,
                 distance_.rest, distance_.compliance, distance_.group_offsets, distance_.quad_runs,
                 distance_.wide_runs);
  }
  appendPadded(topology_.tether, false, 0.0f, dummy, nullptr, 0, tethers_.a, tethers_.b,
               tethers_.rest, tethers_.compliance, tethers_.group_offsets, tethers_.quad_runs,
               tethers_.wide_runs);
  // The inverse masses are the topology's and never change (reset restores them), so their pair
  // sums are fixed with the batches; the dummy particle weighs nothing (w = 0).
  auto w = [&](uint32_t i) { return i < dummy ? topology_.inverse_mass[i] : 0.0f; };
  for (Batches* b : {&distance_, &tethers_}) {
    b->w_ab.resize(b->a.size());
    for (size_t k = 0; k < b->a.size(); ++k) b->w_ab[k] = w(b->a[k]) + (b == &tethers_ ? 0.0f : w(b->b[k]));
  }
  // Byte offsets for the AVX kernel, when the dummy particle's fits 32 bits (always, for the
  // garments the templates and the OBJ reader make: 4 G / 16 bytes is 268 M particles).
  constexpr uint64_t kStride = sizeof(Eigen::Vector4f);
  const bool fits = (uint64_t{dummy} + 1) * kStride <= uint64_t{UINT32_MAX};
  for (Batches* b : {&distance_, &tethers_}) {
    b->a_off.clear();
    b->b_off.clear();
    if (!fits) continue;
    b->a_off.resize(b->a.size());
    b->b_off.resize(b->b.size());
    for (size_t k = 0; k < b->a.size(); ++k) {
      b->a_off[k] = static_cast<uint32_t>(b->a[k] * kStride);
      b->b_off[k] = static_cast<uint32_t>(b->b[k] * kStride);
    }
  }
  refreshCompliance();
}

void XpbdSolver::refreshCompliance() {
  inv_w_h2_ = -1.0f;  // recompute inv_w at the next substep
  distance_.inv_w.resize(distance_.a.size());
  tethers_.inv_w.resize(tethers_.a.size());
  const float by_kind[4] = {params_.stretch_compliance, params_.shear_compliance,
                            params_.bend_compliance, 0.0f};
  for (size_t k = 0; k < distance_kind_.size(); ++k)
    distance_.compliance[k] = by_kind[distance_kind_[k]];
  for (size_t k = 0; k < tethers_.a.size(); ++k)
    tethers_.compliance[k] = tethers_.a[k] == topology_.particleCount() ? 0.0f : params_.tether_compliance;
  // Rigid entries: 1 / (w_a + w_b + 0 / h^2) is the same for every h (w_ab + 0 == w_ab).
  for (Batches* b : {&distance_, &tethers_}) {
    b->compliant.clear();
    for (size_t k = 0; k < b->a.size(); ++k) {
      if (b->compliance[k] != 0.0f) {
        if (b->compliant.empty() || b->compliant.back().second != k)
          b->compliant.emplace_back(static_cast<uint32_t>(k), static_cast<uint32_t>(k));
        ++b->compliant.back().second;
        continue;
      }
      b->inv_w[k] = b->w_ab[k] > 0.0f ? 1.0f / b->w_ab[k] : 0.0f;
    }
  }
}

bool XpbdSolver::setParams(const XpbdParams& p, std::string& error) {
  if (!finite(p.gravity) || !finite(p.wind)) {
    error = "gravity and wind must be finite";
    return false;
  }
  const float non_negative[] = {p.stretch_compliance, p.shear_compliance, p.bend_compliance,
                                p.tether_compliance, p.damping, p.drag};
  for (float f : non_negative) {
    if (!finite(f) || f < 0.0f) {
      error = "compliance, damping and drag must be finite and not negative";
      return false;
    }
  }
  if (!finite(p.tether_scale) || p.tether_scale < 1.0f) {
    error = "tether_scale must be finite and at least 1";
    return false;
  }
  if (!finite(p.max_speed)) {
    error = "max_speed must be finite (<= 0 disables the clamp)";
    return false;
  }
  if (p.collision_stride < 0 || p.collision_stride > 8) {
    error = "collision_stride must be in [0, 8] (0: by the garment's resolution)";
    return false;
  }
  if (p.iterations < 1 || p.iterations > 64) {
    error = "iterations must be in [1, 64]";
    return false;
  }
  if (!finite(p.strain_limit) || p.strain_limit < 0.0f || p.strain_limit > 10.0f) {
    error = "strain_limit must be in [0, 10] (0 = off)";
    return false;
  }
  if (p.strain_limit_passes < 1 || p.strain_limit_passes > 16) {
    error = "strain_limit_passes must be in [1, 16]";
    return false;
  }
  params_ = p;
  refreshCompliance();
  return true;
}

bool XpbdSolver::setPinTargets(const Vec3* targets, size_t count, std::string& error) {
  if (count != pin_target_.size() || (count > 0 && targets == nullptr)) {
    error = "expected " + std::to_string(pin_target_.size()) + " pin targets, got " +
            std::to_string(count);
    return false;
  }
  for (size_t k = 0; k < count; ++k) {
    if (!finite(targets[k])) {
      error = "pin target " + std::to_string(k) + " is not finite";
      return false;
    }
  }
  for (size_t k = 0; k < count; ++k) pin_target_[k] = targets[k];
  return true;
}

bool XpbdSolver::reset(const Vec3* positions, size_t count, std::string& error) {
  if (count != particleCount() || positions == nullptr) {
    error = "expected " + std::to_string(particleCount()) + " positions, got " + std::to_string(count);
    return false;
  }
  for (size_t i = 0; i < count; ++i) {
    if (!finite(positions[i])) {
      error = "position " + std::to_string(i) + " is not finite";
      return false;
    }
  }
  // w from the topology as well: a reset is also how a garment recovers from a bad state, and
  // the inverse masses are part of what must be right afterwards.
  for (size_t i = 0; i < count; ++i) {
    x_[i] = Vec4(positions[i].x(), positions[i].y(), positions[i].z(), topology_.inverse_mass[i]);
    v_[i].setZero();
  }
  prev_ = x_;  // same size: no allocation
  for (size_t k = 0; k < pin_target_.size(); ++k) pin_target_[k] = positions[topology_.pinned[k]];
  return true;
}

bool XpbdSolver::step(float dt, int substeps) {
  if (!(dt > 0.0f) || !(dt <= 1.0f) || substeps < 1 || substeps > 1000) return false;
  if (!(dt / static_cast<float>(substeps) >= kMinSubstepS)) return false;
  for (size_t k = 0; k < pin_start_.size(); ++k)
    pin_start_[k] = x_[topology_.pinned[k]].head<3>();
  collision_stats_ = CollisionStats{};
  timings_ = XpbdTimings{};
  const float h = dt / static_cast<float>(substeps);
  const float inv_n = 1.0f / static_cast<float>(substeps);
  const int stride = collisionStrideFor(params_.collision_stride, particleCount());
  int span0 = 0;
  bool predicted = false;  // substep s's prediction already ran, fused into s - 1's last loop
  for (int s = 0; s < substeps; ++s) {
    const bool collide = (s + 1 - span0) >= stride || s + 1 == substeps;
    const bool last = s + 1 == substeps;
    // A span's start positions are taken just before its first prediction: here for the step's
    // first substep, else inside the fused loop of the substep before (`capture`).
    if (stride > 1 && s == 0) span_start_.assign(x_.begin(), x_.end());  // same size: no allocation
    const EllipsoidCollider* collider = nullptr;
    if (collide) {
      const Clock::time_point t0 = timing_ ? Clock::now() : Clock::time_point{};
      collider = motion_.active() ? motion_.beginSpan(span0, s + 1, substeps) : collider_;
      if (timing_) timings_.collision_ns += nsBetween(t0, Clock::now());
    }
    Vec4* capture = (stride > 1 && collide && !last) ? span_start_.data() : nullptr;
    substep(h, last ? 1.0f : static_cast<float>(s + 1) * inv_n, collider,
            stride > 1 ? span_start_.data() : nullptr, predicted, !last, capture);
    predicted = !last;
    if (collide) span0 = s + 1;
  }
  return true;
}

void XpbdSolver::transform(const Mat3& R, const Vec3& pivot, const Vec3& t, float velocity_scale) {
  const Vec3 shift = pivot + t;
  size_t first = 0;
#if DRAPE_XPBD_AVX
  if (cpuHasAvx())
    first = transformPairsAvx(x_.data(), prev_.data(), v_.data(), particleCount(), R, pivot, shift, velocity_scale);
#endif
  for (size_t i = first; i < particleCount(); ++i) {
    x_[i].head<3>() = R * (Vec3(x_[i].head<3>()) - pivot) + shift;
    prev_[i].head<3>() = R * (Vec3(prev_[i].head<3>()) - pivot) + shift;
    v_[i].head<3>() = velocity_scale * (R * Vec3(v_[i].head<3>()));
  }
  for (Vec3& p : pin_target_) p = R * (p - pivot) + shift;
}

void XpbdSolver::substep(float h, float pin_t, const EllipsoidCollider* collider,
                         const Eigen::Vector4f* span_prev, bool predicted, bool predict_next,
                         Eigen::Vector4f* capture) {
  const Clock::time_point start = timing_ ? Clock::now() : Clock::time_point{};
  const double collision_before = timings_.collision_ns;
  const XpbdParams& p = params_;
  const size_t n = particleCount();
  Vec4* x = x_.data();
  Vec4* prev = prev_.data();
  Vec4* vel = v_.data();
  // 1. Predict: explicit velocity update (gravity, drag towards the wind), clamp, move. Four-lane
  // arithmetic with w = 0 in v, g and the wind, so x's w (inverse mass) is carried unchanged.
  const Vec4 hg = h * Vec4(p.gravity.x(), p.gravity.y(), p.gravity.z(), 0.0f);
  const Vec4 wind(p.wind.x(), p.wind.y(), p.wind.z(), 0.0f);
  const float h_drag = h * p.drag;
  const float max_speed2 = p.max_speed > 0.0f ? p.max_speed * p.max_speed : 0.0f;
  // Particle i's prediction from its velocity v (xi = its position now).
  auto predict = [&](size_t i, const Vec4& xi, Vec4 v) DRAPE_LAMBDA_INLINE {
    prev[i] = xi;
    if (xi.w() == 0.0f) {
      vel[i] = v;
      return;
    }
    v += hg + h_drag * (wind - v);
    if (max_speed2 > 0.0f) {
      const float s2 = v.squaredNorm();
      if (s2 > max_speed2) v *= p.max_speed / std::sqrt(s2);
    }
    vel[i] = v;
    x[i] = xi + h * v;
  };
  if (!predicted)
    for (size_t i = 0; i < n; ++i) predict(i, x[i], vel[i]);
  // Pinned particles follow their targets, interpolated linearly across the step.
  for (size_t k = 0; k < pin_target_.size(); ++k) {
    const Vec3 at = pin_start_[k] + pin_t * (pin_target_[k] - pin_start_[k]);
    x[topology_.pinned[k]].head<3>() = at;
  }
  // 2. One XPBD iteration (alpha~ = alpha / h^2): shear, bend and stretch colour by colour (one
  // list, kDistanceKindOrder), then tethers.
  const float inv_h2 = 1.0f / (h * h);
  if (inv_h2 != inv_w_h2_) {  // h changed (or params): refresh 1 / (w_a + w_b + alpha~)
    inv_w_h2_ = inv_h2;
    // Host frame times vary (a Kinect's by a few per cent), so h and this refresh change nearly
    // every step: only the compliant runs (shear and bend by default, ~40 % of the entries),
    // contiguous, no gathers (w_a + w_b first, as the sum was always written).
    for (Batches* b : {&distance_, &tethers_}) {
      const float* w_ab = b->w_ab.data();
      const float* comp = b->compliance.data();
      float* inv_w = b->inv_w.data();
      for (const auto& run : b->compliant) {
        uint32_t k = run.first;
#if DRAPE_XPBD_AVX
        if (wide_projection_ && cpuHasAvx512()) k = refreshInvWAvx512(w_ab, comp, inv_w, k, run.second, inv_h2);
#endif
        for (; k < run.second; ++k) {
          const float wsum = w_ab[k] + comp[k] * inv_h2;
          inv_w[k] = wsum > 0.0f ? 1.0f / wsum : 0.0f;
        }
      }
    }
  }
  for (int it = 0; it < p.iterations; ++it) {  // 1 by default: the method's single pass
    project<Kind::Equality>(x, distance_.a, distance_.b, distance_.a_off, distance_.b_off,
                            distance_.rest.data(), distance_.inv_w.data(), 1.0f, distance_.quad_runs,
                            distance_.wide_runs, 0, wide_projection_);
    project<Kind::Tether>(x, tethers_.a, tethers_.b, tethers_.a_off, tethers_.b_off, tethers_.rest.data(),
                          tethers_.inv_w.data(), p.tether_scale, tethers_.quad_runs, tethers_.wide_runs, 0,
                          wide_projection_);
  }
  // The strain limit (XpbdParams::strain_limit) on the step's last substep, before collision so
  // that no particle is left inside an ellipsoid.
  static_assert(kDistanceKindOrder[2] == 0, "the strain limit's passes run from the stretch groups to the end");
  if (!predict_next && p.strain_limit > 0.0f) {
    for (int pass = 0; pass < p.strain_limit_passes; ++pass)
      project<Kind::Limit>(x, distance_.a, distance_.b, distance_.a_off, distance_.b_off, distance_.rest.data(),
                           distance_.inv_w.data(), 1.0f + p.strain_limit, distance_.quad_runs, distance_.wide_runs,
                           stretch_first_, wide_projection_);
  }
  // 3. Collision against the tracking ellipsoids.
  if (collider != nullptr) {
    const Clock::time_point t0 = timing_ ? Clock::now() : Clock::time_point{};
    CollisionStats cs = collider->collide(x, span_prev ? span_prev : prev, n, p.collision);
    const DistanceConstraints& rims = topology_.rims;
    if (p.collision.rims && rims.size() > 0)
      collider->collideRims(x, n, rims.a.data(), rims.b.data(), rims.size(), p.collision, cs,
                            rim_gate_.size() == n ? rim_gate_.data() : nullptr);
    collision_stats_.tests += cs.tests;
    collision_stats_.contacts += cs.contacts;
    collision_stats_.swept_catches += cs.swept_catches;
    collision_stats_.escapes += cs.escapes;
    if (timing_) timings_.collision_ns += nsBetween(t0, Clock::now());
  }
  // 4. Velocities from positions, then damping (w lane: w - w = 0).
  // The speed clamp applies here too: a collision or constraint correction (a particle squeezed
  // out between two limbs) must not turn into a velocity that flings it on the next substep.
  // Then (predict_next) the next substep's prediction in the same pass over the particles:
  // one pass instead of two, the same arithmetic per particle.
  const float scale = std::exp(-p.damping * h) / h;
  auto update = [&](size_t i) DRAPE_LAMBDA_INLINE {
    Vec4 v = (x[i] - prev[i]) * scale;
    if (max_speed2 > 0.0f) {
      const float s2 = v.squaredNorm();
      if (s2 > max_speed2) v *= p.max_speed / std::sqrt(s2);
    }
    if (!predict_next) {
      vel[i] = v;
      return;
    }
    const Vec4 xi = x[i];
    if (capture) capture[i] = xi;
    predict(i, xi, v);
  };
  size_t i = 0;
#if DRAPE_XPBD_AVX
  // Four particles at a time where the CPU has AVX-512F, two where it has AVX; a pair the speed
  // clamp acts on (rare) and an odd last particle go the scalar way. (After a quad the clamp acts
  // on, the rest of the substep goes by pairs: simpler, and the clamp is rare.)
  if (predict_next && paired_update_ && cpuHasAvx()) {
    if (wide_projection_ && cpuHasAvx512())
      i = fusedQuadsAvx512(x, prev, vel, capture, i, n, scale, hg, wind, h_drag, h, max_speed2);
    while ((i = fusedPairsAvx(x, prev, vel, capture, i, n, scale, hg, wind, h_drag, h, max_speed2)) < n) {
      const size_t stop = std::min(n, i + 2);
      for (; i < stop; ++i) update(i);
    }
  }
#endif
  for (; i < n; ++i) update(i);
  if (timing_) {
    const double collided = timings_.collision_ns - collision_before;
    timings_.constraints_ns += nsBetween(start, Clock::now()) - collided;
  }
}

}  // namespace drape
