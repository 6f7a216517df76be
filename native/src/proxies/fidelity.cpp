#include "proxies/fidelity.h"

#include "proxies/closest_point.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace drape {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
// A union sample is dropped when it lies deeper than this inside another ellipsoid, in that
// ellipsoid's unit space (|q| < 1 - kStrictlyInside): about 0.1 mm for a 10 cm radius, so samples
// on the seam where two surfaces cross are kept.
constexpr float kStrictlyInside = 1e-3f;
// How far outside its ellipsoid's box a union sample may fall by rounding, metres (far more than
// it does: float rounding of a 1 m coordinate is 1e-7 m).
constexpr float kSampleBoxSlackM = 1e-3f;

float boxDistance(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  const Vec3 d = (lo - p).cwiseMax(p - hi).cwiseMax(0.0f);
  return d.norm();
}

struct Stats {
  float mean = 0.0f, p95 = 0.0f, max = 0.0f, weighted_mean = 0.0f;
};

// values in metres -> statistics in mm. Sorts `values` (scratch).
Stats statistics(std::vector<float>& values, const std::vector<float>& weights) {
  Stats s;
  if (values.empty()) return s;
  double sum = 0.0, wsum = 0.0, wtotal = 0.0;
  for (size_t i = 0; i < values.size(); ++i) {
    sum += values[i];
    if (weights[i] > 0.0f) {
      wsum += static_cast<double>(weights[i]) * values[i];
      wtotal += weights[i];
    }
  }
  s.mean = static_cast<float>(1000.0 * sum / static_cast<double>(values.size()));
  s.weighted_mean = wtotal > 0.0 ? static_cast<float>(1000.0 * wsum / wtotal) : s.mean;
  const size_t rank = static_cast<size_t>(std::ceil(0.95 * static_cast<double>(values.size())));
  const size_t k = rank == 0 ? 0 : rank - 1;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  s.p95 = 1000.0f * values[k];
  s.max = 1000.0f * *std::max_element(values.begin(), values.end());
  return s;
}

}  // namespace

Vec3 fibonacciSpherePoint(int i, int n) {
  if (n <= 0) return Vec3::UnitY();
  const double golden = 3.14159265358979323846 * (3.0 - std::sqrt(5.0));
  const double y = 1.0 - (2.0 * i + 1.0) / n;
  const double r = std::sqrt(std::max(0.0, 1.0 - y * y));
  const double phi = golden * i;
  return Vec3(static_cast<float>(r * std::cos(phi)), static_cast<float>(y),
              static_cast<float>(r * std::sin(phi)));
}

EllipsoidSurfacePoint ellipsoidSurfacePoint(const Ellipsoid& el, const Vec3& p) {
  EllipsoidSurfacePoint out;
  const Vec3 d = p - el.centre;
  if (!(el.radii.minCoeff() > 0.0f) || !std::isfinite(el.radii.sum()) || !isFinite(d)) {
    out.point = el.centre;
    out.distance = d.norm();
    return out;
  }
  // The collider's reference solver (Eberly's bisection in double, proxies/closest_point.h).
  const Vec3 closest_local = closestPointOnEllipsoid(el.radii, el.rotation.transpose() * d, &out.distance);
  out.point = el.centre + el.rotation * closest_local;
  return out;
}

float distanceOutsideUnion(const Ellipsoid* ellipsoids, size_t count, const Vec3& p, std::vector<float>& box_scratch,
                           size_t skip) {
  for (size_t j = 0; j < count; ++j)
    if (j != skip && containsPoint(ellipsoids[j].bounds_min, ellipsoids[j].bounds_max, p) &&
        ellipsoids[j].implicit(p) < 0.0f)
      return 0.0f;
  // Nearest box first, so the remaining boxes prune against a good bound.
  box_scratch.resize(count);
  size_t first = count;
  for (size_t j = 0; j < count; ++j) {
    if (j == skip) continue;
    box_scratch[j] = boxDistance(p, ellipsoids[j].bounds_min, ellipsoids[j].bounds_max);
    if (first == count || box_scratch[j] < box_scratch[first]) first = j;
  }
  if (first == count) return kInf;
  float best = ellipsoidSurfacePoint(ellipsoids[first], p).distance;
  for (size_t j = 0; j < count; ++j) {
    if (j == first || j == skip || !(box_scratch[j] < best)) continue;
    best = std::min(best, ellipsoidSurfacePoint(ellipsoids[j], p).distance);
  }
  return best;
}

FidelityReport measureFidelity(const std::vector<Vec3>& body_positions,
                               const std::vector<uint32_t>& body_indices,
                               const Ellipsoid* ellipsoids, int count, const TriangleBvh& bvh,
                               int samples_per_ellipsoid) {
  FidelityReport report;
  std::vector<Ellipsoid> ell;
  if (ellipsoids && count > 0) {
    ell.assign(ellipsoids, ellipsoids + count);
    for (Ellipsoid& e : ell) e.refresh();  // bounds and to_unit from centre/rotation/radii
  }
  const size_t m = ell.size();

  // ---- body -> union, on the body surface: every vertex and every triangle's centroid ----
  // Vertices alone miss the middle of the straight segments between rings, exactly where a union
  // of ellipsoids dips; centroids sample it. Each sample carries half its share of the area.
  const size_t nv = body_positions.size();
  std::vector<Vec3> samples(body_positions);
  std::vector<float> vertex_area(nv, 0.0f);
  samples.reserve(nv + body_indices.size() / 3);
  std::vector<float> centroid_area;
  centroid_area.reserve(body_indices.size() / 3);
  for (size_t t = 0; t + 2 < body_indices.size(); t += 3) {
    const uint32_t a = body_indices[t], b = body_indices[t + 1], c = body_indices[t + 2];
    if (a >= nv || b >= nv || c >= nv) continue;
    const float area = 0.5f * (body_positions[b] - body_positions[a])
                                  .cross(body_positions[c] - body_positions[a]).norm();
    if (!std::isfinite(area)) continue;
    vertex_area[a] += area / 6.0f;
    vertex_area[b] += area / 6.0f;
    vertex_area[c] += area / 6.0f;
    samples.push_back((body_positions[a] + body_positions[b] + body_positions[c]) / 3.0f);
    centroid_area.push_back(area / 2.0f);
  }
  vertex_area.insert(vertex_area.end(), centroid_area.begin(), centroid_area.end());
  const size_t n = samples.size();
  std::vector<float> outside(n, 0.0f);
  std::vector<float> box_distance(m, 0.0f);
  int outside_count = 0;
  for (size_t v = 0; v < n; ++v) {
    const float best = distanceOutsideUnion(ell.data(), m, samples[v], box_distance);
    outside[v] = best;
    if (!(best <= kFidelityOutsideMm * 1e-3f)) ++outside_count;
  }
  if (n > 0) {
    const Stats s = statistics(outside, vertex_area);
    report.body_to_union_mean_mm = s.mean;
    report.body_to_union_p95_mm = s.p95;
    report.body_to_union_max_mm = s.max;
    report.body_to_union_area_mean_mm = s.weighted_mean;
    report.outside_fraction = static_cast<float>(outside_count) / static_cast<float>(n);
    report.body_vertices = static_cast<int>(nv);
  }

  // ---- union -> body, Fibonacci samples on each ellipsoid's exposed surface ----
  const int per = std::max(0, samples_per_ellipsoid);
  std::vector<float> dist, weight;
  dist.reserve(m * static_cast<size_t>(per));
  weight.reserve(m * static_cast<size_t>(per));
  const float solid_angle = per > 0 ? 4.0f * kPi / static_cast<float>(per) : 0.0f;
  std::vector<size_t> near;
  near.reserve(m);
  for (size_t i = 0; i < m; ++i) {
    const Ellipsoid& e = ell[i];
    const float volume_factor = e.radii.prod();
    // Only an ellipsoid whose box meets this one's can hold its samples (they lie in its box, up
    // to rounding: the slack), so the others are left out once, not per sample; same answer.
    const Vec3 lo = e.bounds_min.array() - kSampleBoxSlackM, hi = e.bounds_max.array() + kSampleBoxSlackM;
    near.clear();
    for (size_t j = 0; j < m; ++j)
      if (j != i && overlaps(lo, hi, ell[j].bounds_min, ell[j].bounds_max)) near.push_back(j);
    for (int k = 0; k < per; ++k) {
      const Vec3 u = fibonacciSpherePoint(k, per);
      const Vec3 x = e.fromUnit(u);
      bool covered = false;
      for (size_t c = 0; c < near.size() && !covered; ++c) {
        const size_t j = near[c];
        if (!containsPoint(ell[j].bounds_min, ell[j].bounds_max, x)) continue;
        covered = ell[j].toUnit(x).norm() < 1.0f - kStrictlyInside;
      }
      if (covered) continue;
      const TriangleBvh::Hit h = bvh.closest(x);
      // Only where the union sticks out of the body: a union surface point inside the body is a
      // gap of the proxies, which the body -> union direction already measures (and points deep
      // inside are internal pockets of the union that no cloth can reach).
      dist.push_back(TriangleBvh::hitSign(x, h) > 0.0f ? h.distance : 0.0f);
      // Area element of the unit sphere -> ellipsoid map at u: det(S) |S^-1 u| dOmega.
      weight.push_back(volume_factor * u.cwiseQuotient(e.radii).norm() * solid_angle);
    }
  }
  report.union_samples = static_cast<int>(dist.size());
  if (!dist.empty()) {
    const Stats s = statistics(dist, weight);
    report.union_to_body_mean_mm = s.mean;
    report.union_to_body_p95_mm = s.p95;
    report.union_to_body_max_mm = s.max;
    report.union_to_body_area_mean_mm = s.weighted_mean;
  }
  return report;
}

}  // namespace drape
