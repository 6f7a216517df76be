// Fidelity of a set of ellipsoids against a mesh (proxies/fidelity.h): exact answers on spheres,
// the union's sampling, and the point-to-ellipsoid distance against brute force.
#include "body/body_model.h"
#include "body/mesh_metrics.h"
#include "proxies/fidelity.h"
#include "random_draws.h"
#include "sanitizer_scale.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <random>
#include <vector>

namespace drape {
namespace {

struct Mesh {
  std::vector<Vec3> positions;
  std::vector<uint32_t> indices;
};

// Icosahedron subdivided `levels` times, vertices on the sphere (centre, r), outward winding.
Mesh icosphere(const Vec3& centre, float r, int levels) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<Vec3> v = {{-1, t, 0}, {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (Vec3& p : v) p.normalize();
  std::vector<uint32_t> f = {0, 11, 5, 0, 5,  1,  0,  1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                             4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3, 9, 4,  3, 4,  2,  3, 2, 6, 3, 6,
                             8, 3,  8,  9, 4,  9, 5, 2, 4, 11, 6, 2, 10, 8, 6,  7,  9, 8, 1};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      const uint32_t id = static_cast<uint32_t>(v.size() - 1);
      mid[key] = id;
      return id;
    };
    std::vector<uint32_t> g;
    for (size_t i = 0; i < f.size(); i += 3) {
      const uint32_t a = f[i], b = f[i + 1], c = f[i + 2];
      const uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      g.insert(g.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    f.swap(g);
  }
  Mesh m;
  for (const Vec3& p : v) m.positions.push_back(centre + r * p);
  m.indices = f;
  return m;
}

// Largest gap between the sphere and its inscribed mesh: r minus the smallest distance from the
// centre to any triangle.
float tessellationError(const Mesh& m, const Vec3& centre, float r) {
  float nearest = r;
  for (size_t i = 0; i < m.indices.size(); i += 3) {
    const Vec3 q = closestPointOnTriangle(centre, m.positions[m.indices[i]],
                                          m.positions[m.indices[i + 1]], m.positions[m.indices[i + 2]]);
    nearest = std::min(nearest, (q - centre).norm());
  }
  return r - nearest;
}

Ellipsoid sphere(const Vec3& centre, float r, const Mat3& rotation = Mat3::Identity()) {
  Ellipsoid e;
  e.centre = centre;
  e.rotation = rotation;
  e.radii = Vec3::Constant(r);
  e.refresh();
  return e;
}

const Vec3 kCentre(0.25f, 1.3f, 2.5f);  // where the body's chest would be
constexpr float kR = 0.12f;

TEST(Fidelity, SphereAgainstItsTessellationIsExact) {
  const Mesh m = icosphere(kCentre, kR, 5);  // 10 242 vertices, 20 480 triangles
  ASSERT_GT(signedVolume(m.positions, m.indices), 0.0);
  const MeshCheck check = checkMesh(m.positions, m.indices);
  ASSERT_TRUE(check.watertight && check.consistent_winding) << check.first_problem;
  const float sag = tessellationError(m, kCentre, kR);
  std::printf("  level-5 icosphere, r = %.0f mm: tessellation error %.1f um\n", 1000.0f * kR, 1e6f * sag);
  EXPECT_GT(sag, 1e-5f);
  EXPECT_LT(sag, 1e-4f);  // ~ r (1 - cos(edge angle)) for 3.5-degree edges

  TriangleBvh bvh;
  ASSERT_TRUE(bvh.build(m.positions, m.indices));
  const Mat3 turn = Eigen::AngleAxisf(0.7f, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Ellipsoid e = sphere(kCentre, kR, turn);
  const FidelityReport f = measureFidelity(m.positions, m.indices, &e, 1, bvh, 512);
  // Every vertex lies on the sphere: no distance beyond float rounding.
  EXPECT_LT(f.body_to_union_max_mm, 1e-3f);
  EXPECT_EQ(f.outside_fraction, 0.0f);
  EXPECT_EQ(f.body_vertices, static_cast<int>(m.positions.size()));
  // The sphere lies outside its inscribed mesh by at most the tessellation error.
  EXPECT_EQ(f.union_samples, 512);
  EXPECT_LE(f.union_to_body_max_mm, 1000.0f * sag + 1e-3f);
  EXPECT_GT(f.union_to_body_mean_mm, 0.0f);
  EXPECT_LE(f.union_to_body_mean_mm, f.union_to_body_p95_mm);
  EXPECT_LE(f.union_to_body_p95_mm, f.union_to_body_max_mm);
  EXPECT_LE(f.union_to_body_area_mean_mm, 1000.0f * sag + 1e-3f);
}

TEST(Fidelity, SmallerSphereIsTenPercentShort) {
  const Mesh m = icosphere(kCentre, kR, 5);
  const float sag = tessellationError(m, kCentre, kR);
  TriangleBvh bvh;
  ASSERT_TRUE(bvh.build(m.positions, m.indices));
  const Ellipsoid e = sphere(kCentre, 0.9f * kR);
  const FidelityReport f = measureFidelity(m.positions, m.indices, &e, 1, bvh, 400);
  const float expected_mm = 1000.0f * 0.1f * kR;  // 12 mm at the vertices
  // Triangle centroids sit inside the sphere by at most the tessellation error.
  const float tol = 1000.0f * sag + 1e-3f;
  EXPECT_NEAR(f.body_to_union_mean_mm, expected_mm, tol);
  EXPECT_NEAR(f.body_to_union_p95_mm, expected_mm, tol);
  EXPECT_NEAR(f.body_to_union_max_mm, expected_mm, 1e-3f);
  EXPECT_NEAR(f.body_to_union_area_mean_mm, expected_mm, tol);
  EXPECT_EQ(f.outside_fraction, 1.0f);
  // The union's surface lies 0.1 r inside the mesh: it sticks out nowhere, so union -> body
  // (which measures only where the union is outside the body) is 0; the gap is body -> union's.
  EXPECT_EQ(f.union_samples, 400);
  (void)sag;
  for (float v : {f.union_to_body_mean_mm, f.union_to_body_p95_mm, f.union_to_body_max_mm,
                  f.union_to_body_area_mean_mm}) {
    EXPECT_EQ(v, 0.0f);
  }

  // And a sphere 10 % larger: no vertex outside, the union 0.1 r beyond the mesh.
  const Ellipsoid big = sphere(kCentre, 1.1f * kR);
  const FidelityReport g = measureFidelity(m.positions, m.indices, &big, 1, bvh, 400);
  EXPECT_EQ(g.body_to_union_max_mm, 0.0f);
  EXPECT_EQ(g.outside_fraction, 0.0f);
  EXPECT_GE(g.union_to_body_mean_mm, expected_mm - 1e-3f);
  EXPECT_LE(g.union_to_body_max_mm, expected_mm + 1000.0f * sag + 1e-3f);
}

TEST(Fidelity, UnionSamplesDropTheOverlap) {
  // Two equal spheres, centres d apart: the part of each inside the other is a cap of height
  // r - d/2, i.e. a fraction (r - d/2) / (2r) of its area; Fibonacci samples are area-uniform on
  // a sphere, so that fraction of them is dropped.
  const float r = 0.1f, d = 0.1f;
  const Mesh m = icosphere(kCentre, 0.2f, 3);
  TriangleBvh bvh;
  ASSERT_TRUE(bvh.build(m.positions, m.indices));
  const Ellipsoid pair[2] = {sphere(kCentre - Vec3(d / 2, 0, 0), r),
                             sphere(kCentre + Vec3(d / 2, 0, 0), r)};
  const int n = 2000;
  const FidelityReport f = measureFidelity(m.positions, m.indices, pair, 2, bvh, n);
  const float expected = 2.0f * n * (1.0f - (r - d / 2) / (2 * r));  // 3 000
  EXPECT_NEAR(static_cast<float>(f.union_samples), expected, 0.01f * expected);
  // Both spheres lie inside the big mesh: every vertex outside; its distance is to the union.
  EXPECT_EQ(f.outside_fraction, 1.0f);
  EXPECT_GE(f.body_to_union_max_mm, 1000.0f * (0.2f - r) - 1.0f);  // top/bottom: 0.2 - ~0.087
  EXPECT_LE(f.body_to_union_max_mm, 1000.0f * (0.2f - std::sqrt(r * r - d * d / 4)) + 1e-2f);
  EXPECT_NEAR(f.body_to_union_p95_mm, f.body_to_union_max_mm, 20.0f);
  // The nearest points (on the x axis) are 0.2 - d/2 - r = 0.05 m from the union.
  const float least_mm = 1000.0f * (0.2f - d / 2 - r);
  EXPECT_GT(f.body_to_union_mean_mm, least_mm);

  // No ellipsoids: everything infinitely far, nothing sampled; bad pointers tolerated.
  const FidelityReport none = measureFidelity(m.positions, m.indices, nullptr, 3, bvh);
  EXPECT_TRUE(std::isinf(none.body_to_union_max_mm));
  EXPECT_EQ(none.outside_fraction, 1.0f);
  EXPECT_EQ(none.union_samples, 0);
}

// Brute force: the nearest of a dense (theta, phi) grid on the surface, refined three times on a
// ten times finer grid around the best sample.
float bruteEllipsoidDistance(const Ellipsoid& e, const Vec3& p) {
  const Eigen::Vector3d c = e.centre.cast<double>(), pd = p.cast<double>();
  const Eigen::Matrix3d R = e.rotation.cast<double>();
  const Eigen::Vector3d r = e.radii.cast<double>();
  auto at = [&](double th, double ph) {
    const Eigen::Vector3d u(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
    return (c + R * r.cwiseProduct(u) - pd).norm();
  };
  const double pi = 3.14159265358979323846;
  double best = 1e30, bt = 0, bp = 0, dt = pi / 200, dp = 2 * pi / 400;
  for (int i = 0; i <= 200; ++i)
    for (int j = 0; j < 400; ++j) {
      const double d = at(i * dt, j * dp);
      if (d < best) {
        best = d;
        bt = i * dt;
        bp = j * dp;
      }
    }
  for (int round = 0; round < 4; ++round) {
    const double t0 = bt, p0 = bp;
    for (int i = -20; i <= 20; ++i)
      for (int j = -20; j <= 20; ++j) {
        const double th = std::clamp(t0 + i * dt / 10, 0.0, pi), ph = p0 + j * dp / 10;
        const double d = at(th, ph);
        if (d < best) {
          best = d;
          bt = th;
          bp = ph;
        }
      }
    dt /= 10;
    dp /= 10;
  }
  return static_cast<float>(best);
}

TEST(Fidelity, EllipsoidDistanceMatchesBruteForce) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> radius(0.02f, 0.3f), unit(-1.0f, 1.0f), angle(0.0f, 6.28f);
  int outside = 0, inside = 0;
  // Under the sanitizers the first 100 of the same 300 cases: they still hold every kind (equal
  // radii every 10th, points on a symmetry plane every 7th and 11th, inside and outside); the
  // others repeat the same code on other numbers, against a brute-force reference that is the
  // ASan cost. The counts below are the same fractions of the cases.
  const int cases = test::repeatsUnderSanitizers(300, 3);
  for (int i = 0; i < cases; ++i) {
    Ellipsoid e;
    e.centre = kCentre + 0.2f * test::draw3(unit, rng);
    const float turn = angle(rng);
    const Vec3 axis = test::draw3(unit, rng).normalized();
    e.rotation = Eigen::AngleAxisf(turn, axis).toRotationMatrix();
    e.radii = test::draw3(radius, rng);
    if (i % 10 == 0) e.radii.y() = e.radii.x();  // equal radii: the degenerate branches
    e.refresh();
    // Points from deep inside to 0.5 m outside; some exactly on a symmetry plane.
    const Vec3 dir = test::draw3(unit, rng);
    const float reach = 0.3f + 2.5f * std::fabs(unit(rng));
    Vec3 local = dir.cwiseProduct(e.radii) * reach;
    if (i % 7 == 0) local.z() = 0.0f;
    if (i % 11 == 0) local.x() = 0.0f;
    const Vec3 p = e.centre + e.rotation * local;
    const EllipsoidSurfacePoint s = ellipsoidSurfacePoint(e, p);
    (e.implicit(p) > 0.0f ? outside : inside)++;
    EXPECT_NEAR(e.toUnit(s.point).norm(), 1.0f, 1e-5f) << "case " << i;
    EXPECT_NEAR((s.point - p).norm(), s.distance, 1e-5f) << "case " << i;
    const float brute = bruteEllipsoidDistance(e, p);
    EXPECT_LE(s.distance, brute + 2e-6f) << "case " << i << ": brute force found a closer point";
    EXPECT_NEAR(s.distance, brute, 1e-5f) << "case " << i << " radii " << e.radii.transpose();
  }
  EXPECT_GT(outside, cases / 6);   // 50 of 300
  EXPECT_GT(inside, cases / 10);   // 30 of 300
  // Degenerate radii do not crash.
  Ellipsoid flat = sphere(kCentre, 0.1f);
  flat.radii.z() = 0.0f;
  EXPECT_NEAR(ellipsoidSurfacePoint(flat, kCentre + Vec3(0.3f, 0, 0)).distance, 0.3f, 1e-6f);
}

// distanceOutsideUnion prunes by boxes (nearest first, farther boxes skipped): the same distance
// as the minimum over every ellipsoid, with one left out or none, and 0 inside any.
TEST(Fidelity, DistanceOutsideUnionIsTheMinimumOverTheEllipsoids) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> radius(0.03f, 0.2f), unit(-1.0f, 1.0f), angle(0.0f, 6.28f);
  std::vector<Ellipsoid> e(12);
  for (Ellipsoid& el : e) {
    el.centre = kCentre + 0.4f * test::draw3(unit, rng);
    const float turn = angle(rng);
    const Vec3 axis = test::draw3(unit, rng).normalized();
    el.rotation = Eigen::AngleAxisf(turn, axis).toRotationMatrix();
    el.radii = test::draw3(radius, rng);
    el.refresh();
  }
  std::vector<float> scratch;
  int inside = 0, outside = 0;
  const int points = test::repeatsUnderSanitizers(400, 4);
  for (int i = 0; i < points; ++i) {
    const Vec3 p = kCentre + 0.6f * test::draw3(unit, rng);
    for (const size_t skip : {SIZE_MAX, static_cast<size_t>(i) % e.size()}) {
      float brute = std::numeric_limits<float>::infinity();
      for (size_t k = 0; k < e.size(); ++k) {
        if (k == skip) continue;
        brute = std::min(brute, e[k].implicit(p) < 0.0f ? 0.0f : ellipsoidSurfacePoint(e[k], p).distance);
      }
      const float d = distanceOutsideUnion(e.data(), e.size(), p, scratch, skip);
      EXPECT_EQ(d, brute) << "point " << i << " skip " << skip;
      (d == 0.0f ? inside : outside)++;
    }
  }
  EXPECT_GT(inside, points / 20);
  EXPECT_GT(outside, points / 2);
  // Nothing left: +inf (every ellipsoid skipped, or none given).
  EXPECT_EQ(distanceOutsideUnion(e.data(), 1, kCentre, scratch, 0), std::numeric_limits<float>::infinity());
  EXPECT_EQ(distanceOutsideUnion(nullptr, 0, kCentre, scratch), std::numeric_limits<float>::infinity());
}

TEST(Fidelity, FibonacciSphereIsUnitAndBalanced) {
  Vec3 sum = Vec3::Zero();
  for (int i = 0; i < 1000; ++i) {
    const Vec3 u = fibonacciSpherePoint(i, 1000);
    EXPECT_NEAR(u.norm(), 1.0f, 1e-6f);
    sum += u;
  }
  EXPECT_LT(sum.norm() / 1000.0f, 2e-3f);
}

// Per-ring ellipsoids on the real body (one per feature ring, half-height to the farther
// neighbour): a plausible proxy set of ~80 to check the function is fast enough for every frame
// of a recording and gives sane magnitudes.
TEST(Fidelity, RingEllipsoidsOnTheBodyAreFastAndClose) {
  BodyModel body(resolveShape(BodyShapeInput{}), BodyModelParams{});
  body.update(restPose(body.shape()));
  std::vector<Ellipsoid> ells;
  for (int c = 0; c < kChainCount; ++c) {
    const int first = body.chainFirstRing(static_cast<Chain>(c)), n = body.chainRingCount(static_cast<Chain>(c));
    for (int j = first; j < first + n; ++j) {
      const RingPose& ring = body.rings()[j];
      float h = 0.005f;
      if (j > first) h = std::max(h, (ring.centre - body.rings()[j - 1].centre).norm());
      if (j + 1 < first + n) h = std::max(h, (ring.centre - body.rings()[j + 1].centre).norm());
      Ellipsoid e;
      e.centre = ring.centre;
      e.rotation = ring.frame;
      e.radii = Vec3(std::max(ring.forward_m, 0.005f), h, std::max(ring.side_m, 0.005f));
      e.refresh();
      ells.push_back(e);
    }
  }
  ASSERT_GE(ells.size(), 60u);
  TriangleBvh bvh;
  ASSERT_TRUE(bvh.build(body.positions(), body.indices()));
  const auto t0 = std::chrono::steady_clock::now();
  const FidelityReport f = measureFidelity(body.positions(), body.indices(), ells.data(),
                                           static_cast<int>(ells.size()), bvh);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::printf("  %zu ring ellipsoids: body->union mean %.2f p95 %.2f max %.2f mm (area mean %.2f), "
              "outside %.1f %%; union->body mean %.2f p95 %.2f max %.2f mm (area mean %.2f), %d samples; %.1f ms\n",
              ells.size(), f.body_to_union_mean_mm, f.body_to_union_p95_mm, f.body_to_union_max_mm,
              f.body_to_union_area_mean_mm, 100.0f * f.outside_fraction, f.union_to_body_mean_mm,
              f.union_to_body_p95_mm, f.union_to_body_max_mm, f.union_to_body_area_mean_mm,
              f.union_samples, ms);
  // Ring points lie on their own ellipsoid's equator: no ring vertex is outside; the centroids
  // half-way between rings and in the junction stitches are (this stand-in has no overlap).
  EXPECT_LT(f.body_to_union_p95_mm, 10.0f);
  EXPECT_GT(f.union_samples, 1000);
  EXPECT_LT(f.union_to_body_mean_mm, 60.0f);
}

}  // namespace
}  // namespace drape
