#include "backends/opencl/cl_shapes.h"

#include "proxies/collision.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace drape {
namespace {

DclF4 f4(const Vec3& v, float w = 0.0f) { return DclF4{v.x(), v.y(), v.z(), w}; }

struct Built {
  Vec3 radii, mn, mx;
  Mat3 to_unit, from_unit;
  bool ok;
};

// EllipsoidCollider::setEllipsoids' `build` lambda, float for float.
Built build(const Ellipsoid& e, float margin) {
  Built b;
  for (int i = 0; i < 3; ++i) b.radii[i] = std::max(e.radii[i] + margin, 1e-6f);
  b.to_unit = b.radii.cwiseInverse().asDiagonal() * e.rotation.transpose();
  b.from_unit = e.rotation * b.radii.asDiagonal();
  const Vec3 half = b.from_unit.rowwise().norm();
  b.mn = e.centre - half;
  b.mx = e.centre + half;
  b.ok = isFinite(b.mn) && isFinite(b.mx) && isFinite(b.to_unit.rowwise().sum());
  return b;
}

}  // namespace

std::vector<int> collisionSpanEnds(int substeps, int stride) {
  std::vector<int> ends;
  int span0 = 0;
  for (int s = 0; s < substeps; ++s) {
    if ((s + 1 - span0) >= stride || s + 1 == substeps) {
      ends.push_back(s + 1);
      span0 = s + 1;
    }
  }
  return ends;
}

bool packShape(const Ellipsoid& start, const Ellipsoid& end, float margin, uint32_t group, DrapeClShape& o) {
  const Built e = build(end, margin), s = build(start, margin);
  o = DrapeClShape{};
  o.end_c = f4(end.centre);
  o.start_c = f4(start.centre);
  DclF4* eu[3] = {&o.end_u0, &o.end_u1, &o.end_u2};
  DclF4* ef[3] = {&o.end_f0, &o.end_f1, &o.end_f2};
  DclF4* su[3] = {&o.start_u0, &o.start_u1, &o.start_u2};
  DclF4* sf[3] = {&o.start_f0, &o.start_f1, &o.start_f2};
  DclF4* rot[3] = {&o.rot0, &o.rot1, &o.rot2};
  for (int i = 0; i < 3; ++i) {
    *eu[i] = f4(e.to_unit.col(i));
    *ef[i] = f4(e.from_unit.col(i));
    *su[i] = f4(s.to_unit.col(i));
    *sf[i] = f4(s.from_unit.col(i));
    *rot[i] = f4(end.rotation.col(i));
  }
  o.radii = f4(e.radii);
  o.radii2 = f4(e.radii.cwiseProduct(e.radii));
  o.group = group;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  if (!(e.ok && s.ok)) {
    o.end_min = o.swept_min = f4(Vec3::Constant(kInf));
    o.end_max = o.swept_max = f4(Vec3::Constant(-kInf));
    o.inside_tol2 = 1.0f;
    o.graze = 0.0f;
    return false;
  }
  o.end_min = f4(e.mn);
  o.end_max = f4(e.mx);
  o.swept_min = f4(e.mn.cwiseMin(s.mn));
  o.swept_max = f4(e.mx.cwiseMax(s.mx));
  int smallest = 0;
  for (int i = 1; i < 3; ++i)
    if (e.radii[i] < e.radii[smallest]) smallest = i;
  o.smallest_axis = smallest;
  const float r_max = e.radii.maxCoeff();
  const float tol = std::min(EllipsoidCollider::kPenetrationTolerance / r_max, 1.0f);
  o.inside_tol2 = (1.0f - tol) * (1.0f - tol);
  const float graze = std::min(0.5f * margin / r_max, 1.0f);
  o.graze = (1.0f - graze) * (1.0f - graze);
  return true;
}

void packFrameShapes(const Ellipsoid* start, const Ellipsoid* end, int count, float margin,
                     const std::vector<uint8_t>& groups, int substeps, int stride,
                     std::vector<DrapeClShape>& shapes, std::vector<DclF4>& bounds) {
  const std::vector<int> ends = collisionSpanEnds(substeps, stride);
  const size_t n = static_cast<size_t>(std::max(count, 0));
  shapes.resize(ends.size() * n);
  bounds.resize(2 * ends.size());
  // The collider clamps the margin the same way.
  margin = (margin >= 0.0f && std::isfinite(margin)) ? margin : 0.0f;
  bool identical = true;
  for (size_t k = 0; k < n && identical; ++k) {
    identical = start[k].centre == end[k].centre && start[k].radii == end[k].radii &&
                start[k].rotation == end[k].rotation;
  }
  // ColliderMotion::beginSpan: span 0 starts at `start`, a span ending at the last substep ends
  // at `end`, others at the interpolation; each span starts where the previous one ended.
  std::vector<Ellipsoid> a(start, start + n), b(n);
  constexpr float kInf = std::numeric_limits<float>::infinity();
  for (size_t sp = 0; sp < ends.size(); ++sp) {
    const int s1 = ends[sp];
    if (identical) {
      for (size_t k = 0; k < n; ++k) a[k] = b[k] = end[k];
    } else {
      if (sp > 0) a.swap(b);
      const float t1 = s1 >= substeps ? 1.0f : static_cast<float>(s1) / static_cast<float>(substeps);
      for (size_t k = 0; k < n; ++k) b[k] = t1 == 1.0f ? end[k] : interpolateEllipsoid(start[k], end[k], t1);
    }
    Vec3 lo = Vec3::Constant(kInf), hi = Vec3::Constant(-kInf);
    for (size_t k = 0; k < n; ++k) {
      const uint32_t group = k < groups.size() && groups.size() == n ? groups[k] : 0xFFu;
      DrapeClShape& sh = shapes[sp * n + k];
      if (packShape(a[k], b[k], margin, group, sh)) {
        lo = lo.cwiseMin(Vec3(sh.swept_min.x, sh.swept_min.y, sh.swept_min.z));
        hi = hi.cwiseMax(Vec3(sh.swept_max.x, sh.swept_max.y, sh.swept_max.z));
      }
    }
    bounds[2 * sp] = f4(lo);
    bounds[2 * sp + 1] = f4(hi);
  }
}

}  // namespace drape
