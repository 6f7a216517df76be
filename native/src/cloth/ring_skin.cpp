#include "cloth/ring_skin.h"

#include <algorithm>
#include <cmath>

namespace drape {
namespace {

// The body between rings r0 and r0 + 1 at parameter t, interpolated as the garment templates
// interpolate their sections.
struct Section {
  Vec3 c;
  Mat3 f;
  float a, b;  // semi-axes along the frame's x (forward) and z
};

Section sectionAt(const std::vector<RingPose>& rings, int r0, float t) {
  const RingPose& A = rings[static_cast<size_t>(r0)];
  const RingPose& B = rings[static_cast<size_t>(r0) + 1];
  const float s = 1.0f - t;
  const Vec3 y = (s * A.frame.col(1) + t * B.frame.col(1)).normalized();
  const Vec3 x0 = s * A.frame.col(0) + t * B.frame.col(0) - (s * A.frame.col(0) + t * B.frame.col(0)).dot(y) * y;
  const Vec3 x = x0.norm() > 1e-6f ? Vec3(x0.normalized()) : anyPerpendicular(y);
  Mat3 f;
  f << x, y, x.cross(y);
  return {s * A.centre + t * B.centre, f, s * A.forward_m + t * B.forward_m, s * A.side_m + t * B.side_m};
}

// Bindings beyond this many blend widths from the nearest get weight < 1.8 % and are dropped.
constexpr float kBlendCutoff = 0.018f;

// A lower bound of bindToSegment(rings, c, r0, p).dist: the point's distance to the segment
// between the two ring centres less the largest semi-axis of the two rings. (bindToSegment's
// section centre lies on that segment and its frame is orthonormal, so |q| is at least that
// distance; its dist is at least |q| less the ellipse's radius in q's direction, and the section's
// semi-axes interpolate the rings'.)
float segmentLowerBound(const std::vector<RingPose>& rings, int r0, const Vec3& p) {
  const RingPose& A = rings[static_cast<size_t>(r0)];
  const RingPose& B = rings[static_cast<size_t>(r0) + 1];
  const Vec3 d = B.centre - A.centre;
  const float dd = d.squaredNorm();
  const float t = dd > 1e-12f ? std::clamp((p - A.centre).dot(d) / dd, 0.0f, 1.0f) : 0.0f;
  const float reach = std::max(std::max(A.forward_m, A.side_m), std::max(B.forward_m, B.side_m));
  return (p - (A.centre + t * d)).norm() - reach;
}
// Float rounding in the bound and in dist is ~1e-6 m at body scale; this keeps every pruned
// segment well clear of the cut-off.
constexpr float kBoundSlackM = 1e-3f;

}  // namespace

RingBinding bindToSegment(const std::vector<RingPose>& rings, int chain, int r0, const Vec3& p) {
  const Vec3 c0 = rings[static_cast<size_t>(r0)].centre, d = rings[static_cast<size_t>(r0) + 1].centre - c0;
  const float dd = d.squaredNorm();
  RingBinding b;
  b.chain = chain;
  b.r0 = r0;
  b.t = dd > 1e-12f ? std::clamp((p - c0).dot(d) / dd, 0.0f, 1.0f) : 0.0f;
  const Section s = sectionAt(rings, r0, b.t);
  const Vec3 q = s.f.transpose() * (p - s.c);
  const float nx = q.x() / s.a, nz = q.z() / s.b;
  const float rho = std::hypot(nx, nz), radial = std::hypot(q.x(), q.z());
  // Radial excess over the ellipse, combined with any overshoot past the segment's ends (t is
  // clamped, so past a chain's end y carries the overshoot); negative inside.
  const float surf = rho > 1e-6f ? radial * (1.0f - 1.0f / rho) : -std::min(s.a, s.b);
  b.dist = std::hypot(std::max(surf, 0.0f), q.y()) + std::min(surf, 0.0f);
  b.local = Vec3(nx, q.y(), nz);
  return b;
}

Vec3 placeBinding(const std::vector<RingPose>& rings, const RingBinding& b) {
  const Section s = sectionAt(rings, b.r0, b.t);
  return s.c + s.f * Vec3(b.local.x() * s.a, b.local.y(), b.local.z() * s.b);
}

void RingSkin::bind(const BodyModel& body, const std::vector<Vec3>& points, float blend_m) {
  bind(body, body.rings(), points, blend_m);
}

void RingSkin::bind(const BodyModel& layout, const std::vector<RingPose>& rings, const std::vector<Vec3>& points,
                    float blend_m) {
  primary_.assign(points.size(), RingBinding{});
  blend_.clear();
  weight_.clear();
  offset_.assign(1, 0);
  std::vector<RingBinding> cands;
  // Every segment of every chain, in chain order (the order the blend is summed in).
  std::vector<std::pair<int, int>> segments;
  for (int c = 0; c < kChainCount; ++c) {
    const int first = layout.chainFirstRing(Chain(c)), n = layout.chainRingCount(Chain(c));
    for (int i = 0; i + 1 < n; ++i) segments.emplace_back(c, first + i);
  }
  std::vector<float> bound(segments.size());
  // A segment whose binding would get a blend weight below the cut-off even against the nearest
  // one plays no part: neither nearest nor blended. Its lower bound says so without the binding
  // (most of the body's segments, for any point), with the nearest bounded from above by the
  // segment of the smallest lower bound. The kept bindings, their order and weights are those
  // of binding every segment (test_ring_skin.cpp).
  const float keep_within = blend_m > 0.0f ? blend_m * -std::log(kBlendCutoff) + kBoundSlackM : kBoundSlackM;
  for (size_t v = 0; v < points.size(); ++v) {
    cands.clear();
    size_t likely = 0;
    for (size_t k = 0; k < segments.size(); ++k) {
      bound[k] = segmentLowerBound(rings, segments[k].second, points[v]);
      if (bound[k] < bound[likely]) likely = k;
    }
    const float nearest_at_most =
        segments.empty() ? 0.0f : bindToSegment(rings, segments[likely].first, segments[likely].second, points[v]).dist;
    for (size_t k = 0; k < segments.size(); ++k) {
      if (bound[k] > nearest_at_most + keep_within) continue;
      cands.push_back(bindToSegment(rings, segments[k].first, segments[k].second, points[v]));
    }
    if (cands.empty()) {  // no segments at all (a body always has some): nothing bound
      offset_.push_back(static_cast<uint32_t>(blend_.size()));
      continue;
    }
    primary_[v] = *std::min_element(cands.begin(), cands.end(),
                                    [](const RingBinding& a, const RingBinding& b) { return a.dist < b.dist; });
    const size_t begin = blend_.size();
    float wsum = 0.0f;
    if (blend_m > 0.0f) {
      for (const RingBinding& b : cands) {
        const float w = std::exp(-(b.dist - primary_[v].dist) / blend_m);
        if (w < kBlendCutoff) continue;
        blend_.push_back(b);
        weight_.push_back(w);
        wsum += w;
      }
    } else {
      blend_.push_back(primary_[v]);
      weight_.push_back(1.0f);
      wsum = 1.0f;
    }
    for (size_t k = begin; k < weight_.size(); ++k) weight_[k] /= wsum;
    offset_.push_back(static_cast<uint32_t>(blend_.size()));
  }
}

Vec3 RingSkin::place(const std::vector<RingPose>& rings, size_t i) const {
  Vec3 sum = Vec3::Zero();
  for (uint32_t k = offset_[i]; k < offset_[i + 1]; ++k) sum += weight_[k] * placeBinding(rings, blend_[k]);
  return sum;
}

void RingSkin::place(const BodyModel& body, std::vector<Vec3>& out) const {
  out.resize(primary_.size());
  for (size_t i = 0; i < primary_.size(); ++i) out[i] = place(body.rings(), i);
}

}  // namespace drape
