// The contacts of the eight-lane pass 0 (collision_eight.cpp), eight lanes at once: the exact
// response with friction, and settle's sequential pass. docs/collision.md, "Contacts eight at once".
#include "proxies/collision_avx.h"
#include "proxies/collision_internal.h"

#include "common/cpu.h"

#include <algorithm>

namespace drape {
using namespace collision_internal;

#if DRAPE_COLLISION_AVX
using namespace collision_avx;

// settle()'s first sequential pass for the lanes `lanes` of collideEights' block (their joint
// candidates ks[0..n) cover their positions): per candidate in order, the lanes allowed for it
// (lane_masks when the block's masks are mixed), the box test at the pass's start position, the
// inside test at the lane's current position (pass 0's unit-space arithmetic: mulq and a 4-lane
// squared norm); a lane inside is answered by respond(), one lane at a time (rare). Lanes that
// moved then finish as settle() does after its passes (escapeIfInside). x in xx/xy/xz.
__attribute__((target("avx"))) void EllipsoidCollider::settleEight(const int* ks, int n, int lanes, uint64_t lane_masks,
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
    if (mixed) on &= lanesSharing(lane_masks, groups_[static_cast<size_t>(k)]);
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
    escapeIfInside(x, p, use_grid, allowedFor(grouped, begin + static_cast<size_t>(j)), st);
    xx[j] = x.x(), xy[j] = x.y(), xz[j] = x.z();
  }
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
  // -2 sum(q^2 / (b + (0, 0, 0, 1))): lanes (x + z) + (y + w). The w term is 0 / 1 = +0, and
  // adding +0 (here and below, where the scalar code adds b's w lane 0) changes no value these
  // sums can take (b > 0, b + t > 0, squares >= 0): it is left out.
  __m256 T[3];
  for (int i = 0; i < 3; ++i) T[i] = _mm256_div_ps(_mm256_mul_ps(Q1[i], Q1[i]), B[i]);
  __m256 dF = _mm256_mul_ps(_mm256_set1_ps(-2.0f), _mm256_add_ps(_mm256_add_ps(T[0], T[2]), T[1]));
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
      r[i] = _mm256_div_ps(one, _mm256_add_ps(B[i], t));
      u[i] = _mm256_mul_ps(A[i], r[i]);
    }
    // The w lane: a_w = 0, so u_w = 0 / (t + 1) adds exactly nothing while t > -1, which holds
    // when every b_i < 1 (t stays above -min b): only larger ellipsoids pay for that division.
    const __m256 r3 = w_free ? one : _mm256_div_ps(one, _mm256_add_ps(t, one));
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
void EllipsoidCollider::settleEight(const int*, int, int, uint64_t, bool, float*, float*, float*,
                                    const CollisionParams&, bool, size_t, bool, CollisionStats&) const {}
int EllipsoidCollider::exactContactsEight(int, int, const float*, const float*, const float*, const float*,
                                          const float*, const float*, const float*, const float*, const float*,
                                          const float*, const float*, bool, bool, const CollisionParams&, float*,
                                          float*, float*, CollisionStats&) const {
  return 0;
}
#endif

}  // namespace drape
