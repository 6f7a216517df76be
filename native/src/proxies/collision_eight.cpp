// CollisionParams::batch8: pass 0 of the collider for eight consecutive particles at once (AVX,
// chosen at run time). docs/collision.md, "Eight particles at once". The contacts it finds are
// answered eight lanes at once too (collision_eight_contacts.cpp).
#include "proxies/collision_avx.h"
#include "proxies/collision_internal.h"

#include "common/cpu.h"

#include <cstring>
#include <limits>

namespace drape {
using namespace collision_internal;

#if DRAPE_COLLISION_AVX
using namespace collision_avx;
namespace {
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
}  // namespace

// Pass 0 of resolveParticle for 8 particles, lane by lane the same arithmetic in the same order
// (Eigen's 4-lane sums are (x + z) + y with w = 0, reproduced below; no FMA), so every particle
// meets the same tests with the same values and gets the same contacts: bit-identical results.
// What it saves is per-particle overhead: one grid gather for the 8 particles' joint box instead
// of 8, and one box test and narrow test per candidate for 8 particles. The contacts found (about
// one in seven narrow tests) and the later pass run eight lanes at once as well where they can
// (collision_eight_contacts.cpp); the rest (swept catches, the Radial response, lanes whose float
// closest point fails, escapes) one particle at a time.
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
      if (mixed) lanes &= lanesSharing(lane_masks, groups_[static_cast<size_t>(k)]);
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
    if (together)
      settleEight(ks, candidates, together, mixed ? lane_masks : 0, mixed, X.v, Y.v, Z.v, p, use_grid, begin,
                  grouped, st);
    for (int bits = moved; bits; bits &= bits - 1) {
      const int j = __builtin_ctz(static_cast<unsigned>(bits));
      Vec3 x(X.v[j], Y.v[j], Z.v[j]);
      const size_t i = begin + static_cast<size_t>(j);
      if (!((together >> j) & 1)) {
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

#else
size_t EllipsoidCollider::collideEights(Eigen::Vector4f*, const Eigen::Vector4f*, size_t, const CollisionParams&,
                                        bool, CollisionStats&) const {
  return 0;
}
#endif

}  // namespace drape
