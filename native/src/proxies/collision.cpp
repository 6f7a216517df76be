#include "proxies/collision.h"

#include "common/plain3.h"
#include "proxies/closest_point.h"
#include "proxies/collision_internal.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

namespace drape {
using namespace collision_internal;

namespace {

// 3x3 times 3-vector written out: GCC does not always inline Eigen's small products.
inline Vec3 mulv(const Mat3& m, const Vec3& v) {
  return m.col(0) * v.x() + m.col(1) * v.y() + m.col(2) * v.z();
}
inline Vec3 mulvT(const Mat3& m, const Vec3& v) {  // m^T v
  return Vec3(m.col(0).dot(v), m.col(1).dot(v), m.col(2).dot(v));
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

// Closest point on an ellipsoid (radii^2 b, local frame) to the local point y = e * q inside it
// (|q|^2 = r2 >= 0.25), in float: x_i = b_i y_i / (b_i + t) with t the root of
// F(t) = sum (e_i y_i / (b_i + t))^2 - 1 in (-b_min, 0] (F convex and decreasing there), by
// Newton steps kept inside the bracket (bisection otherwise). The first step, from t = 0 (where
// F = r2 - 1 and F' = -2 sum q_i^2 / b_i need no division), is the one that is exact for a
// sphere: Newton on (F + 1)^(-1/2) - 1, linear in t when the b_i are equal, which gives
// t1 = 2 r2 (1 - sqrt(r2)) / F'; Newton on F itself from there. Converged when |F| < 1e-5: the
// point is then on the surface to 5e-6 of its radius, under 1 um, where the collider promises
// 10 um. On the default scene 75 % of the contacts stop after the first step (at the tolerance
// 2e-6 used until 2026-12-01, 59 %; and 12 % with Newton on F from t = 0: docs/collision.md).
// False when it does not converge in 8 steps (near the medial surface of a flat ellipsoid) or for
// deeper points: the caller then uses the double solver.
// (Down to |q| = 0.5 the float answer is as close to the reference as near the surface, 1e-7 m:
// Collider.ExactDeeperContactsMatchTheReference.)
// e = sqrt(b) per lane (Quick::radii2_sqrt, computed once per ellipsoid and substep).
inline bool closestInsideFloat(const Vec4& b, const Vec4& e, const Vec4& q, float r2, Vec3& local, Vec3& qc) {
  if (!(r2 >= 0.25f)) return false;
  const Vec4 y = e.cwiseProduct(q);  // local point
  const Vec4 a = y.cwiseProduct(e);  // e_i y_i
  float lo = -b.head<3>().minCoeff(), hi = 0.0f, t = 0.0f;
  float F = r2 - 1.0f;
  float dF = -2.0f * (q.array().square() / (b.array() + Eigen::Array4f(0, 0, 0, 1))).sum();
  Eigen::Array4f r = Eigen::Array4f::Zero();
  for (int it = 0; it < 8; ++it) {
    if (F < 0.0f) hi = t; else lo = t;
    // The first step is the sphere's answer (above), Newton's on F after it.
    float tn = dF < 0.0f ? (it == 0 ? 2.0f * r2 * (1.0f - std::sqrt(r2)) / dF : t - F / dF) : lo;
    if (!(tn > lo && tn < hi)) tn = 0.5f * (lo + hi);
    t = tn;
    r = (b.array() + t + Eigen::Array4f(0, 0, 0, 1)).inverse();
    const Eigen::Array4f u = a.array() * r;
    F = (u * u).sum() - 1.0f;
    if (std::fabs(F) < kExactConvergedF) {
      // Just inside (F < 0: the first step lands there): out to just outside, as far as Newton's
      // steps on F leave a point (they land outside), so contacts rest on the same side.
      const float out = F < 0.0f ? 1.0f - F : 1.0f;
      const Eigen::Array4f x = b.array() * y.array() * r * out;
      local = Vec3(x[0], x[1], x[2]);
      const Eigen::Array4f qq = y.array() * r * e.array() * out;  // x / e
      qc = Vec3(qq[0], qq[1], qq[2]);
      return true;
    }
    dF = -2.0f * (u * u * r).sum();
  }
  return false;
}

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

Ellipsoid interpolateEllipsoidPose(const Ellipsoid& a, const Ellipsoid& b, float t) {
  Ellipsoid e;
  e.centre = a.centre + t * (b.centre - a.centre);
  e.radii = a.radii + t * (b.radii - a.radii);
  Quat qa(a.rotation), qb(b.rotation);
  qa.normalize();
  qb.normalize();
  e.rotation = qa.slerp(t, qb).toRotationMatrix();
  return e;
}

Ellipsoid interpolateEllipsoid(const Ellipsoid& a, const Ellipsoid& b, float t) {
  Ellipsoid e = interpolateEllipsoidPose(a, b, t);
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
  hold_count_ = 0;  // a later span cannot keep a grid this call builds
  hold_built_ = false;
  if (!setShapes(start, end, count, margin_m) || count > kMaxGridEllipsoids) return;
  buildGrid(count, [this](int k) { return std::make_pair(&shapes_[static_cast<size_t>(k)].swept_min,
                                                        &shapes_[static_cast<size_t>(k)].swept_max); });
}

void EllipsoidCollider::setSpanEllipsoids(const Ellipsoid* start, const Ellipsoid* end, int count, float margin_m,
                                          const Vec3* hold_min, const Vec3* hold_max) {
  if (hold_min && hold_max && count > 0) {
    hold_min_.assign(hold_min, hold_min + count);
    hold_max_.assign(hold_max, hold_max + count);
    hold_count_ = count;
    hold_built_ = false;
  }
  if (!setShapes(start, end, count, margin_m) || count > kMaxGridEllipsoids) {
    hold_built_ = false;
    return;
  }
  // Every swept box of this span inside its ellipsoid's hold box (finite): the grid built from
  // the hold boxes lists each ellipsoid in every cell its swept box touches.
  bool held = hold_count_ == count;
  for (int k = 0; k < count && held; ++k) {
    const Shape& s = shapes_[static_cast<size_t>(k)];
    if (!(s.swept_min.x() <= s.swept_max.x())) continue;  // not in the grid
    const Vec3& lo = hold_min_[static_cast<size_t>(k)];
    const Vec3& hi = hold_max_[static_cast<size_t>(k)];
    held = isFinite(lo) && isFinite(hi) && (lo.array() <= s.swept_min.array()).all() &&
           (s.swept_max.array() <= hi.array()).all();
  }
  if (held) {
    if (!hold_built_)
      buildGrid(count, [this](int k) { return std::make_pair(&hold_min_[static_cast<size_t>(k)],
                                                            &hold_max_[static_cast<size_t>(k)]); });
    grid_ = true;
    hold_built_ = true;
    return;
  }
  buildGrid(count, [this](int k) { return std::make_pair(&shapes_[static_cast<size_t>(k)].swept_min,
                                                        &shapes_[static_cast<size_t>(k)].swept_max); });
  hold_built_ = false;
}

bool EllipsoidCollider::setShapes(const Ellipsoid* start, const Ellipsoid* end, int count, float margin_m) {
  grid_ = false;
  if (!start || !end || count <= 0) {
    shapes_.clear();
    return false;
  }
  const float margin = (margin_m >= 0.0f && std::isfinite(margin_m)) ? margin_m : 0.0f;
  // What the last call built for its end ellipsoids is valid for this call's start ones at the
  // same margin (bit-for-bit equal inputs, checked per ellipsoid below).
  const size_t reusable = std::memcmp(&margin, &margin_, sizeof margin) == 0 ? shapes_.size() : 0;
  margin_ = margin;
  shapes_.resize(static_cast<size_t>(count));
  quick_.resize(static_cast<size_t>(count));
  constexpr float kInf = std::numeric_limits<float>::infinity();
  // The union of the swept boxes in locals (members would be stored and re-read every shape).
  Vec3 union_min = Vec3::Constant(kInf), union_max = Vec3::Constant(-kInf);
  bool any = false;

  // to_unit = diag(1 / radii) R^T, from_unit = R diag(radii), the box's half extent the rows'
  // norms of from_unit: element by element in the order of the Eigen expressions they replace
  // (row norms and sums as x + (y + z)), the same bits; two frames per ellipsoid every collision
  // substep, 8 % of three stress scenarios' time in the sanitizer build (-O1, perf) as Eigen calls.
  auto build = [this](const Ellipsoid& e, Frame& f, Vec3& radii, Vec3& mn, Vec3& mx) {
    for (int i = 0; i < 3; ++i) radii[i] = std::max(e.radii[i] + margin_, 1e-6f);
    f.centre = e.centre;
    const float inv[3] = {1.0f / radii[0], 1.0f / radii[1], 1.0f / radii[2]};
    bool finite = true;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        f.to_unit(i, j) = inv[i] * e.rotation(j, i);
        f.from_unit(i, j) = e.rotation(i, j) * radii[j];
      }
      const float h0 = f.from_unit(i, 0), h1 = f.from_unit(i, 1), h2 = f.from_unit(i, 2);
      const float half = norm(Plain3<float>{h0, h1, h2});
      mn[i] = e.centre[i] - half;
      mx[i] = e.centre[i] + half;
      const float row_sum = f.to_unit(i, 0) + (f.to_unit(i, 1) + f.to_unit(i, 2));
      finite = finite && std::isfinite(mn[i]) && std::isfinite(mx[i]) && std::isfinite(row_sum);
    }
    return finite;
  };

  auto same = [](const auto& a, const auto& b) { return std::memcmp(a.data(), b.data(), sizeof(a)) == 0; };
  for (int k = 0; k < count; ++k) {
    Shape& s = shapes_[static_cast<size_t>(k)];
    Vec3 start_radii, start_min, start_max;
    bool start_ok;
    // s.end.centre and s.rotation are the last call's end ellipsoid's, as it received them.
    if (static_cast<size_t>(k) < reusable && same(start[k].centre, s.end.centre) &&
        same(start[k].radii, s.end_in_radii) && same(start[k].rotation, s.rotation)) {
      s.start = s.end;  // the previous end frame, built from this very ellipsoid
      start_min = s.end_built_min;
      start_max = s.end_built_max;
      start_ok = s.end_built_ok;
    } else {
      start_ok = build(start[k], s.start, start_radii, start_min, start_max);
    }
    s.end_built_ok = build(end[k], s.end, s.radii, s.end_built_min, s.end_built_max);
    s.end_in_radii = end[k].radii;
    s.end_min = s.end_built_min;
    s.end_max = s.end_built_max;
    const bool ok = s.end_built_ok && start_ok;
    s.rotation = end[k].rotation;
    if (!ok) {  // never matches: empty boxes
      s.end_min = s.swept_min = Vec3::Constant(kInf);
      s.end_max = s.swept_max = Vec3::Constant(-kInf);
      refreshQuick(k);
      continue;
    }
    for (int i = 0; i < 3; ++i) {  // Eigen's cwiseMin / cwiseMax: std::min / std::max
      s.swept_min[i] = std::min(s.end_min[i], start_min[i]);
      s.swept_max[i] = std::max(s.end_max[i], start_max[i]);
      union_min[i] = std::min(union_min[i], s.swept_min[i]);
      union_max[i] = std::max(union_max[i], s.swept_max[i]);
    }
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
  grid_min_ = union_min;
  grid_max_ = union_max;
  return any;
}

template <class BoxOf>
void EllipsoidCollider::buildGrid(int count, BoxOf box_of) {
  // The union of the boxes of the shapes in the grid: for the swept boxes, grid_min_ / grid_max_
  // as setShapes computed them (the same operations in the same order).
  constexpr float kInf = std::numeric_limits<float>::infinity();
  Vec3 box_min = Vec3::Constant(kInf), box_max = Vec3::Constant(-kInf);
  for (int k = 0; k < count; ++k) {
    const Shape& s = shapes_[static_cast<size_t>(k)];
    if (!(s.swept_min.x() <= s.swept_max.x())) continue;
    const auto b = box_of(k);
    for (int i = 0; i < 3; ++i) {
      box_min[i] = std::min(box_min[i], (*b.first)[i]);
      box_max[i] = std::max(box_max[i], (*b.second)[i]);
    }
  }
  ++grid_builds_;
  words_ = (count + 63) / 64;
  // Near-cubic cells, about kGridCells of them over the union of the boxes (a body: ~8 cm
  // cells), at most kGridMaxPerAxis along an axis and 2 * kGridCells in all, so the storage
  // reserved below is never exceeded.
  const Vec3 extent = (box_max - box_min).cwiseMax(Vec3::Constant(1e-4f));
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
  cell_origin_ = Eigen::Array4f(box_min.x(), box_min.y(), box_min.z(), 0.0f);
  cell_scale_ = Eigen::Array4f(grid_scale_.x(), grid_scale_.y(), grid_scale_.z(), 0.0f);
  // Largest float that still truncates to dims - 1.
  cell_top_ = Eigen::Array4f(std::nextafter(static_cast<float>(dims_[0]), 0.0f),
                             std::nextafter(static_cast<float>(dims_[1]), 0.0f),
                             std::nextafter(static_cast<float>(dims_[2]), 0.0f), 0.0f);
  cells_.assign(static_cast<size_t>(dims_[0] * dims_[1] * dims_[2] * words_), 0);
  for (int k = 0; k < count; ++k) {
    const Shape& s = shapes_[static_cast<size_t>(k)];
    if (!(s.swept_min.x() <= s.swept_max.x())) continue;
    const auto b = box_of(k);
    const Eigen::Array4i lo = cellsOf(*b.first, cell_origin_, cell_scale_, cell_top_);
    const Eigen::Array4i hi = cellsOf(*b.second, cell_origin_, cell_scale_, cell_top_);
    const uint64_t bit = uint64_t{1} << (k & 63);
    // Row by row through a local pointer: indexing cells_ with the members, re-read for every
    // cell (a store might change them, as far as the compiler knows), cost 0.7 % of the default
    // replay's instructions (docs/performance.md, "Instruction counts").
    uint64_t* const first = cells_.data() + (k >> 6);
    const size_t stride = static_cast<size_t>(words_);
    const int dx = dims_[0], dy = dims_[1], nx = hi[0] - lo[0] + 1;
    for (int z = lo[2]; z <= hi[2]; ++z) {
      for (int y = lo[1]; y <= hi[1]; ++y) {
        uint64_t* word = first + static_cast<size_t>((z * dy + y) * dx + lo[0]) * stride;
        for (int x = 0; x < nx; ++x, word += stride) *word |= bit;
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
  q.radii2_sqrt = q.radii2.cwiseSqrt();
  q.inside_tol2 = s.inside_tol2;
  q.graze = s.graze;
  // The swept test's rejection bound (Quick::sweep_keep2, collision_batch.inc): with U0, U1 the
  // start and end to_unit, e1 = x1 - c1 and dx, dc the particle's and the centre's moves,
  // q1 - q0 = (U1 - U0) e1 + U0 (dx - dc), |e1| <= r_max |q1|: |q1 - q0| <= alpha |q1| +
  // gamma (|dx| + |dc|), alpha = |U1 - U0|_F r_max, gamma = |U0|_F. A path that came within the
  // unit sphere is at least |q1| - 1 long, so |q1| (1 - alpha) > 1 + gamma |dc| + gamma |dx| (plus
  // slack for the float tests) means no crossing. Computed in double, rounded the safe way.
  double du = 0.0, g = 0.0;
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) {
      const double e = static_cast<double>(s.end.to_unit(r, c)) - static_cast<double>(s.start.to_unit(r, c));
      const double u0 = s.start.to_unit(r, c);
      du += e * e;
      g += u0 * u0;
    }
  }
  const double r_max = s.radii.maxCoeff();
  const double gamma = std::sqrt(g) * (1.0 + 1e-6);
  const double dc = (s.end.centre.cast<double>() - s.start.centre.cast<double>()).norm();
  const double keep = (1.0 - std::sqrt(du) * r_max) * (1.0 - 1e-6) - 1e-6;
  q.sweep_keep2 = keep > 0.0 ? static_cast<float>(keep * keep * (1.0 - 1e-6)) : 0.0f;
  q.sweep_gamma = static_cast<float>(gamma);
  q.sweep_k = static_cast<float>(1.0 + kSweepSlack + gamma * dc * (1.0 + 1e-6));
}

template <class F>
void EllipsoidCollider::forCandidates(const Vec3& lo, const Vec3& hi, bool use_grid, const uint64_t* allowed,
                                      F&& f) const {
  Candidates c;
  if (gather(lo, hi, use_grid, allowed, c)) iterate(c, f);
}

inline bool EllipsoidCollider::holdsBeyondTolerance(const Quick& qk, const Vec4& x4, uint32_t& tests) {
  if (!contains4(qk.end_min, qk.end_max, x4)) return false;
  ++tests;
  return mulq(qk.end_u, x4 - qk.end_c).squaredNorm() < qk.inside_tol2;
}

int EllipsoidCollider::firstContaining(const Vec3& x, bool use_grid, const uint64_t* allowed,
                                       CollisionStats& st) const {
  int found = -1;
  const Vec4 x4 = lift(x);
  forCandidates(x, x, use_grid, allowed, [&](int k) {
    if (found < 0 && holdsBeyondTolerance(quick_[static_cast<size_t>(k)], x4, st.tests)) found = k;
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
  if (!closestInsideFloat(qk.radii2, qk.radii2_sqrt, lift(q), r2, y, q_contact)) {
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

void EllipsoidCollider::escape(Vec3& x, const EscapeStart& start, bool use_grid, const uint64_t* allowed,
                               float max_escape, CollisionStats& st) const {
  // x is inside one or more overlapping ellipsoids after the sequential passes (pushes out of
  // one keep landing in another). Candidates: the response target of each ellipsoid containing
  // x (start: up to 8). Take the nearest target that is outside every ellipsoid; if there is none,
  // march from x along each push direction to the first point outside every ellipsoid (along a
  // ray each ellipsoid covers one interval, so jumping to the exit of whichever contains the
  // current point ends after at most count() jumps) and take the shortest march.
  const int m = start.m;
  const int* containing = start.containing;
  const Vec3* targets = start.targets;
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
  if (moved) escapeIfInside(x, p, use_grid, allowed, st);
}

void EllipsoidCollider::escapeIfInside(Vec3& x, const CollisionParams& p, bool use_grid, const uint64_t* allowed,
                                       CollisionStats& st) const {
  // One scan of x's candidates answers both questions that were two scans: firstContaining's (is
  // x inside one by more than the tolerance? the Quick copy's test, counted up to the first that
  // holds it) and, since the answer is nearly always yes (98.5 % on the default scene), escape's
  // start (the ellipsoids containing x by the Shape's test, up to 8, and their response
  // targets). Each with its own arithmetic and its own test count, as before; the second count
  // is added only when x escapes, and the targets of an x that turns out not to be inside are
  // dropped.
  int found = -1;
  uint32_t tests_first = 0, tests_escape = 0;
  EscapeStart start;
  const Vec4 x4 = lift(x);
  forCandidates(x, x, use_grid, allowed, [&](int k) {
    if (found < 0 && holdsBeyondTolerance(quick_[static_cast<size_t>(k)], x4, tests_first)) found = k;
    if (start.m == kMaxEscapeCandidates) return;
    const Shape& s = shapes_[static_cast<size_t>(k)];
    if (!containsPoint(s.end_min, s.end_max, x)) return;
    ++tests_escape;
    const Vec3 q = mulv(s.end.to_unit, x - s.end.centre);
    const float r2 = q.squaredNorm();
    if (!(r2 < s.inside_tol2)) return;
    Vec3 qc;
    start.targets[start.m] = respond(s, x, q, r2, p.response, qc);
    start.containing[start.m++] = k;
  });
  st.tests += tests_first;
  if (found < 0) return;
  st.tests += tests_escape;
  escape(x, start, use_grid, allowed, p.max_escape_m, st);
  ++st.escapes;
}

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
  if (p.batch8) {
    if (p.batch16) i = collideSixteens(positions, previous, i, count, p, grouped, st);
    i = collideEights(positions, previous, i, count, p, grouped, st);
  }
  for (; i < count; ++i) {
    if (!mayTouch(positions, previous, i, swept)) continue;
    const Vec3 x = positions[i].head<3>();
    Vec3 x0 = x;
    bool has_prev = false;
    if (previous) {
      x0 = previous[i].head<3>();
      has_prev = isFinite(x0);
      if (!has_prev) x0 = x;
    }
    Vec3 y = x;
    resolveParticle(y, x0, has_prev, p, allowedFor(grouped, i), st);
    if (y != x) positions[i].head<3>() = y;
  }
  return st;
}

}  // namespace drape
