// CollisionParams::batch8: pass 0 of the collider for eight consecutive particles at once (AVX,
// chosen at run time). docs/collision.md, "Eight particles at once".
#include "proxies/collision_internal.h"

#include "common/cpu.h"

#include <cstring>
#include <limits>

#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
#include <immintrin.h>
#endif

namespace drape {
using namespace collision_internal;

#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
namespace {
// The 8 lanes of v.
struct Lanes {
  alignas(32) float v[8];
};
#define DRAPE_AVX_INLINE __attribute__((target("avx"), always_inline)) inline
DRAPE_AVX_INLINE __m256 bcast(float f) { return _mm256_set1_ps(f); }
// q = U (p - c) per lane, as mulq: (u0 * d.x + u1 * d.y) + u2 * d.z per component.
DRAPE_AVX_INLINE void unitSpace8(const Vec4* u, const Vec4& cen, __m256 px, __m256 py, __m256 pz, __m256& qx,
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
DRAPE_AVX_INLINE void load8(const Vec4* v, __m256& x, __m256& y, __m256& z, __m256& w) {
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
alignas(16) constexpr int32_t kNibbleLanes[16][4] = {
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
// The OR of the grid cells [lo, hi] (W bitmask words each), ANDed with `allowed` when given,
// into out[0..W): the broad phase's gather with the words in registers (and written once: a
// wider load of words just stored one by one would stall on store forwarding).
template <int W>
DRAPE_AVX_INLINE void orCells(const uint64_t* cells, int dim_x, int dim_y, const Eigen::Array4i& lo,
                              const Eigen::Array4i& hi, const uint64_t* allowed, uint64_t* out) {
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
                               const Vec4& mn, const Vec4& mx) {
  return _mm256_and_ps(
      _mm256_and_ps(_mm256_and_ps(_mm256_cmp_ps(lox, bcast(mx.x()), _CMP_LE_OQ), _mm256_cmp_ps(hix, bcast(mn.x()), _CMP_GE_OQ)),
                    _mm256_and_ps(_mm256_cmp_ps(loy, bcast(mx.y()), _CMP_LE_OQ), _mm256_cmp_ps(hiy, bcast(mn.y()), _CMP_GE_OQ))),
      _mm256_and_ps(_mm256_cmp_ps(loz, bcast(mx.z()), _CMP_LE_OQ), _mm256_cmp_ps(hiz, bcast(mn.z()), _CMP_GE_OQ)));
}
}  // namespace

// Pass 0 of resolveParticle for 8 particles, lane by lane the same arithmetic in the same order
// (Eigen's 4-lane sums are (x + z) + y with w = 0, reproduced below; no FMA), so every particle
// meets the same tests with the same values and gets the same contacts: bit-identical results.
// What it saves is per-particle overhead: one grid gather for the 8 particles' joint box instead
// of 8, and one box test and narrow test per candidate for 8 particles. Contacts (rare: under 10 %
// of particle tests) and the later passes stay one particle at a time.
__attribute__((target("avx"))) size_t EllipsoidCollider::collideEights(Eigen::Vector4f* positions,
                                                                        const Eigen::Vector4f* previous,
                                                                        size_t count, const CollisionParams& p,
                                                                        bool grouped, CollisionStats& st) const {
  // More ellipsoids than the grid takes (broad phase off): one particle at a time.
  if (!cpuHasAvx() || shapes_.size() > static_cast<size_t>(kMaxGridEllipsoids)) return 0;
  // Every lane that takes part has a finite start position when `previous` is given (the others
  // go the one-particle way), so the swept test and friction are the same for all of them.
  const bool cont = p.continuous && previous != nullptr;
  const bool friction = previous != nullptr && (p.static_friction > 0.0f || p.kinetic_friction > 0.0f);
  const bool use_grid = p.broad_phase && grid_;
  const Vec4 gmin = lift(grid_min_), gmax = lift(grid_max_);
  const __m256 zero = _mm256_setzero_ps();
  const __m256 inf = _mm256_set1_ps(std::numeric_limits<float>::infinity()),
               minf = _mm256_set1_ps(-std::numeric_limits<float>::infinity());
  const __m256 one = _mm256_set1_ps(1.0f);
  const size_t end = count - count % 8;
  for (size_t begin = 0; begin < end; begin += 8) {
    Lanes X, Y, Z, X0, Y0, Z0;
    // The eight particles' positions (and start positions) loaded at once, lane j = particle
    // begin + j, and collide()'s per-particle rejections (mayTouch) for all lanes together: the
    // same comparisons, so the same lanes take part.
    __m256 px, py, pz, pw, p0x, p0y, p0z, p0w;
    load8(positions + begin, px, py, pz, pw);
    if (previous) {
      load8(previous + begin, p0x, p0y, p0z, p0w);
    } else {
      p0x = px, p0y = py, p0z = pz;
    }
    const __m256 finite = finite8(px, py, pz);
    const __m256 finite0 = previous ? finite8(p0x, p0y, p0z) : finite;
    // Each lane's box: its motion box with the swept test (finite start positions: plain min /
    // max), else its end position.
    const __m256 lox = cont ? _mm256_min_ps(px, p0x) : px, loy = cont ? _mm256_min_ps(py, p0y) : py,
                 loz = cont ? _mm256_min_ps(pz, p0z) : pz;
    const __m256 hix = cont ? _mm256_max_ps(px, p0x) : px, hiy = cont ? _mm256_max_ps(py, p0y) : py,
                 hiz = cont ? _mm256_max_ps(pz, p0z) : pz;
    __m256 touch = boxes8(px, py, pz, px, py, pz, gmin, gmax);  // x inside the grid's box
    if (cont) touch = _mm256_or_ps(touch, boxes8(lox, loy, loz, hix, hiy, hiz, gmin, gmax));  // or its motion box
    touch = _mm256_and_ps(_mm256_and_ps(touch, finite), _mm256_cmp_ps(pw, zero, _CMP_GT_OQ));
    // A lane without a finite start position goes the one-particle way (its own mayTouch first:
    // the swept box test above assumed finite start positions).
    int scalar = previous ? (0xFF & ~_mm256_movemask_ps(finite0)) : 0;
    const int active = _mm256_movemask_ps(touch) & ~scalar;  // bit j: lane j takes part in pass 0
    while (scalar) {
      const int j = __builtin_ctz(static_cast<unsigned>(scalar));
      scalar &= scalar - 1;
      const size_t i = begin + static_cast<size_t>(j);
      if (!mayTouch(positions, previous, i, cont)) continue;  // as collide()'s particle loop
      const Vec3 x = positions[i].head<3>();
      Vec3 y = x;
      resolveParticle(y, x, false, p, allowedFor(grouped, i), st);
      if (y != x) positions[i].head<3>() = y;
    }
    if (active == 0) continue;
    _mm256_store_ps(X.v, px), _mm256_store_ps(Y.v, py), _mm256_store_ps(Z.v, pz);
    _mm256_store_ps(X0.v, p0x), _mm256_store_ps(Y0.v, p0y), _mm256_store_ps(Z0.v, p0z);
    // The joint box of the lanes taking part (the others set to an empty box first).
    // and/andnot/or rather than blendv: GCC 12 lowered that blend lane by lane here.
    const __m256 on = laneMask8(active);
    const Vec3 lo(hmin8(select8(on, lox, inf)), hmin8(select8(on, loy, inf)), hmin8(select8(on, loz, inf)));
    const Vec3 hi(hmax8(select8(on, hix, minf)), hmax8(select8(on, hiy, minf)), hmax8(select8(on, hiz, minf)));
    // Lane j's collision mask in byte j: lane j may touch ellipsoid k when its byte shares a bit
    // with groups_[k] (what allowed_ tabulates, setGroups), so one AND and one byte compare give
    // the lanes allowed for k. Lanes not taking part keep 0. The lanes' joint candidates are those
    // of the union of their masks (allowed for m1 or m2 = allowed for m1 | m2). When every lane
    // taking part has the same mask, the joint candidates are exactly each lane's own: no
    // per-candidate test then.
    uint64_t lane_masks = 0;
    const uint64_t* joint_allowed = nullptr;
    bool mixed = false;
    if (grouped) {
      std::memcpy(&lane_masks, particle_masks_ + begin, sizeof lane_masks);
      const uint64_t on_bytes = byteMask8(on);
      lane_masks &= on_bytes;
      uint64_t m = lane_masks;
      m |= m >> 32;
      m |= m >> 16;
      m |= m >> 8;
      m &= 0xFFu;
      mixed = lane_masks != (0x0101010101010101ull * m & on_bytes);
      joint_allowed = allowedRow(static_cast<uint8_t>(m));
    }
    // The broad phase's gather (collision_internal.h) for the joint box, with the multi-cell
    // union kept in registers: the same candidates.
    if (!overlaps(lo, hi, grid_min_, grid_max_)) continue;  // outside every swept box
    Candidates c;
    c.all = !use_grid;
    c.allowed = joint_allowed;
    if (!c.all) {
      c.lo = cellsOf(lo, cell_origin_, cell_scale_, cell_top_);
      c.hi = cellsOf(hi, cell_origin_, cell_scale_, cell_top_);
      switch (words_) {
        case 1: orCells<1>(cells_.data(), dims_[0], dims_[1], c.lo, c.hi, joint_allowed, c.mask); break;
        case 2: orCells<2>(cells_.data(), dims_[0], dims_[1], c.lo, c.hi, joint_allowed, c.mask); break;
        case 3: orCells<3>(cells_.data(), dims_[0], dims_[1], c.lo, c.hi, joint_allowed, c.mask); break;
        default: orCells<4>(cells_.data(), dims_[0], dims_[1], c.lo, c.hi, joint_allowed, c.mask); break;
      }
    }
    const __m256 x0x = p0x, x0y = p0y, x0z = p0z;
    int moved = 0;
    int ks[kMaxGridEllipsoids];
    int candidates = 0;
    iterate(c, [&](int k) { ks[candidates++] = k; });
    for (int n = 0; n < candidates; ++n) {
      const int k = ks[n];
      const Quick& qk = quick_[static_cast<size_t>(k)];
      int lanes = active;
      if (mixed) {
        const uint64_t shared = lane_masks & (0x0101010101010101ull * groups_[static_cast<size_t>(k)]);
        const int none = _mm_movemask_epi8(_mm_cmpeq_epi8(_mm_cvtsi64_si128(static_cast<long long>(shared)),
                                                           _mm_setzero_si128())) & 0xFF;
        lanes &= ~none;
      }
      // X, Y, Z as contacts with earlier candidates left them.
      const __m256 cx = _mm256_load_ps(X.v), cy = _mm256_load_ps(Y.v), cz = _mm256_load_ps(Z.v);
      // The swept box (fixed per particle) against the ellipsoid's swept box, or the end position
      // as pass 0 saw it (lo = hi = x then) in the end box.
      const __m256 in_box = cont ? boxes8(lox, loy, loz, hix, hiy, hiz, qk.swept_min, qk.swept_max)
                                 : boxes8(lox, loy, loz, hix, hiy, hiz, qk.end_min, qk.end_max);
      lanes &= _mm256_movemask_ps(in_box);
      if (!lanes) continue;
      st.tests += static_cast<uint32_t>(__builtin_popcount(static_cast<unsigned>(lanes)));
      __m256 q1x, q1y, q1z;
      unitSpace8(qk.end_u, qk.end_c, cx, cy, cz, q1x, q1y, q1z);
      const __m256 r2 = dot8(q1x, q1y, q1z, q1x, q1y, q1z);
      const __m256 inside = _mm256_cmp_ps(r2, one, _CMP_LT_OQ);
      __m256 q0x = zero, q0y = zero, q0z = zero, q0sq = zero, hit = inside;
      if (cont) {
        unitSpace8(qk.start_u, qk.start_c, x0x, x0y, x0z, q0x, q0y, q0z);
        q0sq = dot8(q0x, q0y, q0z, q0x, q0y, q0z);
        const __m256 dx = _mm256_sub_ps(q1x, q0x), dy = _mm256_sub_ps(q1y, q0y), dz = _mm256_sub_ps(q1z, q0z);
        const __m256 a = dot8(dx, dy, dz, dx, dy, dz), b = dot8(q0x, q0y, q0z, dx, dy, dz);
        const __m256 graze_a = _mm256_mul_ps(bcast(qk.graze), a);
        const __m256 crossed = _mm256_and_ps(
            _mm256_and_ps(_mm256_andnot_ps(inside, _mm256_cmp_ps(q0sq, one, _CMP_GE_OQ)),
                          _mm256_and_ps(_mm256_cmp_ps(b, zero, _CMP_LT_OQ), _mm256_cmp_ps(a, zero, _CMP_GT_OQ))),
            _mm256_and_ps(_mm256_cmp_ps(_mm256_sub_ps(zero, b), a, _CMP_LE_OQ),
                          _mm256_cmp_ps(_mm256_sub_ps(_mm256_mul_ps(q0sq, a), _mm256_mul_ps(b, b)), graze_a,
                                        _CMP_LT_OQ)));
        hit = _mm256_or_ps(inside, crossed);
      }
      int contacts = lanes & _mm256_movemask_ps(hit);
      if (!contacts) continue;
      Lanes Q1X, Q1Y, Q1Z, R2, Q0X, Q0Y, Q0Z, Q0SQ;
      _mm256_store_ps(Q1X.v, q1x), _mm256_store_ps(Q1Y.v, q1y), _mm256_store_ps(Q1Z.v, q1z);
      _mm256_store_ps(R2.v, r2);
      _mm256_store_ps(Q0X.v, q0x), _mm256_store_ps(Q0Y.v, q0y), _mm256_store_ps(Q0Z.v, q0z);
      _mm256_store_ps(Q0SQ.v, q0sq);
      const int inside_bits = _mm256_movemask_ps(inside);
      if (p.response == ContactResponse::Exact && (contacts & inside_bits)) {
        const int done = exactContactsEight(k, contacts & inside_bits, Q1X.v, Q1Y.v, Q1Z.v, R2.v, Q0X.v, Q0Y.v,
                                            Q0Z.v, Q0SQ.v, X0.v, Y0.v, Z0.v, cont, friction, p, X.v, Y.v, Z.v, st);
        moved |= done;
        contacts &= ~done;
      }
      while (contacts) {
        const int j = __builtin_ctz(static_cast<unsigned>(contacts));
        contacts &= contacts - 1;
        Vec3 x(X.v[j], Y.v[j], Z.v[j]);
        contact(shapes_[static_cast<size_t>(k)], Vec4(Q1X.v[j], Q1Y.v[j], Q1Z.v[j], 0.0f), R2.v[j],
                Vec4(Q0X.v[j], Q0Y.v[j], Q0Z.v[j], 0.0f), Q0SQ.v[j], (inside_bits >> j) & 1, cont, friction,
                Vec3(X0.v[j], Y0.v[j], Z0.v[j]), p, x, st);
        X.v[j] = x.x(), Y.v[j] = x.y(), Z.v[j] = x.z();
        moved |= 1 << j;
      }
    }
    if (!moved) continue;
    // settle() for the lanes pass 0 moved: its first sequential pass on the eight lanes at once
    // where the joint candidates' cells cover a lane's position (then, narrowed to the lane's
    // groups, they are what settle would test: an ellipsoid whose box holds the point is in its
    // cell), in the same order with the same arithmetic; the rest one lane at a time.
    int together = 0;
    for (int bits = moved; bits; bits &= bits - 1) {
      const int j = __builtin_ctz(static_cast<unsigned>(bits));
      if (covers(c, Vec3(X.v[j], Y.v[j], Z.v[j]))) together |= 1 << j;
    }
    const int settled = together ? settleEight(ks, candidates, together, mixed ? lane_masks : 0, mixed, X.v, Y.v,
                                               Z.v, p, use_grid, begin, grouped, st)
                                 : 0;
    for (int bits = moved; bits; bits &= bits - 1) {
      const int j = __builtin_ctz(static_cast<unsigned>(bits));
      Vec3 x(X.v[j], Y.v[j], Z.v[j]);
      const size_t i = begin + static_cast<size_t>(j);
      if (!((settled >> j) & 1)) {
        const uint64_t* allowed = allowedFor(grouped, i);
        Candidates mine = c;
        if (mixed) {
          if (mine.all) {
            mine.allowed = allowed;
          } else {
            for (int w = 0; w < words_; ++w) mine.mask[w] &= allowed[w];
          }
        }
        settle(x, &mine, p, use_grid, allowed, st);
      }
      if (x != Vec3(positions[i].head<3>())) positions[i].head<3>() = x;
    }
  }
  return end;
}

// settle()'s first sequential pass for the lanes `lanes` of collideEights' block (their joint
// candidates ks[0..n) cover their positions): per candidate in order, the lanes allowed for it
// (lane_masks when the block's masks are mixed), the box test at the pass's start position, the
// inside test at the lane's current position (pass 0's unit-space arithmetic: mulq and a 4-lane
// squared norm); a lane inside is answered by respond(), one lane at a time (rare). Lanes that
// moved then finish as settle() does after its passes (firstContaining, escape). Returns `lanes`:
// every lane given is settled, x in xx/xy/xz.
__attribute__((target("avx"))) int EllipsoidCollider::settleEight(const int* ks, int n, int lanes, uint64_t lane_masks,
                                                                  bool mixed, float* xx, float* xy, float* xz,
                                                                  const CollisionParams& p, bool use_grid,
                                                                  size_t begin, bool grouped, CollisionStats& st) const {
  static_assert(kSequentialPasses == 2, "settleEight runs settle's one sequential pass");
  const __m256 XP = _mm256_load_ps(xx), YP = _mm256_load_ps(xy), ZP = _mm256_load_ps(xz);
  int moved = 0;
  for (int m = 0; m < n; ++m) {
    const int k = ks[m];
    const Quick& qk = quick_[static_cast<size_t>(k)];
    int on = lanes;
    if (mixed) {
      const uint64_t shared = lane_masks & (0x0101010101010101ull * groups_[static_cast<size_t>(k)]);
      const int none = _mm_movemask_epi8(_mm_cmpeq_epi8(_mm_cvtsi64_si128(static_cast<long long>(shared)),
                                                         _mm_setzero_si128())) & 0xFF;
      on &= ~none;
    }
    on &= _mm256_movemask_ps(boxes8(XP, YP, ZP, XP, YP, ZP, qk.end_min, qk.end_max));
    if (!on) continue;
    st.tests += static_cast<uint32_t>(__builtin_popcount(static_cast<unsigned>(on)));
    __m256 qx, qy, qz;
    unitSpace8(qk.end_u, qk.end_c, _mm256_load_ps(xx), _mm256_load_ps(xy), _mm256_load_ps(xz), qx, qy, qz);
    const __m256 r2 = dot8(qx, qy, qz, qx, qy, qz);
    int inside = on & _mm256_movemask_ps(_mm256_cmp_ps(r2, bcast(qk.inside_tol2), _CMP_LT_OQ));
    if (!inside) continue;
    Lanes QX, QY, QZ, R2;
    _mm256_store_ps(QX.v, qx), _mm256_store_ps(QY.v, qy), _mm256_store_ps(QZ.v, qz), _mm256_store_ps(R2.v, r2);
    for (; inside; inside &= inside - 1) {
      const int j = __builtin_ctz(static_cast<unsigned>(inside));
      Vec3 qc;
      const Vec3 x = respond(shapes_[static_cast<size_t>(k)], Vec3(xx[j], xy[j], xz[j]), Vec3(QX.v[j], QY.v[j], QZ.v[j]),
                             R2.v[j], p.response, qc);
      xx[j] = x.x(), xy[j] = x.y(), xz[j] = x.z();
      moved |= 1 << j;
    }
  }
  for (; moved; moved &= moved - 1) {
    const int j = __builtin_ctz(static_cast<unsigned>(moved));
    Vec3 x(xx[j], xy[j], xz[j]);
    settle(x, nullptr, p, use_grid, allowedFor(grouped, begin + static_cast<size_t>(j)), st, kSequentialPasses);
    xx[j] = x.x(), xy[j] = x.y(), xz[j] = x.z();
  }
  return lanes;
}

// contact() for inside lanes with the Exact response, eight at once (exactContactsEight in
// collision.h): closestInsideFloat's Newton iteration, respond's target, contact's deep-contact
// cone test and applyFriction, each lane with the scalar code's operations in its order (Eigen's
// 4-lane sums as (x + z) + (y + w), its 3-vector sums as x + (y + z), no FMA). A lane whose
// iteration does not converge in float, or whose cone test fails, is left to contact().
__attribute__((target("avx"))) int EllipsoidCollider::exactContactsEight(
    int k, int lanes, const float* q1x, const float* q1y, const float* q1z, const float* r2p, const float* q0x,
    const float* q0y, const float* q0z, const float* q0sqp, const float* x0x, const float* x0y, const float* x0z,
    bool cont, bool friction, const CollisionParams& p, float* xx, float* xy, float* xz, CollisionStats& st) const {
  const Shape& s = shapes_[static_cast<size_t>(k)];
  const Quick& qk = quick_[static_cast<size_t>(k)];
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
  const __m256 Q1[3] = {_mm256_load_ps(q1x), _mm256_load_ps(q1y), _mm256_load_ps(q1z)};
  const __m256 R2 = _mm256_load_ps(r2p);
  // closestInsideFloat(b = radii^2, e = sqrt(b), q, r2), b's and q's w lanes 0.
  const float b[3] = {qk.radii2.x(), qk.radii2.y(), qk.radii2.z()};
  const float e[3] = {qk.radii2_sqrt.x(), qk.radii2_sqrt.y(), qk.radii2_sqrt.z()};
  const __m256 act = _mm256_and_ps(laneMask8(lanes), _mm256_cmp_ps(R2, _mm256_set1_ps(0.64f), _CMP_GE_OQ));
  if (_mm256_movemask_ps(act) == 0) return 0;
  __m256 Y[3], A[3], B[3];
  for (int i = 0; i < 3; ++i) {
    B[i] = bcast(b[i]);
    Y[i] = _mm256_mul_ps(bcast(e[i]), Q1[i]);
    A[i] = _mm256_mul_ps(Y[i], bcast(e[i]));
  }
  const float b_min = std::min(std::min(b[0], b[1]), b[2]);
  const bool w_free = b_min < 1.0f;
  __m256 lo = bcast(-b_min), hi = zero, t = zero;
  __m256 F = _mm256_sub_ps(R2, one);
  // -2 sum(q^2 / (b + (0, 0, 0, 1))): lanes (x + z) + (y + w), w = 0 / 1.
  __m256 T[3];
  for (int i = 0; i < 3; ++i) T[i] = _mm256_div_ps(_mm256_mul_ps(Q1[i], Q1[i]), _mm256_add_ps(B[i], zero));
  const __m256 T3 = _mm256_div_ps(_mm256_mul_ps(zero, zero), _mm256_add_ps(zero, one));
  __m256 dF = _mm256_mul_ps(_mm256_set1_ps(-2.0f),
                            _mm256_add_ps(_mm256_add_ps(T[0], T[2]), _mm256_add_ps(T[1], T3)));
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7FFFFFFF));
  __m256 conv = zero, L[3] = {zero, zero, zero}, QC[3] = {zero, zero, zero};
  for (int it = 0; it < 8; ++it) {
    const __m256 live = _mm256_andnot_ps(conv, act);
    if (_mm256_movemask_ps(live) == 0) break;
    const __m256 fneg = _mm256_cmp_ps(F, zero, _CMP_LT_OQ);
    hi = select8(_mm256_and_ps(live, fneg), t, hi);
    lo = select8(_mm256_andnot_ps(fneg, live), t, lo);
    __m256 tn = select8(_mm256_cmp_ps(dF, zero, _CMP_LT_OQ), _mm256_sub_ps(t, _mm256_div_ps(F, dF)), lo);
    const __m256 inside = _mm256_and_ps(_mm256_cmp_ps(tn, lo, _CMP_GT_OQ), _mm256_cmp_ps(tn, hi, _CMP_LT_OQ));
    tn = select8(inside, tn, _mm256_mul_ps(_mm256_set1_ps(0.5f), _mm256_add_ps(lo, hi)));
    t = select8(live, tn, t);
    __m256 r[3], u[3];
    for (int i = 0; i < 3; ++i) {
      r[i] = _mm256_div_ps(one, _mm256_add_ps(_mm256_add_ps(B[i], t), zero));
      u[i] = _mm256_mul_ps(A[i], r[i]);
    }
    // The w lane: a_w = 0, so u_w = 0 / (t + 1) adds exactly nothing while t > -1, which holds
    // when every b_i < 1 (t stays above -min b): only larger ellipsoids pay for that division.
    const __m256 r3 = w_free ? one : _mm256_div_ps(one, _mm256_add_ps(_mm256_add_ps(zero, t), one));
    const __m256 u3 = _mm256_mul_ps(zero, r3);
    const __m256 uu[4] = {_mm256_mul_ps(u[0], u[0]), _mm256_mul_ps(u[1], u[1]), _mm256_mul_ps(u[2], u[2]),
                          _mm256_mul_ps(u3, u3)};
    const __m256 Fn =
        _mm256_sub_ps(_mm256_add_ps(_mm256_add_ps(uu[0], uu[2]), _mm256_add_ps(uu[1], uu[3])), one);
    const __m256 newly =
        _mm256_and_ps(live, _mm256_cmp_ps(_mm256_and_ps(Fn, abs_mask), _mm256_set1_ps(2e-6f), _CMP_LT_OQ));
    for (int i = 0; i < 3; ++i) {
      L[i] = select8(newly, _mm256_mul_ps(_mm256_mul_ps(B[i], Y[i]), r[i]), L[i]);
      QC[i] = select8(newly, _mm256_mul_ps(_mm256_mul_ps(Y[i], r[i]), bcast(e[i])), QC[i]);
    }
    conv = _mm256_or_ps(conv, newly);
    F = select8(live, Fn, F);
    const __m256 v[4] = {_mm256_mul_ps(uu[0], r[0]), _mm256_mul_ps(uu[1], r[1]), _mm256_mul_ps(uu[2], r[2]),
                         _mm256_mul_ps(uu[3], r3)};
    const __m256 dFn = _mm256_mul_ps(_mm256_set1_ps(-2.0f),
                                     _mm256_add_ps(_mm256_add_ps(v[0], v[2]), _mm256_add_ps(v[1], v[3])));
    dF = select8(live, dFn, dF);
  }
  __m256 done = conv;
  // contact(): a start outside (q0sq >= inside_tol2) with the swept test and the response far
  // round the sphere from the path may need the entry point: left to contact().
  if (cont) {
    const __m256 Q0[3] = {_mm256_load_ps(q0x), _mm256_load_ps(q0y), _mm256_load_ps(q0z)};
    const __m256 Q0SQ = _mm256_load_ps(q0sqp);
    const __m256 d0 = sum3(_mm256_mul_ps(QC[0], Q0[0]), _mm256_mul_ps(QC[1], Q0[1]), _mm256_mul_ps(QC[2], Q0[2]));
    const __m256 d1 = sum3(_mm256_mul_ps(QC[0], Q1[0]), _mm256_mul_ps(QC[1], Q1[1]), _mm256_mul_ps(QC[2], Q1[2]));
    constexpr float kCos2 = kDeepContactCos * kDeepContactCos;
    const __m256 cos2 = bcast(kCos2);
    const __m256 in_cone = _mm256_and_ps(
        _mm256_and_ps(_mm256_cmp_ps(d0, zero, _CMP_GE_OQ), _mm256_cmp_ps(d1, zero, _CMP_GE_OQ)),
        _mm256_and_ps(_mm256_cmp_ps(_mm256_mul_ps(d0, d0), _mm256_mul_ps(cos2, Q0SQ), _CMP_GE_OQ),
                      _mm256_cmp_ps(_mm256_mul_ps(d1, d1), _mm256_mul_ps(cos2, R2), _CMP_GE_OQ)));
    const __m256 check = _mm256_cmp_ps(Q0SQ, bcast(s.inside_tol2), _CMP_GE_OQ);
    done = _mm256_andnot_ps(_mm256_andnot_ps(in_cone, check), done);
  }
  const int done_bits = _mm256_movemask_ps(done);
  if (done_bits == 0) return 0;
  // respond(): centre + rotation * local.
  const Mat3& R = s.rotation;
  const Vec3& c = s.end.centre;
  __m256 X[3];
  for (int i = 0; i < 3; ++i)
    X[i] = _mm256_add_ps(bcast(c[i]), row3(R(i, 0), R(i, 1), R(i, 2), L[0], L[1], L[2]));
  if (friction) {
    // applyFriction(s.end.to_unit, s.end.centre, s.end.from_unit, s.start.centre,
    // s.start.from_unit, qc, before, x0, mu_s, mu_k, x).
    const __m256 before[3] = {_mm256_load_ps(xx), _mm256_load_ps(xy), _mm256_load_ps(xz)};
    const __m256 X0[3] = {_mm256_load_ps(x0x), _mm256_load_ps(x0y), _mm256_load_ps(x0z)};
    const Mat3& Tu = s.end.to_unit;
    const Mat3& Fe = s.end.from_unit;
    const Mat3& Fs = s.start.from_unit;
    const Vec3& cs = s.start.centre;
    __m256 n[3], rel[3];
    for (int i = 0; i < 3; ++i) {
      n[i] = col3(Tu(0, i), Tu(1, i), Tu(2, i), QC[0], QC[1], QC[2]);
      const __m256 me = _mm256_add_ps(bcast(c[i]), row3(Fe(i, 0), Fe(i, 1), Fe(i, 2), QC[0], QC[1], QC[2]));
      const __m256 ms = _mm256_add_ps(bcast(cs[i]), row3(Fs(i, 0), Fs(i, 1), Fs(i, 2), QC[0], QC[1], QC[2]));
      rel[i] = _mm256_sub_ps(_mm256_sub_ps(X[i], X0[i]), _mm256_sub_ps(me, ms));
    }
    const __m256 nn = sum3(_mm256_mul_ps(n[0], n[0]), _mm256_mul_ps(n[1], n[1]), _mm256_mul_ps(n[2], n[2]));
    const __m256 rd = sum3(_mm256_mul_ps(rel[0], n[0]), _mm256_mul_ps(rel[1], n[1]), _mm256_mul_ps(rel[2], n[2]));
    const __m256 sc = _mm256_div_ps(rd, nn);
    __m256 tg[3], dd[3];
    for (int i = 0; i < 3; ++i) {
      tg[i] = _mm256_sub_ps(rel[i], _mm256_mul_ps(sc, n[i]));
      dd[i] = _mm256_sub_ps(X[i], before[i]);
    }
    const __m256 slip2 = sum3(_mm256_mul_ps(tg[0], tg[0]), _mm256_mul_ps(tg[1], tg[1]), _mm256_mul_ps(tg[2], tg[2]));
    const __m256 depth2 = sum3(_mm256_mul_ps(dd[0], dd[0]), _mm256_mul_ps(dd[1], dd[1]), _mm256_mul_ps(dd[2], dd[2]));
    const float mu_s = p.static_friction, mu_k = p.kinetic_friction;
    const __m256 kin_raw = _mm256_mul_ps(bcast(mu_k), _mm256_sqrt_ps(_mm256_div_ps(depth2, slip2)));
    const __m256 kin = select8(_mm256_cmp_ps(one, kin_raw, _CMP_LT_OQ), one, kin_raw);  // std::min(kin_raw, 1)
    const __m256 kinetic = select8(_mm256_cmp_ps(slip2, zero, _CMP_GT_OQ), kin, zero);
    const __m256 f = select8(_mm256_cmp_ps(slip2, _mm256_mul_ps(bcast(mu_s * mu_s), depth2), _CMP_LT_OQ), one, kinetic);
    const __m256 acts = _mm256_cmp_ps(nn, zero, _CMP_GT_OQ);  // !(nn > 0): no friction
    for (int i = 0; i < 3; ++i) X[i] = select8(acts, _mm256_sub_ps(X[i], _mm256_mul_ps(f, tg[i])), X[i]);
  }
  float* out[3] = {xx, xy, xz};
  for (int i = 0; i < 3; ++i) _mm256_store_ps(out[i], select8(done, X[i], _mm256_load_ps(out[i])));
  st.contacts += static_cast<uint32_t>(__builtin_popcount(static_cast<unsigned>(done_bits)));
  return done_bits;
}
#else
size_t EllipsoidCollider::collideEights(Eigen::Vector4f*, const Eigen::Vector4f*, size_t, const CollisionParams&,
                                        bool, CollisionStats&) const {
  return 0;
}
int EllipsoidCollider::settleEight(const int*, int, int, uint64_t, bool, float*, float*, float*,
                                   const CollisionParams&, bool, size_t, bool, CollisionStats&) const {
  return 0;
}
int EllipsoidCollider::exactContactsEight(int, int, const float*, const float*, const float*, const float*,
                                          const float*, const float*, const float*, const float*, const float*,
                                          const float*, const float*, bool, bool, const CollisionParams&, float*,
                                          float*, float*, CollisionStats&) const {
  return 0;
}
#endif

}  // namespace drape
