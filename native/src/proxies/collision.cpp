#include "proxies/collision.h"

#include "proxies/closest_point.h"

#include <algorithm>
#include <cmath>
#include <limits>

#if defined(_MSC_VER)
#include <intrin.h>
#endif
#if defined(__SSE2__) || defined(_M_X64)
#include <emmintrin.h>
#endif
#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
#include <immintrin.h>
#endif

namespace drape {
namespace {

inline int lowestBit(uint64_t m) {
#if defined(_MSC_VER)
  unsigned long index = 0;
  _BitScanForward64(&index, m);
  return static_cast<int>(index);
#else
  return __builtin_ctzll(m);
#endif
}

// 3x3 times 3-vector written out: GCC does not always inline Eigen's small products.
inline Vec3 mulv(const Mat3& m, const Vec3& v) {
  return m.col(0) * v.x() + m.col(1) * v.y() + m.col(2) * v.z();
}
inline Vec3 mulvT(const Mat3& m, const Vec3& v) {  // m^T v
  return Vec3(m.col(0).dot(v), m.col(1).dot(v), m.col(2).dot(v));
}

// Box tests with & rather than &&: no branch per comparison (random particle data mispredicts).
inline bool containsPoint(const Vec3& mn, const Vec3& mx, const Vec3& p) {
  return (p.x() >= mn.x()) & (p.x() <= mx.x()) & (p.y() >= mn.y()) & (p.y() <= mx.y()) &
         (p.z() >= mn.z()) & (p.z() <= mx.z());
}

inline bool overlaps(const Vec3& lo, const Vec3& hi, const Vec3& mn, const Vec3& mx) {
  return (lo.x() <= mx.x()) & (hi.x() >= mn.x()) & (lo.y() <= mx.y()) & (hi.y() >= mn.y()) &
         (lo.z() <= mx.z()) & (hi.z() >= mn.z());
}

// Cell coordinates of a point (4-wide: the w lane is ignored), clamped to the grid. Monotone in
// each coordinate, so a point inside two boxes lies in a cell both boxes' cell ranges include.
inline Eigen::Array4i cellsOf(const Vec3& p, const Eigen::Array4f& origin, const Eigen::Array4f& scale,
                              const Eigen::Array4f& top) {
  const Eigen::Array4f v(p.x(), p.y(), p.z(), 0.0f);
  return ((v - origin) * scale).max(Eigen::Array4f::Zero()).min(top).cast<int>();
}

// Positional Coulomb friction against the moving surface (Macklin et al. 2014, §6.1). qc is the
// contact's unit-space coordinate; the surface point under the particle moved from E_start(qc)
// to E_end(qc) during the substep. Written with squared lengths: one square root in the
// kinetic case, none in the static one.
inline void applyFriction(const Mat3& to_unit_end, const Vec3& c_end, const Mat3& from_end,
                          const Vec3& c_start, const Mat3& from_start, const Vec3& qc,
                          const Vec3& before, const Vec3& x0, float mu_s, float mu_k, Vec3& x) {
  const Vec3 n = mulvT(to_unit_end, qc);  // outward normal (unnormalised): gradient of |q|^2/2
  const float nn = n.squaredNorm();
  if (!(nn > 0.0f)) return;
  const Vec3 surface_move = (c_end + mulv(from_end, qc)) - (c_start + mulv(from_start, qc));
  const Vec3 rel = (x - x0) - surface_move;
  const Vec3 tangential = rel - (rel.dot(n) / nn) * n;
  const float slip2 = tangential.squaredNorm();
  const float depth2 = (x - before).squaredNorm();
  // Static (slip below mu_s * depth): remove all slip, the particle rides with the surface.
  // Kinetic: remove mu_k * depth of it. Selected without a branch.
  const float kinetic = slip2 > 0.0f ? std::min(mu_k * std::sqrt(depth2 / slip2), 1.0f) : 0.0f;
  const float f = slip2 < mu_s * mu_s * depth2 ? 1.0f : kinetic;
  x -= f * tangential;
}

using Vec4 = Eigen::Vector4f;
// xyz0 built in registers: going through a 12-byte store and a 16-byte load stalls on store
// forwarding (it cost more than the narrow test itself).
#if defined(__SSE2__) || defined(_M_X64)
inline Vec4 lift(const Vec3& v) {
  const __m128 xy = _mm_unpacklo_ps(_mm_set_ss(v.x()), _mm_set_ss(v.y()));
  Vec4 out;
  _mm_store_ps(out.data(), _mm_movelh_ps(xy, _mm_set_ss(v.z())));
  return out;
}
#else
inline Vec4 lift(const Vec3& v) { return Vec4(v.x(), v.y(), v.z(), 0.0f); }
#endif
// q = U d for U given by its columns (w lanes 0).
inline Vec4 mulq(const Vec4* u, const Vec4& d) {
  return u[0] * d.x() + u[1] * d.y() + u[2] * d.z();
}
// Box tests on 4 lanes (w lanes are 0 on both sides, so they always pass), one branch.
#if defined(__SSE2__) || defined(_M_X64)
inline bool overlaps4(const Vec4& lo, const Vec4& hi, const Vec4& mn, const Vec4& mx) {
  const __m128 in = _mm_and_ps(_mm_cmple_ps(_mm_load_ps(lo.data()), _mm_load_ps(mx.data())),
                               _mm_cmpge_ps(_mm_load_ps(hi.data()), _mm_load_ps(mn.data())));
  return _mm_movemask_ps(in) == 0xF;
}
inline bool contains4(const Vec4& mn, const Vec4& mx, const Vec4& p) {
  return overlaps4(p, p, mn, mx);
}
#else
inline bool overlaps4(const Vec4& lo, const Vec4& hi, const Vec4& mn, const Vec4& mx) {
  return ((lo.array() <= mx.array()).cast<int>() * (hi.array() >= mn.array()).cast<int>()).sum() == 4;
}
inline bool contains4(const Vec4& mn, const Vec4& mx, const Vec4& p) {
  return overlaps4(p, p, mn, mx);
}
#endif

// Closest point on an ellipsoid (radii^2 b, local frame) to the local point y = e * q inside it
// near its surface (|q|^2 = r2 >= 0.64), in float: x_i = b_i y_i / (b_i + t) with t the root of
// F(t) = sum (e_i y_i / (b_i + t))^2 - 1 in (-b_min, 0] (F convex and decreasing there), by
// Newton steps kept inside the bracket (bisection otherwise). The first step is at t = 0, where
// F = r2 - 1 and F' = -2 sum q_i^2 / b_i need no division. A resting contact (|q| ~ 0.999)
// converges in one or two steps. False when it does not converge in 8 steps (near the medial
// surface of a flat ellipsoid, or deeper points): the caller then uses the double solver.
inline bool closestInsideFloat(const Vec4& b, const Vec4& q, float r2, Vec3& local, Vec3& qc) {
  if (!(r2 >= 0.64f)) return false;
  const Vec4 e = b.cwiseSqrt();
  const Vec4 y = e.cwiseProduct(q);  // local point
  const Vec4 a = y.cwiseProduct(e);  // e_i y_i
  float lo = -b.head<3>().minCoeff(), hi = 0.0f, t = 0.0f;
  float F = r2 - 1.0f;
  float dF = -2.0f * (q.array().square() / (b.array() + Eigen::Array4f(0, 0, 0, 1))).sum();
  Eigen::Array4f r = Eigen::Array4f::Zero();
  for (int it = 0; it < 8; ++it) {
    if (F < 0.0f) hi = t; else lo = t;
    float tn = dF < 0.0f ? t - F / dF : lo;
    if (!(tn > lo && tn < hi)) tn = 0.5f * (lo + hi);
    t = tn;
    r = (b.array() + t + Eigen::Array4f(0, 0, 0, 1)).inverse();
    const Eigen::Array4f u = a.array() * r;
    F = (u * u).sum() - 1.0f;
    if (std::fabs(F) < 2e-6f) {
      const Eigen::Array4f x = b.array() * y.array() * r;
      local = Vec3(x[0], x[1], x[2]);
      const Eigen::Array4f qq = y.array() * r * e.array();  // x / e
      qc = Vec3(qq[0], qq[1], qq[2]);
      return true;
    }
    dF = -2.0f * (u * u * r).sum();
  }
  return false;
}

// A swept contact is answered at the entry point when the discrete response would land more
// than 45 degrees (round the unit sphere) away from it.
constexpr float kDeepContactCos = 0.70710678f;

// Where the unit-space segment q0 -> q1 (q0 outside or on the sphere) first meets the unit
// sphere, normalised onto it.
inline Vec3 entryPoint(const Vec3& q0, float q0sq, const Vec3& q1) {
  const Vec3 d = q1 - q0;
  const float a = d.squaredNorm(), b = q0.dot(d), c0 = q0sq - 1.0f;
  float t = 0.0f;
  if (c0 > 0.0f && a > 0.0f) {
    const float den = -b + std::sqrt(std::max(b * b - a * c0, 0.0f));
    t = den > 0.0f ? std::min(c0 / den, 1.0f) : 0.0f;
  }
  const Vec3 qe = q0 + t * d;
  const float len = qe.norm();
  return len > 0.0f ? Vec3(qe / len) : Vec3(q0);
}

}  // namespace

Ellipsoid interpolateEllipsoid(const Ellipsoid& a, const Ellipsoid& b, float t) {
  Ellipsoid e;
  e.centre = a.centre + t * (b.centre - a.centre);
  e.radii = a.radii + t * (b.radii - a.radii);
  Quat qa(a.rotation), qb(b.rotation);
  qa.normalize();
  qb.normalize();
  e.rotation = qa.slerp(t, qb).toRotationMatrix();
  e.refresh();
  return e;
}

Ellipsoid EllipsoidCollider::inflatedEnd(int i) const {
  Ellipsoid e;
  if (i < 0 || i >= count()) return e;
  const Shape& s = shapes_[static_cast<size_t>(i)];
  e.centre = s.end.centre;
  e.rotation = s.rotation;
  e.radii = s.radii;
  e.refresh();
  return e;
}

void EllipsoidCollider::setEllipsoids(const Ellipsoid* start, const Ellipsoid* end, int count,
                                      float margin_m) {
  grid_ = false;
  if (!start || !end || count <= 0) {
    shapes_.clear();
    return;
  }
  margin_ = (margin_m >= 0.0f && std::isfinite(margin_m)) ? margin_m : 0.0f;
  shapes_.resize(static_cast<size_t>(count));
  quick_.resize(static_cast<size_t>(count));
  constexpr float kInf = std::numeric_limits<float>::infinity();
  grid_min_ = Vec3::Constant(kInf);
  grid_max_ = Vec3::Constant(-kInf);
  bool any = false;

  auto build = [this](const Ellipsoid& e, Frame& f, Vec3& radii, Vec3& mn, Vec3& mx) {
    for (int i = 0; i < 3; ++i) radii[i] = std::max(e.radii[i] + margin_, 1e-6f);
    f.centre = e.centre;
    f.to_unit = radii.cwiseInverse().asDiagonal() * e.rotation.transpose();
    f.from_unit = e.rotation * radii.asDiagonal();
    const Vec3 half = f.from_unit.rowwise().norm();
    mn = e.centre - half;
    mx = e.centre + half;
    return isFinite(mn) && isFinite(mx) && isFinite(f.to_unit.rowwise().sum());
  };

  for (int k = 0; k < count; ++k) {
    Shape& s = shapes_[static_cast<size_t>(k)];
    Vec3 start_radii, start_min, start_max;
    const bool ok = build(end[k], s.end, s.radii, s.end_min, s.end_max) &&
                    build(start[k], s.start, start_radii, start_min, start_max);
    s.rotation = end[k].rotation;
    if (!ok) {  // never matches: empty boxes
      s.end_min = s.swept_min = Vec3::Constant(kInf);
      s.end_max = s.swept_max = Vec3::Constant(-kInf);
      refreshQuick(k);
      continue;
    }
    s.swept_min = s.end_min.cwiseMin(start_min);
    s.swept_max = s.end_max.cwiseMax(start_max);
    grid_min_ = grid_min_.cwiseMin(s.swept_min);
    grid_max_ = grid_max_.cwiseMax(s.swept_max);
    any = true;
    int smallest = 0;
    for (int i = 1; i < 3; ++i) {
      if (s.radii[i] < s.radii[smallest]) smallest = i;
    }
    s.smallest_axis = smallest;
    const float r_max = s.radii.maxCoeff();
    // Depth along any ray from inside is at most (1 - |q|) * r_max, so |q| >= 1 - tol / r_max
    // means "inside by at most tol".
    const float tol = std::min(kPenetrationTolerance / r_max, 1.0f);
    s.inside_tol2 = (1.0f - tol) * (1.0f - tol);
    const float graze = std::min(0.5f * margin_ / r_max, 1.0f);
    s.graze = (1.0f - graze) * (1.0f - graze);
    refreshQuick(k);
  }
  if (!any || count > kMaxGridEllipsoids) return;

  words_ = (count + 63) / 64;
  // Near-cubic cells, about kGridCells of them over the union of the swept boxes (a body:
  // ~8 cm cells), at most kGridMaxPerAxis along an axis and 2 * kGridCells in all, so the
  // storage reserved below is never exceeded.
  const Vec3 extent = (grid_max_ - grid_min_).cwiseMax(Vec3::Constant(1e-4f));
  const float cell = std::cbrt(extent.prod() / static_cast<float>(kGridCells));
  for (int a = 0; a < 3; ++a) {
    const float cells_a = std::ceil(extent[a] / cell);
    dims_[a] = cells_a >= static_cast<float>(kGridMaxPerAxis) ? kGridMaxPerAxis
                                                               : std::max(1, static_cast<int>(cells_a));
  }
  while (dims_[0] * dims_[1] * dims_[2] > 2 * kGridCells) {
    int* largest = std::max_element(dims_, dims_ + 3);
    --*largest;
  }
  for (int a = 0; a < 3; ++a) grid_scale_[a] = static_cast<float>(dims_[a]) / extent[a];
  const size_t capacity = static_cast<size_t>(2 * kGridCells * words_);
  if (cells_.capacity() < capacity) cells_.reserve(capacity);
  cell_origin_ = Eigen::Array4f(grid_min_.x(), grid_min_.y(), grid_min_.z(), 0.0f);
  cell_scale_ = Eigen::Array4f(grid_scale_.x(), grid_scale_.y(), grid_scale_.z(), 0.0f);
  // Largest float that still truncates to dims - 1.
  cell_top_ = Eigen::Array4f(std::nextafter(static_cast<float>(dims_[0]), 0.0f),
                             std::nextafter(static_cast<float>(dims_[1]), 0.0f),
                             std::nextafter(static_cast<float>(dims_[2]), 0.0f), 0.0f);
  cells_.assign(static_cast<size_t>(dims_[0] * dims_[1] * dims_[2] * words_), 0);
  for (int k = 0; k < count; ++k) {
    const Shape& s = shapes_[static_cast<size_t>(k)];
    if (!(s.swept_min.x() <= s.swept_max.x())) continue;
    const Eigen::Array4i lo = cellsOf(s.swept_min, cell_origin_, cell_scale_, cell_top_);
    const Eigen::Array4i hi = cellsOf(s.swept_max, cell_origin_, cell_scale_, cell_top_);
    const uint64_t bit = uint64_t{1} << (k & 63);
    for (int z = lo[2]; z <= hi[2]; ++z) {
      for (int y = lo[1]; y <= hi[1]; ++y) {
        for (int x = lo[0]; x <= hi[0]; ++x) {
          cells_[static_cast<size_t>(((z * dims_[1] + y) * dims_[0] + x) * words_ + (k >> 6))] |= bit;
        }
      }
    }
  }
  grid_ = true;
}

void EllipsoidCollider::refreshQuick(int k) {
  const Shape& s = shapes_[static_cast<size_t>(k)];
  Quick& q = quick_[static_cast<size_t>(k)];
  q.end_c = lift(s.end.centre);
  q.start_c = lift(s.start.centre);
  for (int i = 0; i < 3; ++i) {
    q.end_u[i] = lift(s.end.to_unit.col(i));
    q.start_u[i] = lift(s.start.to_unit.col(i));
  }
  q.swept_min = lift(s.swept_min);
  q.swept_max = lift(s.swept_max);
  q.end_min = lift(s.end_min);
  q.end_max = lift(s.end_max);
  q.radii2 = lift(s.radii.cwiseProduct(s.radii));
  q.inside_tol2 = s.inside_tol2;
  q.graze = s.graze;
}

#if defined(__GNUC__)
#define DRAPE_ALWAYS_INLINE __attribute__((always_inline)) inline
#define DRAPE_LAMBDA_INLINE __attribute__((always_inline))
#else
#define DRAPE_ALWAYS_INLINE inline
#define DRAPE_LAMBDA_INLINE
#endif

DRAPE_ALWAYS_INLINE bool EllipsoidCollider::gather(const Vec3& lo, const Vec3& hi, bool use_grid,
                                                   const uint64_t* allowed, Candidates& c) const {
  if (!overlaps(lo, hi, grid_min_, grid_max_)) return false;  // outside every swept box
  c.all = !use_grid;
  c.allowed = allowed;
  if (c.all) return true;
  c.lo = cellsOf(lo, cell_origin_, cell_scale_, cell_top_);
  c.hi = cellsOf(hi, cell_origin_, cell_scale_, cell_top_);
  if ((c.lo == c.hi).all()) {  // the usual case: one cell
    const uint64_t* cell =
        &cells_[static_cast<size_t>(((c.lo[2] * dims_[1] + c.lo[1]) * dims_[0] + c.lo[0]) * words_)];
    if (allowed) {
      for (int w = 0; w < words_; ++w) c.mask[w] = cell[w] & allowed[w];
    } else {
      for (int w = 0; w < words_; ++w) c.mask[w] = cell[w];
    }
    return true;
  }
  for (int w = 0; w < words_; ++w) c.mask[w] = 0;
  for (int z = c.lo[2]; z <= c.hi[2]; ++z) {
    for (int y = c.lo[1]; y <= c.hi[1]; ++y) {
      for (int x = c.lo[0]; x <= c.hi[0]; ++x) {
        const uint64_t* cell = &cells_[static_cast<size_t>(((z * dims_[1] + y) * dims_[0] + x) * words_)];
        for (int w = 0; w < words_; ++w) c.mask[w] |= cell[w];
      }
    }
  }
  if (allowed)
    for (int w = 0; w < words_; ++w) c.mask[w] &= allowed[w];
  return true;
}

bool EllipsoidCollider::covers(const Candidates& c, const Vec3& p) const {
  if (c.all) return true;
  const Eigen::Array4i i = cellsOf(p, cell_origin_, cell_scale_, cell_top_);
  return (i >= c.lo).all() && (i <= c.hi).all();
}

template <class F>
void EllipsoidCollider::iterate(const Candidates& c, F&& f) const {
  if (c.all) {
    const int n = count();
    for (int k = 0; k < n; ++k)
      if (!c.allowed || ((c.allowed[k >> 6] >> (k & 63)) & 1u)) f(k);
    return;
  }
  for (int w = 0; w < words_; ++w) {
    uint64_t m = c.mask[w];
    while (m) {
      const int k = (w << 6) + lowestBit(m);
      m &= m - 1;
      f(k);
    }
  }
}

template <class F>
void EllipsoidCollider::forCandidates(const Vec3& lo, const Vec3& hi, bool use_grid, const uint64_t* allowed,
                                      F&& f) const {
  Candidates c;
  if (gather(lo, hi, use_grid, allowed, c)) iterate(c, f);
}

int EllipsoidCollider::firstContaining(const Vec3& x, bool use_grid, const uint64_t* allowed,
                                       CollisionStats& st) const {
  int found = -1;
  forCandidates(x, x, use_grid, allowed, [&](int k) {
    if (found >= 0) return;
    const Quick& qk = quick_[static_cast<size_t>(k)];
    const Vec4 x4 = lift(x);
    if (!contains4(qk.end_min, qk.end_max, x4)) return;
    ++st.tests;
    if (mulq(qk.end_u, x4 - qk.end_c).squaredNorm() < qk.inside_tol2) found = k;
  });
  return found;
}

Vec3 EllipsoidCollider::respond(const Shape& s, const Vec3& x, const Vec3& q, float r2,
                                ContactResponse mode, Vec3& q_contact) const {
  if (mode == ContactResponse::Radial) {
    // Paper eq. 9-10; at the exact centre, push along the smallest axis (the nearest exit).
    q_contact = r2 > 1e-30f ? Vec3(q / std::sqrt(r2)) : Vec3(Vec3::Unit(s.smallest_axis));
    return s.end.centre + mulv(s.end.from_unit, q_contact);
  }
  Vec3 y;
  const Quick& qk = quick_[static_cast<size_t>(&s - shapes_.data())];
  if (!closestInsideFloat(qk.radii2, lift(q), r2, y, q_contact)) {
    const Vec3 local = mulvT(s.rotation, x - s.end.centre);
    y = closestPointOnEllipsoidFast(s.radii, local);
    q_contact = y.cwiseQuotient(s.radii);
  }
  return s.end.centre + mulv(s.rotation, y);
}

Vec3 EllipsoidCollider::slideFromEntry(const Shape& s, const Vec3& qe, const Vec3& q1,
                                       Vec3& q_contact) const {
  // Time of impact, then slide: from the entry point the rest of the relative motion continues
  // in the tangent plane there (its inward normal part is what the contact removes).
  const Vec3 xe = s.end.centre + mulv(s.end.from_unit, qe);
  Vec3 n = mulvT(s.end.to_unit, qe);
  const float nn = n.norm();
  Vec3 rest = mulv(s.end.from_unit, q1 - qe);
  if (nn > 0.0f) {
    n /= nn;
    const float rn = rest.dot(n);
    if (rn < 0.0f) rest -= rn * n;
  }
  const Vec3 x = xe + rest;
  q_contact = mulv(s.end.to_unit, x - s.end.centre);
  return x;
}

void EllipsoidCollider::escape(Vec3& x, ContactResponse mode, bool use_grid, const uint64_t* allowed,
                               float max_escape, CollisionStats& st) const {
  // x is inside one or more overlapping ellipsoids after the sequential passes (pushes out of
  // one keep landing in another). Candidates: the response target of each ellipsoid containing
  // x (up to 8). Take the nearest target that is outside every ellipsoid; if there is none,
  // march from x along each push direction to the first point outside every ellipsoid (along a
  // ray each ellipsoid covers one interval, so jumping to the exit of whichever contains the
  // current point ends after at most count() jumps) and take the shortest march.
  constexpr int kMaxCandidates = 8;
  int containing[kMaxCandidates];
  Vec3 targets[kMaxCandidates];
  int m = 0;
  forCandidates(x, x, use_grid, allowed, [&](int k) {
    if (m == kMaxCandidates) return;
    const Shape& s = shapes_[static_cast<size_t>(k)];
    if (!containsPoint(s.end_min, s.end_max, x)) return;
    ++st.tests;
    const Vec3 q = mulv(s.end.to_unit, x - s.end.centre);
    const float r2 = q.squaredNorm();
    if (!(r2 < s.inside_tol2)) return;
    Vec3 qc;
    targets[m] = respond(s, x, q, r2, mode, qc);
    containing[m++] = k;
  });
  // Beyond max_escape the particle stays (pinched): best starts at the limit.
  const float limit2 = max_escape > 0.0f ? max_escape * max_escape : std::numeric_limits<float>::infinity();
  float best = limit2;
  Vec3 best_x = x;
  for (int i = 0; i < m; ++i) {
    const float d = (targets[i] - x).squaredNorm();
    if (d < best && firstContaining(targets[i], use_grid, allowed, st) < 0) {
      best = d;
      best_x = targets[i];
    }
  }
  if (best < limit2) {
    x = best_x;
    return;
  }
  const int n = count();
  for (int i = 0; i < m; ++i) {
    const Shape& s0 = shapes_[static_cast<size_t>(containing[i])];
    Vec3 dir = targets[i] - x;
    const float len = dir.norm();
    dir = len > 1e-12f ? Vec3(dir / len) : Vec3(s0.rotation.col(s0.smallest_axis));
    float t = 0.0f;
    bool out = false;
    for (int jump = 0; jump <= n && t * t < best; ++jump) {
      const Vec3 p = x + t * dir;
      const int k = firstContaining(p, use_grid, allowed, st);
      if (k < 0) {
        out = true;
        break;
      }
      const Shape& s = shapes_[static_cast<size_t>(k)];
      const Vec3 q = mulv(s.end.to_unit, p - s.end.centre);
      const Vec3 v = mulv(s.end.to_unit, dir);
      const float a = v.squaredNorm(), b = q.dot(v), c = q.squaredNorm() - 1.0f;
      const float step = a > 0.0f ? (-b + std::sqrt(std::max(b * b - a * c, 0.0f))) / a : 0.0f;
      t += std::max(step, 1e-7f) * 1.000001f;
    }
    if (out && t * t < best) {
      best = t * t;
      best_x = x + t * dir;
    }
  }
  x = best_x;
}

// The response to one contact of pass 0 (discrete or swept), friction included. Kept out of
// line so the candidate loop around the narrow test stays small and inlined.
#if defined(__GNUC__)
__attribute__((noinline))
#endif
void EllipsoidCollider::contact(const Shape& s, const Eigen::Vector4f& q1_4, float r2,
                                const Eigen::Vector4f& q0_4, float q0sq, bool inside, bool cont,
                                bool friction, const Vec3& x0, const CollisionParams& p, Vec3& x,
                                CollisionStats& st) const {
  const Vec3 q1 = q1_4.head<3>(), q0 = q0_4.head<3>();
  Vec3 target, qc;
  bool swept = false;
  if (inside) {
    target = respond(s, x, q1, r2, p.response, qc);
    // Entered during this substep: if the discrete push would move it far round the surface
    // from where it came in (it went deep, e.g. a fast limb), use the entry point.
    // The cone of directions within 45 degrees of qc is convex: when q0 and q1 both lie in
    // it, so does the whole segment and its entry point, and the test below cannot fire.
    if (cont && q0sq >= s.inside_tol2) {
      const float d0 = qc.dot(q0), d1 = qc.dot(q1);
      constexpr float kCos2 = kDeepContactCos * kDeepContactCos;
      const bool in_cone = (d0 >= 0.0f) & (d1 >= 0.0f) & (d0 * d0 >= kCos2 * q0sq) &
                           (d1 * d1 >= kCos2 * r2);
      if (!in_cone) {
        const Vec3 qe = entryPoint(q0, q0sq, q1);
        if (qc.dot(qe) < kDeepContactCos) {
          target = slideFromEntry(s, qe, q1, qc);
          swept = true;
        }
      }
    }
  } else {
    target = slideFromEntry(s, entryPoint(q0, q0sq, q1), q1, qc);
    swept = true;
  }
  ++st.contacts;
  if (swept) ++st.swept_catches;
  const Vec3 before = x;
  x = target;
  if (friction) {
    applyFriction(s.end.to_unit, s.end.centre, s.end.from_unit, s.start.centre,
                  s.start.from_unit, qc, before, x0, p.static_friction, p.kinetic_friction, x);
  }
}

void EllipsoidCollider::resolveParticle(Vec3& x, const Vec3& x0, bool has_prev,
                                        const CollisionParams& p, const uint64_t* allowed,
                                        CollisionStats& st) const {
  const bool cont = p.continuous && has_prev;
  const bool friction = has_prev && (p.static_friction > 0.0f || p.kinetic_friction > 0.0f);
  const bool use_grid = p.broad_phase && grid_;
  // Every visitor below first applies the per-ellipsoid AABB test, which every ellipsoid the grid
  // leaves out fails: with and without the grid the same ellipsoids are tested in the same
  // order, so both modes give bit-identical results.

  // Pass 0: discrete test at the substep end, swept test, friction.
  const Vec3 lo = cont ? x.cwiseMin(x0) : x;
  const Vec3 hi = cont ? x.cwiseMax(x0) : x;
  const Vec3 x_end = x;
  bool moved = false;
  Candidates first;
  if (!gather(lo, hi, use_grid, allowed, first)) return;
  const Vec4 lo4 = lift(lo), hi4 = lift(hi), x0_4 = lift(x0), x_end4 = lift(x_end);
  iterate(first, [&](int k) DRAPE_LAMBDA_INLINE {
    const Quick& qk = quick_[static_cast<size_t>(k)];
    const bool in_box = cont ? overlaps4(lo4, hi4, qk.swept_min, qk.swept_max)
                             : contains4(qk.end_min, qk.end_max, x_end4);
    if (!in_box) return;
    ++st.tests;
    // Past the box test, no contact is decided with one branch: the discrete and the swept
    // tests are both evaluated and combined (4-lane arithmetic on the Quick copy).
    const Vec4 q1_4 = mulq(qk.end_u, lift(x) - qk.end_c);
    const float r2 = q1_4.squaredNorm();
    const bool inside = r2 < 1.0f;
    Vec4 q0_4 = Vec4::Zero();
    float q0sq = 0.0f;
    bool crossed = false;
    if (cont) {
      // Outside at both ends: did the relative path q0 -> q1 pass through the unit ball (deeper
      // than the graze threshold)? Closest approach^2 = q0sq - b^2 / a, compared times a.
      q0_4 = mulq(qk.start_u, x0_4 - qk.start_c);
      q0sq = q0_4.squaredNorm();
      const Vec4 d = q1_4 - q0_4;
      const float a = d.squaredNorm(), b = q0_4.dot(d);
      crossed = !inside & (q0sq >= 1.0f) & (b < 0.0f) & (a > 0.0f) & (-b <= a) &
                (q0sq * a - b * b < qk.graze * a);
    }
    if (!(inside | crossed)) return;
    contact(shapes_[static_cast<size_t>(k)], q1_4, r2, q0_4, q0sq, inside, cont, friction, x0, p, x, st);
    moved = true;
  });

  if (moved) settle(x, &first, p, use_grid, allowed, st);
}

void EllipsoidCollider::settle(Vec3& x, const Candidates* first, const CollisionParams& p, bool use_grid,
                               const uint64_t* allowed, CollisionStats& st) const {
  bool moved = true;
  // Further sequential passes (no friction): a push out of one ellipsoid may land in another.
  // The first pass's candidates still cover x when it stayed in the same cells (the usual case).
  // Gathering again instead gives the same tests in the same order: an ellipsoid whose end box
  // holds x is in x's cell.
  for (int pass = 1; pass < kSequentialPasses && moved; ++pass) {
    moved = false;
    const Vec3 xp = x;
    Candidates again;
    const Candidates* c = first;
    if (!first || !covers(*first, xp)) {
      if (!gather(xp, xp, use_grid, allowed, again)) break;
      c = &again;
    }
    const Vec4 xp4 = lift(xp);
    iterate(*c, [&](int k) {
      const Quick& qk = quick_[static_cast<size_t>(k)];
      if (!contains4(qk.end_min, qk.end_max, xp4)) return;
      ++st.tests;
      const Vec4 q4 = mulq(qk.end_u, lift(x) - qk.end_c);
      const float r2 = q4.squaredNorm();
      if (!(r2 < qk.inside_tol2)) return;
      Vec3 qc;
      x = respond(shapes_[static_cast<size_t>(k)], x, q4.head<3>(), r2, p.response, qc);
      moved = true;
    });
  }
  // Guarantee: if the last pass moved the particle, check it; still inside -> escape step.
  if (moved && firstContaining(x, use_grid, allowed, st) >= 0) {
    escape(x, p.response, use_grid, allowed, p.max_escape_m, st);
    ++st.escapes;
  }
}

#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
namespace {
bool cpuHasAvx() {
  static const bool avx = __builtin_cpu_supports("avx");
  return avx;
}
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
  const bool swept = p.continuous && previous != nullptr;
  const bool use_grid = p.broad_phase && grid_;
  const bool any_friction = p.static_friction > 0.0f || p.kinetic_friction > 0.0f;
  Lanes X, Y, Z, X0, Y0, Z0, LOX, LOY, LOZ, HIX, HIY, HIZ;
  const uint64_t* allowed[8];
  Vec3 start[8];
  int active = 0;  // bit j: lane j takes part in the batched pass 0
  uint64_t joint_allowed[kMaxGridEllipsoids / 64] = {};
  Vec3 lo = Vec3::Constant(std::numeric_limits<float>::infinity()), hi = -lo;
  for (int j = 0; j < 8; ++j) {
    const size_t i = begin + static_cast<size_t>(j);
    // The same rejections as collide()'s particle loop.
    if (!(positions[i].w() > 0.0f)) continue;
    const Vec3 x = positions[i].head<3>();
    if (!containsPoint(grid_min_, grid_max_, x)) {
      if (!swept) continue;
      const Vec3 p0 = previous[i].head<3>();
      if (!overlaps(x.cwiseMin(p0), x.cwiseMax(p0), grid_min_, grid_max_)) continue;
    }
    if (!isFinite(x)) continue;
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
    const Vec3 l = swept ? x.cwiseMin(x0) : x, h = swept ? x.cwiseMax(x0) : x;
    LOX.v[j] = l.x(), LOY.v[j] = l.y(), LOZ.v[j] = l.z();
    HIX.v[j] = h.x(), HIY.v[j] = h.y(), HIZ.v[j] = h.z();
    lo = lo.cwiseMin(l);
    hi = hi.cwiseMax(h);
    if (allowed[j])
      for (int w = 0; w < words_; ++w) joint_allowed[w] |= allowed[j][w];
  }
  Candidates c;
  if (active == 0 || !gather(lo, hi, use_grid, grouped ? joint_allowed : nullptr, c)) return true;
  const bool has_prev = previous != nullptr;
  const bool cont = p.continuous && has_prev;
  const bool friction = has_prev && any_friction;
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
    if (grouped)
      for (int j = 0; j < 8; ++j)
        if (((lanes >> j) & 1) && !((allowed[j][k >> 6] >> (k & 63)) & 1u)) lanes &= ~(1 << j);
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
    settle(x, nullptr, p, use_grid, allowed[j], st);
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

void EllipsoidCollider::setGroups(const std::vector<uint8_t>& ellipsoid_groups, const uint8_t* particle_masks) {
  groups_ = ellipsoid_groups;
  particle_masks_ = particle_masks;
  allowed_.clear();
  if (groups_.empty() || !particle_masks_ || groups_.size() > static_cast<size_t>(kMaxGridEllipsoids)) return;
  constexpr size_t kWords = kMaxGridEllipsoids / 64;
  allowed_.assign(256 * kWords, 0);
  for (size_t mask = 0; mask < 256; ++mask)
    for (size_t k = 0; k < groups_.size(); ++k)
      if (groups_[k] & mask) allowed_[mask * kWords + k / 64] |= uint64_t{1} << (k % 64);
}

CollisionStats EllipsoidCollider::collide(Eigen::Vector4f* positions,
                                          const Eigen::Vector4f* previous, size_t count,
                                          const CollisionParams& params) const {
  CollisionStats st;
  if (!positions || shapes_.empty()) return st;
  // Friction coefficients outside [0, 1e6] (negative, NaN, infinite) are clamped.
  CollisionParams p = params;
  p.static_friction = p.static_friction > 0.0f ? std::min(p.static_friction, 1e6f) : 0.0f;
  p.kinetic_friction = p.kinetic_friction > 0.0f ? std::min(p.kinetic_friction, 1e6f) : 0.0f;
  const bool swept = p.continuous && previous != nullptr;
  const bool grouped = particle_masks_ != nullptr && !allowed_.empty() &&
                       groups_.size() == shapes_.size() && shapes_.size() <= static_cast<size_t>(kMaxGridEllipsoids);
  size_t i = 0;
  if (p.batch8)
    for (; i + 8 <= count && collideEight(positions, previous, i, p, grouped, st); i += 8) {}
  for (; i < count; ++i) {
    if (!(positions[i].w() > 0.0f)) continue;
    const Vec3 x = positions[i].head<3>();
    // Cheap reject before anything else: nowhere near any ellipsoid's (swept) box. NaN fails
    // every comparison and is rejected here too, unless the previous position is finite.
    if (!containsPoint(grid_min_, grid_max_, x)) {
      if (!swept) continue;
      const Vec3 p0 = previous[i].head<3>();
      if (!overlaps(x.cwiseMin(p0), x.cwiseMax(p0), grid_min_, grid_max_)) continue;
    }
    if (!isFinite(x)) continue;
    Vec3 x0 = x;
    bool has_prev = false;
    if (previous) {
      x0 = previous[i].head<3>();
      has_prev = isFinite(x0);
      if (!has_prev) x0 = x;
    }
    Vec3 y = x;
    const uint64_t* allowed =
        grouped ? &allowed_[static_cast<size_t>(particle_masks_[i]) * (kMaxGridEllipsoids / 64)] : nullptr;
    resolveParticle(y, x0, has_prev, p, allowed, st);
    if (y != x) positions[i].head<3>() = y;
  }
  return st;
}

}  // namespace drape
