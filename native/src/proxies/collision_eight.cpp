// CollisionParams::batch8: pass 0 of the collider for eight consecutive particles at once (AVX,
// chosen at run time). docs/collision.md, "Eight particles at once".
#include "proxies/collision_internal.h"

#include "common/cpu.h"

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
__attribute__((target("avx"))) bool EllipsoidCollider::collideEight(Eigen::Vector4f* positions,
                                                                     const Eigen::Vector4f* previous,
                                                                     size_t begin, const CollisionParams& p,
                                                                     bool grouped, CollisionStats& st) const {
  // More ellipsoids than the grid takes (broad phase off): one particle at a time.
  if (!cpuHasAvx() || shapes_.size() > static_cast<size_t>(kMaxGridEllipsoids)) return false;
  // Every lane that takes part has a finite start position when `previous` is given (the others
  // go the one-particle way), so the swept test and friction are the same for all of them.
  const bool cont = p.continuous && previous != nullptr;
  const bool friction = previous != nullptr && (p.static_friction > 0.0f || p.kinetic_friction > 0.0f);
  const bool use_grid = p.broad_phase && grid_;
  Lanes X, Y, Z, X0, Y0, Z0, LOX, LOY, LOZ, HIX, HIY, HIZ;
  const uint64_t* allowed[8];
  Vec3 start[8];
  int active = 0;  // bit j: lane j takes part in the batched pass 0
  uint64_t joint_allowed[kMaxGridEllipsoids / 64] = {};
  // Lane j's collision mask in byte j: lane j may touch ellipsoid k when its byte shares a bit
  // with groups_[k] (what allowed_ tabulates, setGroups), so one AND and one byte compare give
  // the lanes allowed for k. Lanes not taking part keep 0.
  uint64_t lane_masks = 0;
  Vec3 lo = Vec3::Constant(std::numeric_limits<float>::infinity()), hi = -lo;
  for (int j = 0; j < 8; ++j) {
    const size_t i = begin + static_cast<size_t>(j);
    if (!mayTouch(positions, previous, i, cont)) continue;  // as collide()'s particle loop
    const Vec3 x = positions[i].head<3>();
    allowed[j] = grouped ? &allowed_[static_cast<size_t>(particle_masks_[i]) * (kMaxGridEllipsoids / 64)] : nullptr;
    const Vec3 x0 = previous ? Vec3(previous[i].head<3>()) : x;
    if (previous && !isFinite(x0)) {  // no start position: the one-particle path
      Vec3 y = x;
      resolveParticle(y, x, false, p, allowed[j], st);
      if (y != x) positions[i].head<3>() = y;
      continue;
    }
    active |= 1 << j;
    start[j] = x0;
    X.v[j] = x.x(), Y.v[j] = x.y(), Z.v[j] = x.z();
    X0.v[j] = x0.x(), Y0.v[j] = x0.y(), Z0.v[j] = x0.z();
    const Vec3 l = cont ? x.cwiseMin(x0) : x, h = cont ? x.cwiseMax(x0) : x;
    LOX.v[j] = l.x(), LOY.v[j] = l.y(), LOZ.v[j] = l.z();
    HIX.v[j] = h.x(), HIY.v[j] = h.y(), HIZ.v[j] = h.z();
    lo = lo.cwiseMin(l);
    hi = hi.cwiseMax(h);
    if (allowed[j]) {
      for (int w = 0; w < words_; ++w) joint_allowed[w] |= allowed[j][w];
      lane_masks |= static_cast<uint64_t>(particle_masks_[i]) << (8 * j);
    }
  }
  Candidates c;
  if (active == 0 || !gather(lo, hi, use_grid, grouped ? joint_allowed : nullptr, c)) return true;
  const __m256 lox = _mm256_load_ps(LOX.v), loy = _mm256_load_ps(LOY.v), loz = _mm256_load_ps(LOZ.v);
  const __m256 hix = _mm256_load_ps(HIX.v), hiy = _mm256_load_ps(HIY.v), hiz = _mm256_load_ps(HIZ.v);
  const __m256 x0x = _mm256_load_ps(X0.v), x0y = _mm256_load_ps(Y0.v), x0z = _mm256_load_ps(Z0.v);
  const __m256 one = _mm256_set1_ps(1.0f), zero = _mm256_setzero_ps();
  int moved = 0;
  int ks[kMaxGridEllipsoids];
  int candidates = 0;
  iterate(c, [&](int k) { ks[candidates++] = k; });
  for (int n = 0; n < candidates; ++n) {
    const int k = ks[n];
    const Quick& qk = quick_[static_cast<size_t>(k)];
    int lanes = active;
    if (grouped) {
      const uint64_t shared = lane_masks & (0x0101010101010101ull * groups_[static_cast<size_t>(k)]);
      const int none = _mm_movemask_epi8(_mm_cmpeq_epi8(_mm_cvtsi64_si128(static_cast<long long>(shared)),
                                                         _mm_setzero_si128())) & 0xFF;
      lanes &= ~none;
    }
    const __m256 px = _mm256_load_ps(X.v), py = _mm256_load_ps(Y.v), pz = _mm256_load_ps(Z.v);
    // The swept box (fixed per particle) against the ellipsoid's swept box, or the end position
    // as pass 0 saw it (lo = hi = x then) in the end box.
    const __m256 in_box = cont ? boxes8(lox, loy, loz, hix, hiy, hiz, qk.swept_min, qk.swept_max)
                               : boxes8(lox, loy, loz, hix, hiy, hiz, qk.end_min, qk.end_max);
    lanes &= _mm256_movemask_ps(in_box);
    if (!lanes) continue;
    st.tests += static_cast<uint32_t>(__builtin_popcount(static_cast<unsigned>(lanes)));
    __m256 q1x, q1y, q1z;
    unitSpace8(qk.end_u, qk.end_c, px, py, pz, q1x, q1y, q1z);
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
    while (contacts) {
      const int j = __builtin_ctz(static_cast<unsigned>(contacts));
      contacts &= contacts - 1;
      Vec3 x(X.v[j], Y.v[j], Z.v[j]);
      contact(shapes_[static_cast<size_t>(k)], Vec4(Q1X.v[j], Q1Y.v[j], Q1Z.v[j], 0.0f), R2.v[j],
              Vec4(Q0X.v[j], Q0Y.v[j], Q0Z.v[j], 0.0f), Q0SQ.v[j], (inside_bits >> j) & 1, cont, friction,
              start[j], p, x, st);
      X.v[j] = x.x(), Y.v[j] = x.y(), Z.v[j] = x.z();
      moved |= 1 << j;
    }
  }
  for (int j = 0; j < 8; ++j) {
    if (!((moved >> j) & 1)) continue;
    Vec3 x(X.v[j], Y.v[j], Z.v[j]);
    // The joint candidates narrowed to this lane's groups: where they cover x, settle tests the
    // same ellipsoids in the same order as after a gather of its own (collision.cpp, settle).
    Candidates mine = c;
    if (grouped) {
      if (mine.all) {
        mine.allowed = allowed[j];
      } else {
        for (int w = 0; w < words_; ++w) mine.mask[w] &= allowed[j][w];
      }
    }
    settle(x, &mine, p, use_grid, allowed[j], st);
    const size_t i = begin + static_cast<size_t>(j);
    if (x != Vec3(positions[i].head<3>())) positions[i].head<3>() = x;
  }
  return true;
}
#else
bool EllipsoidCollider::collideEight(Eigen::Vector4f*, const Eigen::Vector4f*, size_t, const CollisionParams&,
                                     bool, CollisionStats&) const {
  return false;
}
#endif

}  // namespace drape
