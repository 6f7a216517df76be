// Particle–ellipsoid collision (native/src/proxies/collision.h, closest_point.h).
#include "cloth/collider_motion.h"
#include "proxies/closest_point.h"
#include "proxies/collision.h"

#include "random_draws.h"
#include "sanitizer_scale.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace drape {
namespace {

using Vec4 = Eigen::Vector4f;
using V3d = Eigen::Vector3d;

// ---------------------------------------------------------------------------------------------
// Brute-force reference: sample the surface e ∘ u(θ, φ) densely, then refine the best samples by
// pattern search in (θ, φ) with a shrinking step, all in double. The local surface point is mapped
// to the frame `p` is given in by x = c + R s (identity and zero for local tests, a rigid transform
// for rotated ones). Plain doubles, not Eigen expressions: the sampling is 80 000 points per probe,
// and in the sanitizer build (-O1) Eigen's expression templates stay calls (this test took 13 s
// there).
double bruteDistance(const V3d& e, const V3d& p, const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity(),
                     const V3d& c = V3d::Zero()) {
  // Polar axis = the longest radius, so that along an elongated ellipsoid theta moves along the
  // long axis and phi around it: the distance's valleys are then aligned with the parameters.
  int pa = 0;
  for (int i = 1; i < 3; ++i) {
    if (e[i] > e[pa]) pa = i;
  }
  const int pb = (pa + 1) % 3, pc = (pa + 2) % 3;
  double r[3][3], cc[3], pp[3], ee[3];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r[i][j] = R(i, j);
    cc[i] = c[i];
    pp[i] = p[i];
    ee[i] = e[i];
  }
  auto dist2At = [&](double st, double ct, double sp, double cp) {
    double u[3];
    u[pa] = ct;
    u[pb] = st * cp;
    u[pc] = st * sp;
    const double s0 = ee[0] * u[0], s1 = ee[1] * u[1], s2 = ee[2] * u[2];
    double d2 = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double d = cc[i] + (r[i][0] * s0 + r[i][1] * s1 + r[i][2] * s2) - pp[i];
      d2 += d * d;
    }
    return d2;
  };
  auto dist = [&](double th, double ph) {
    return std::sqrt(dist2At(std::sin(th), std::cos(th), std::sin(ph), std::cos(ph)));
  };
  constexpr int kTh = 200, kPh = 400;
  static std::vector<double> sth, cth, sph, cph;
  if (sth.empty()) {
    for (int i = 0; i <= kTh; ++i) {
      sth.push_back(std::sin(M_PI * i / kTh));
      cth.push_back(std::cos(M_PI * i / kTh));
    }
    for (int j = 0; j < kPh; ++j) {
      sph.push_back(std::sin(2.0 * M_PI * j / kPh));
      cph.push_back(std::cos(2.0 * M_PI * j / kPh));
    }
  }
  // Best sample per octant of the parameter sphere so every basin is refined.
  double best_d[8], best_th[8], best_ph[8];
  for (int i = 0; i < 8; ++i) best_d[i] = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= kTh; ++i) {
    for (int j = 0; j < kPh; ++j) {
      const double d = dist2At(sth[i], cth[i], sph[j], cph[j]);
      const int oct = (cth[i] >= 0 ? 1 : 0) | (cph[j] >= 0 ? 2 : 0) | (sph[j] >= 0 ? 4 : 0);
      if (d < best_d[oct]) {
        best_d[oct] = d;
        best_th[oct] = M_PI * i / kTh;
        best_ph[oct] = 2.0 * M_PI * j / kPh;
      }
    }
  }
  double result = std::numeric_limits<double>::infinity();
  for (int o = 0; o < 8; ++o) {
    if (!std::isfinite(best_d[o])) continue;
    double th = best_th[o], ph = best_ph[o], d = dist(th, ph);
    double step = M_PI / kTh;
    for (int it = 0; it < 100000 && step > 1e-13; ++it) {
      double bt = th, bp = ph, bd = d;
      for (int a = -1; a <= 1; ++a) {
        for (int b = -1; b <= 1; ++b) {
          const double dd = dist(th + a * step, ph + b * step);
          if (dd < bd) {
            bd = dd;
            bt = th + a * step;
            bp = ph + b * step;
          }
        }
      }
      if (bt == th && bp == ph) step *= 0.5;
      th = bt;
      ph = bp;
      d = bd;
    }
    result = std::min(result, d);
  }
  return result;
}

double bruteLocal(const Vec3& radii, const Vec3& p) {
  return bruteDistance(radii.cast<double>(), p.cast<double>());
}

// Points to test against ellipsoid `r`: random inside/outside, on every axis (inside, on the
// surface, outside), the centre, in the coordinate planes, on and just off the surface.
std::vector<Vec3> probePoints(const Vec3& r, std::mt19937& rng, int random_count) {
  std::vector<Vec3> pts;
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::uniform_real_distribution<float> scale(0.05f, 2.5f);
  for (int i = 0; i < random_count; ++i) {
    Vec3 d = test::draw3(u, rng);
    if (d.norm() < 1e-3f) continue;
    d.normalize();
    pts.push_back(r.cwiseProduct(d) * scale(rng));
  }
  pts.push_back(Vec3::Zero());
  for (int a = 0; a < 3; ++a) {
    for (float f : {0.01f, 0.3f, 0.7f, 0.999f, 1.0f, 1.5f, -0.5f}) {
      Vec3 p = Vec3::Zero();
      p[a] = f * r[a];
      pts.push_back(p);
    }
  }
  // Coordinate planes (one coordinate exactly zero), inside and outside.
  for (int a = 0; a < 3; ++a) {
    for (float f : {0.2f, 0.6f, 1.3f}) {
      Vec3 p = r * f * 0.57735f;
      p[a] = 0.0f;
      pts.push_back(p);
      p[(a + 1) % 3] = -p[(a + 1) % 3];
      pts.push_back(p);
    }
  }
  // On the surface and 1 mm inside / outside it.
  for (int i = 0; i < 6; ++i) {
    Vec3 d = test::draw3(u, rng);
    d.normalize();
    const Vec3 s = r.cwiseProduct(d);
    const Vec3 n = s.cwiseQuotient(r.cwiseProduct(r)).normalized();
    pts.push_back(s);
    pts.push_back(s + 1e-3f * n);
    pts.push_back(s - 1e-3f * n * std::min(1.0f, r.minCoeff() * 0.5f / 1e-3f));
  }
  return pts;
}

const Vec3 kShapes[] = {
    Vec3(0.1f, 0.1f, 0.1f),     // sphere
    Vec3(0.05f, 0.15f, 0.05f),  // prolate 3:1 (a limb)
    Vec3(0.2f, 0.2f, 0.05f),    // oblate 4:1
    Vec3(0.3f, 0.1f, 0.02f),    // triaxial
    Vec3(1.0f, 0.01f, 0.01f),   // 100:1 needle
    Vec3(0.01f, 1.0f, 0.5f),    // 100:1 flat, permuted axes
};

TEST(ClosestPoint, MatchesBruteForceLocal) {
  std::mt19937 rng(7);
  for (const Vec3& r : kShapes) {
    for (const Vec3& p : probePoints(r, rng, 12)) {
      const double ref = bruteLocal(r, p);
      for (int method = 0; method < 2; ++method) {
        float d = -1.0f;
        const Vec3 x = method == 0 ? closestPointOnEllipsoid(r, p, &d)
                                   : closestPointOnEllipsoidFast(r, p, &d);
        SCOPED_TRACE(::testing::Message() << "radii " << r.transpose() << " p " << p.transpose()
                                          << (method == 0 ? " bisection" : " fast"));
        ASSERT_TRUE(isFinite(x));
        EXPECT_NEAR(d, ref, 1e-5 * std::max(ref, 1e-4));
        // The point returned is on the surface and at the distance returned.
        EXPECT_NEAR(x.cwiseQuotient(r).norm(), 1.0f, 2e-6f);
        EXPECT_NEAR((x - p).norm(), d, 2e-6f * r.maxCoeff());
      }
    }
  }
}

TEST(ClosestPoint, MatchesBruteForceRotated) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (const Vec3& r : kShapes) {
    for (int rep = 0; rep < test::repeatsUnderSanitizers(2, 2); ++rep) {
      const Quat rot = Quat(test::draw4(u, rng).normalized());
      const Mat3 R = rot.toRotationMatrix();
      const Vec3 c = test::draw3(u, rng) * 0.01f;
      const std::vector<Vec3> probes = probePoints(r, rng, test::repeatsUnderSanitizers(4, 4));
      // Under the sanitizers the random probe and every other fixed one (odd indices: the centre,
      // then points on each axis, in each coordinate plane, on and either side of the surface, all
      // kinds still present). What this test adds to MatchesBruteForceLocal (every probe there) is
      // the rotation, the same code for every probe; the double-precision brute force is the cost.
      for (size_t k = 0; k < probes.size(); ++k) {
        if (test::kSanitizedBuild && k > 0 && k % 2 == 0) continue;
        const Vec3& local = probes[k];
        const Vec3 p = c + R * local;
        const Vec3 l = R.transpose() * (p - c);
        float d = 0.0f;
        const Vec3 y = closestPointOnEllipsoid(r, l, &d);
        const Vec3 x = c + R * y;
        const Eigen::Matrix3d Rd = R.cast<double>();
        const V3d cd = c.cast<double>();
        const double ref = bruteDistance(r.cast<double>(), p.cast<double>(), Rd, cd);
        SCOPED_TRACE(::testing::Message() << "radii " << r.transpose() << " local " << local.transpose());
        // The float transforms round coordinates (~1e-7 of the size), so the relative tolerance
        // has a floor at 5e-7 of the ellipsoid's largest radius.
        EXPECT_NEAR((x - p).norm(), ref, 1e-5 * std::max(ref, 0.05 * r.maxCoeff()));
      }
    }
  }
}

TEST(ClosestPoint, FastAgreesWithBisection) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), lr(-2.5f, 1.0f);
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    const float rx = std::pow(10.0f, lr(rng)) * 0.1f;
    const float ry = std::pow(10.0f, lr(rng)) * 0.1f;
    const float rz = std::pow(10.0f, lr(rng)) * 0.1f;
    const Vec3 r(rx, ry, rz);
    const Vec3 p = r.cwiseProduct(test::draw3(u, rng)) * 1.5f;
    float d0 = 0.0f, d1 = 0.0f;
    const Vec3 a = closestPointOnEllipsoid(r, p, &d0);
    const Vec3 b = closestPointOnEllipsoidFast(r, p, &d1);
    worst = std::max(worst, static_cast<double>(std::fabs(d0 - d1)) / std::max(d0, 1e-6f * r.maxCoeff()));
    ASSERT_LE((a - b).norm(), 1e-5f * r.maxCoeff()) << r.transpose() << " | " << p.transpose();
  }
  EXPECT_LT(worst, 1e-5);
  std::printf("[ closest  ] fast (Halley) vs bisection, 200k random points: max relative distance difference %.2e\n", worst);
}

TEST(ClosestPoint, DegenerateInputs) {
  float d = -1.0f;
  // Centre of a sphere: some surface point at distance r.
  Vec3 x = closestPointOnEllipsoid(Vec3(0.1f, 0.1f, 0.1f), Vec3::Zero(), &d);
  EXPECT_NEAR(x.norm(), 0.1f, 1e-7f);
  EXPECT_NEAR(d, 0.1f, 1e-7f);
  // Centre of an ellipsoid: the ends of the smallest axis.
  x = closestPointOnEllipsoidFast(Vec3(0.3f, 0.05f, 0.1f), Vec3::Zero(), &d);
  EXPECT_NEAR(std::fabs(x.y()), 0.05f, 1e-7f);
  EXPECT_NEAR(d, 0.05f, 1e-7f);
  // Invalid radii or point: returned unchanged, distance 0, no NaN invented.
  const Vec3 p(0.1f, 0.2f, 0.3f);
  EXPECT_EQ(closestPointOnEllipsoid(Vec3(0.0f, 1.0f, 1.0f), p, &d), p);
  EXPECT_EQ(d, 0.0f);
  EXPECT_EQ(closestPointOnEllipsoid(Vec3(-1.0f, 1.0f, 1.0f), p, &d), p);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(closestPointOnEllipsoidFast(Vec3(nan, 1.0f, 1.0f), p, &d), p);
  const Vec3 bad(nan, 0.0f, 0.0f);
  const Vec3 r = closestPointOnEllipsoid(Vec3::Ones(), bad, &d);
  EXPECT_TRUE(std::isnan(r.x()));
  EXPECT_EQ(d, 0.0f);
}

// ---------------------------------------------------------------------------------------------
// Collider helpers.

Ellipsoid makeEllipsoid(const Vec3& c, const Vec3& radii, const Mat3& R = Mat3::Identity()) {
  Ellipsoid e;
  e.centre = c;
  e.radii = radii;
  e.rotation = R;
  e.refresh();
  return e;
}

// Exact penetration depth (metres) of p into ellipsoid e, 0 outside.
float depthInside(const Ellipsoid& e, const Vec3& p) {
  if (e.toUnit(p).squaredNorm() >= 1.0f) return 0.0f;
  float d = 0.0f;
  closestPointOnEllipsoid(e.radii, e.rotation.transpose() * (p - e.centre), &d);
  return d;
}

float maxDepth(const EllipsoidCollider& c, const std::vector<Vec4>& x) {
  float worst = 0.0f;
  for (const Vec4& p : x) {
    if (!(p.w() > 0.0f)) continue;
    for (int k = 0; k < c.count(); ++k) worst = std::max(worst, depthInside(c.inflatedEnd(k), p.head<3>()));
  }
  return worst;
}

// Minimal position-based integrator: predict with velocity and acceleration, collide against the
// substep's start/end ellipsoids, the prediction becomes the new position.
struct Particles {
  std::vector<Vec4> x, prev;
  void add(const Vec3& p, float w = 1.0f) {
    x.emplace_back(p.x(), p.y(), p.z(), w);
    prev.push_back(x.back());
  }
  CollisionStats step(const EllipsoidCollider& c, const Vec3& accel, float dt, const CollisionParams& p,
                      const std::vector<Vec3>* per_particle_accel = nullptr) {
    for (size_t i = 0; i < x.size(); ++i) {
      if (!(x[i].w() > 0.0f)) continue;
      const Vec3 pos = x[i].head<3>();
      const Vec3 v = (pos - prev[i].head<3>()) / dt;
      const Vec3 a = per_particle_accel ? (*per_particle_accel)[i] : accel;
      prev[i].head<3>() = pos;
      x[i].head<3>() = pos + v * dt + a * dt * dt;
    }
    return c.collide(x.data(), prev.data(), x.size(), p);
  }
};

TEST(Collider, InterpolateEllipsoid) {
  const Ellipsoid a = makeEllipsoid(Vec3(0, 0, 0), Vec3(0.1f, 0.2f, 0.3f));
  const Ellipsoid b = makeEllipsoid(Vec3(1, 2, 3), Vec3(0.3f, 0.2f, 0.1f),
                                    Eigen::AngleAxisf(1.0f, Vec3::UnitY()).toRotationMatrix());
  const Ellipsoid m = interpolateEllipsoid(a, b, 0.5f);
  EXPECT_TRUE(m.centre.isApprox(Vec3(0.5f, 1.0f, 1.5f)));
  EXPECT_TRUE(m.radii.isApprox(Vec3(0.2f, 0.2f, 0.2f)));
  EXPECT_TRUE(m.rotation.isApprox(Eigen::AngleAxisf(0.5f, Vec3::UnitY()).toRotationMatrix(), 1e-5f));
  EXPECT_TRUE(m.to_unit.isApprox(m.radii.cwiseInverse().asDiagonal() * m.rotation.transpose()));
  const Ellipsoid e1 = interpolateEllipsoid(a, b, 1.0f);
  EXPECT_TRUE(e1.rotation.isApprox(b.rotation, 1e-5f));
  EXPECT_TRUE(e1.centre.isApprox(b.centre));
}

TEST(Collider, RadialVersusExact) {
  // A 3:1 limb-like ellipsoid; particles everywhere inside it.
  const Ellipsoid e = makeEllipsoid(Vec3(0.2f, 1.0f, -0.1f), Vec3(0.04f, 0.12f, 0.04f),
                                    Eigen::AngleAxisf(0.7f, Vec3(1, 1, 0).normalized()).toRotationMatrix());
  EllipsoidCollider col;
  col.setEllipsoids(&e, &e, 1, 0.0f);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Vec4> pts;
  while (pts.size() < 20000) {
    const Vec3 q = test::draw3(u, rng);
    if (q.squaredNorm() >= 0.999f) continue;
    pts.emplace_back(Vec4(0, 0, 0, 1));
    pts.back().head<3>() = e.fromUnit(q);
  }
  std::vector<Vec4> radial = pts, exact = pts;
  CollisionParams p;
  p.continuous = false;
  p.static_friction = p.kinetic_friction = 0.0f;
  p.response = ContactResponse::Radial;
  const CollisionStats sr = col.collide(radial.data(), nullptr, radial.size(), p);
  p.response = ContactResponse::Exact;
  const CollisionStats se = col.collide(exact.data(), nullptr, exact.size(), p);
  EXPECT_EQ(sr.contacts, pts.size());
  EXPECT_EQ(se.contacts, pts.size());
  float max_diff = 0.0f, max_excess = 0.0f, max_ratio = 1.0f;
  for (size_t i = 0; i < pts.size(); ++i) {
    const Vec3 o = pts[i].head<3>();
    const float dr = (radial[i].head<3>() - o).norm();
    const float de = (exact[i].head<3>() - o).norm();
    EXPECT_LE(de, dr + 1e-6f);  // exact is never farther than radial
    max_diff = std::max(max_diff, (radial[i].head<3>() - exact[i].head<3>()).norm());
    max_excess = std::max(max_excess, dr - de);
    if (de > 1e-3f) max_ratio = std::max(max_ratio, dr / de);
    EXPECT_LE(depthInside(e, exact[i].head<3>()), 1e-5f);
    EXPECT_LE(depthInside(e, radial[i].head<3>()), 1e-5f);
  }
  std::printf("[ radial   ] 3:1 ellipsoid (4 x 12 x 4 cm), 20k points inside: max |radial - exact| = %.1f mm, "
              "radial push up to %.1f mm (x%.2f) longer than the exact one\n",
              max_diff * 1e3f, max_excess * 1e3f, max_ratio);
  EXPECT_GT(max_diff, 1e-3f);  // the two responses really differ on an elongated ellipsoid
}

TEST(Collider, MarginInflationClearance) {
  // Every point of the inflated surface (radii + m) is e∘u + m·u for a unit u, so its distance
  // to the original ellipsoid is at most m; it is at least m·(u·n) >= m·2√(ab)/(a+b) (supporting
  // plane). Measure the real minimum for growing elongation.
  const float m = 0.004f;
  for (float ratio : {1.0f, 3.0f, 10.0f, 100.0f}) {
    const Vec3 r(0.04f * ratio, 0.04f, 0.04f);
    float lo = std::numeric_limits<float>::infinity(), hi = 0.0f;
    for (int i = 0; i <= 2000; ++i) {
      const float th = kPi * static_cast<float>(i) / 2000.0f;
      const Vec3 uvec(std::cos(th), std::sin(th), 0.0f);
      const Vec3 s = (r + Vec3::Constant(m)).cwiseProduct(uvec);
      float d = 0.0f;
      closestPointOnEllipsoid(r, s, &d);
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
    const float bound = 2.0f * std::sqrt(r.x() * r.y()) / (r.x() + r.y());
    std::printf("[ margin   ] %5.0f:1 ellipsoid, margin 4 mm: clearance of the inflated surface %.2f .. %.2f mm "
                "(plane bound %.2f mm)\n", ratio, lo * 1e3f, hi * 1e3f, bound * m * 1e3f);
    EXPECT_LE(hi, m * 1.0001f);
    EXPECT_GE(lo, bound * m * 0.999f);
  }
}

struct Motion {
  // Centre on a circle, rotation about a tilted axis.
  Ellipsoid at(float t) const {
    const Vec3 c(0.3f * std::cos(6.0f * t), 1.0f + 0.1f * std::sin(3.0f * t), 0.3f * std::sin(6.0f * t));
    const Mat3 R = Eigen::AngleAxisf(4.0f * t, Vec3(0.3f, 1.0f, 0.2f).normalized()).toRotationMatrix();
    return makeEllipsoid(c, Vec3(0.06f, 0.15f, 0.05f), R);
  }
};

TEST(Collider, PressedParticlesNeverEndInsideMovingEllipsoid) {
  const float dt = 1.0f / 240.0f;
  const Motion motion;
  for (int response = 0; response < 2; ++response) {
    for (int cont = 0; cont < 2; ++cont) {
      CollisionParams p;
      p.response = static_cast<ContactResponse>(response);
      p.continuous = cont != 0;
      Particles ps;
      std::mt19937 rng(17);
      std::uniform_real_distribution<float> u(-1.0f, 1.0f);
      const Ellipsoid e0 = motion.at(0.0f);
      // Under the sanitizers 100 of the 300 particles (the first of the same sequence) through the
      // whole motion: each particle collides on its own, so the others repeat the same code at
      // other places on the ellipsoid; the contact bound below is per particle.
      const int count = test::repeatsUnderSanitizers(300, 3);
      for (int i = 0; i < count; ++i) {
        const Vec3 d = test::draw3(u, rng).normalized();
        ps.add(e0.fromUnit(d * 1.3f));
      }
      EllipsoidCollider col;
      float worst = 0.0f;
      uint32_t contacts = 0;
      std::vector<Vec3> accel(ps.x.size());
      for (int s = 0; s < 960; ++s) {
        const Ellipsoid a = motion.at(static_cast<float>(s) * dt), b = motion.at(static_cast<float>(s + 1) * dt);
        col.setEllipsoids(&a, &b, 1);
        for (size_t i = 0; i < ps.x.size(); ++i) {  // pulled hard towards the centre
          accel[i] = (a.centre - ps.x[i].head<3>()).normalized() * 40.0f;
        }
        contacts += ps.step(col, Vec3::Zero(), dt, p, &accel).contacts;
        worst = std::max(worst, maxDepth(col, ps.x));
      }
      SCOPED_TRACE(::testing::Message() << "response " << response << " continuous " << cont);
      EXPECT_GT(contacts, 100000u * static_cast<uint32_t>(count) / 300u);  // 100 000 for 300 particles
      EXPECT_LE(worst, EllipsoidCollider::kPenetrationTolerance);
      for (const Vec4& x : ps.x) ASSERT_TRUE(x.allFinite());
    }
  }
}

// Random clusters of overlapping ellipsoids (armpit-like junctions): the guarantee holds after
// one collide() however the particle starts.
TEST(Collider, OverlapsResolvedWithinTolerance) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), r01(0.0f, 1.0f);
  uint32_t escapes = 0, particles = 0;
  for (int scene = 0; scene < 20; ++scene) {
    std::vector<Ellipsoid> es;
    for (int k = 0; k < 12; ++k) {
      const Quat q(test::draw4(u, rng).normalized());
      const Vec3 centre = test::draw3(u, rng) * 0.08f;
      const float rx = 0.02f + 0.08f * r01(rng);
      const float ry = 0.02f + 0.08f * r01(rng);
      const float rz = 0.01f + 0.05f * r01(rng);
      es.push_back(makeEllipsoid(centre, Vec3(rx, ry, rz), q.toRotationMatrix()));
    }
    EllipsoidCollider col;
    col.setEllipsoids(es.data(), es.data(), static_cast<int>(es.size()));
    for (int response = 0; response < 2; ++response) {
      std::vector<Vec4> x;
      for (int i = 0; i < 2000; ++i) {
        const Vec3 at = test::draw3(u, rng) * 0.15f;
        x.emplace_back(at.x(), at.y(), at.z(), 1.0f);
      }
      std::vector<Vec4> prev = x;
      CollisionParams p;
      p.response = static_cast<ContactResponse>(response);
      const CollisionStats st = col.collide(x.data(), prev.data(), x.size(), p);
      escapes += st.escapes;
      particles += static_cast<uint32_t>(x.size());
      EXPECT_LE(maxDepth(col, x), EllipsoidCollider::kPenetrationTolerance);
    }
  }
  std::printf("[ overlaps ] 12 overlapping ellipsoids x 20 scenes: %u of %u particles needed the escape step\n",
              escapes, particles);
}

// A large flat ellipsoid tilted by alpha is locally a plane: Coulomb's law says a resting
// particle stays iff tan(alpha) < mu_s.
float slideDistance(float alpha, ContactResponse response, float mu_s, float mu_k) {
  const Mat3 R = Eigen::AngleAxisf(alpha, Vec3::UnitZ()).toRotationMatrix();
  const Ellipsoid plane = makeEllipsoid(Vec3(0, 0, 0), Vec3(4.0f, 0.4f, 4.0f), R);
  EllipsoidCollider col;
  col.setEllipsoids(&plane, &plane, 1);
  const Vec3 start = plane.centre + R * Vec3(0.0f, 0.4f + col.margin(), 0.0f);
  Particles ps;
  ps.add(start);
  CollisionParams p;
  p.response = response;
  p.static_friction = mu_s;
  p.kinetic_friction = mu_k;
  const float dt = 1.0f / 240.0f;
  for (int s = 0; s < 240; ++s) ps.step(col, Vec3(0.0f, -9.81f, 0.0f), dt, p);
  return (ps.x[0].head<3>() - start).norm();
}

TEST(Collider, FrictionHoldsBelowFrictionAngleSlidesAbove) {
  for (int response = 0; response < 2; ++response) {
    const ContactResponse r = static_cast<ContactResponse>(response);
    const float held = slideDistance(std::atan(0.5f), r, 0.6f, 0.4f);  // tan = 0.5 < 0.6
    const float near = slideDistance(std::atan(0.58f), r, 0.6f, 0.4f);
    const float slid = slideDistance(std::atan(0.7f), r, 0.6f, 0.4f);  // tan = 0.7 > 0.6
    const float frictionless = slideDistance(std::atan(0.1f), r, 0.0f, 0.0f);
    std::printf("[ friction ] %s: 1 s at 240 substeps on a slope, mu_s 0.6 mu_k 0.4: tan 0.50 -> %.3f mm, "
                "tan 0.58 -> %.3f mm, tan 0.70 -> %.0f mm; frictionless tan 0.10 -> %.0f mm\n",
                response ? "exact " : "radial", held * 1e3f, near * 1e3f, slid * 1e3f, frictionless * 1e3f);
    EXPECT_LT(held, 1e-3f);
    EXPECT_LT(near, 1e-3f);
    // Kinetic: a = g (sin - mu_k cos) = 0.85 m/s^2 -> ~0.42 m in 1 s.
    EXPECT_GT(slid, 0.3f);
    EXPECT_GT(frictionless, 0.3f);
  }
}

TEST(Collider, StaticFrictionCarriesRestingParticle) {
  // A ball moving sideways at 0.3 m/s under a resting particle: friction accelerates it at up
  // to mu_k g, then it rides along (static) — a sleeve does not slide off a moving arm.
  const float dt = 1.0f / 240.0f, v = 0.3f, radius = 0.1f;
  for (int response = 0; response < 2; ++response) {
    for (float mu : {0.6f, 0.0f}) {
      Particles ps;
      EllipsoidCollider col;
      CollisionParams p;
      p.response = static_cast<ContactResponse>(response);
      p.static_friction = mu;
      p.kinetic_friction = mu * (0.4f / 0.6f);
      ps.add(Vec3(0.0f, radius + col.margin(), 0.0f));
      float x_half = 0.0f;
      for (int s = 0; s < 240; ++s) {
        const Ellipsoid a = makeEllipsoid(Vec3(v * static_cast<float>(s) * dt, 0, 0), Vec3::Constant(radius));
        const Ellipsoid b = makeEllipsoid(Vec3(v * static_cast<float>(s + 1) * dt, 0, 0), Vec3::Constant(radius));
        col.setEllipsoids(&a, &b, 1);
        ps.step(col, Vec3(0.0f, -9.81f, 0.0f), dt, p);
        if (s == 119) x_half = ps.x[0].x();
      }
      const Vec3 end = ps.x[0].head<3>();
      std::printf("[ carry    ] %s mu_s %.1f: ball moved 300 mm, particle %.1f mm (last 0.5 s: %.2f mm vs 150)\n",
                  response ? "exact " : "radial", mu, end.x() * 1e3f, (end.x() - x_half) * 1e3f);
      if (mu > 0.0f) {
        EXPECT_NEAR(end.x() - x_half, 0.5f * v, 1e-3f);  // rides with the ball
        EXPECT_GT(end.y(), radius * 0.95f);               // still on top
      } else {
        EXPECT_LT(end.x(), 0.15f);  // without friction the ball slides out from under it
      }
    }
  }
}

// A forearm-sized ellipsoid swept at 7 m/s (along +z) through a resting particle, 30 fps x 4
// substeps: 5.8 cm per substep, more than the 4 cm radius. Returns in how many of 20 phases
// (the ellipsoid's offset at the first substep) the particle passes through the ellipsoid: its
// path relative to the ellipsoid crosses the ellipsoid's middle plane well inside the
// cross-section. Going round the side (a glancing hit deflects a free particle) is not tunnelling.
int tunnelledPhases(bool continuous, ContactResponse response, float radius, float lateral,
                    uint32_t* catches) {
  const float dt = 1.0f / 120.0f, v = 7.0f;
  int tunnelled = 0;
  for (int phase = 0; phase < 20; ++phase) {
    const float z0 = -0.4f + v * dt * static_cast<float>(phase) / 20.0f;
    Particles ps;
    ps.add(Vec3(lateral, 0.02f, 0.0f));
    EllipsoidCollider col;
    CollisionParams p;
    p.continuous = continuous;
    p.response = response;
    const Vec3 radii(radius, 0.13f, radius);
    bool through = false;
    for (int s = 0; s < 14; ++s) {
      const Ellipsoid a = makeEllipsoid(Vec3(0, 0, z0 + v * dt * static_cast<float>(s)), radii);
      const Ellipsoid b = makeEllipsoid(Vec3(0, 0, z0 + v * dt * static_cast<float>(s + 1)), radii);
      col.setEllipsoids(&a, &b, 1);
      const Vec3 rel0 = ps.x[0].head<3>() - a.centre;
      const CollisionStats st = ps.step(col, Vec3::Zero(), dt, p);
      const Vec3 rel1 = ps.x[0].head<3>() - b.centre;
      if (catches) *catches += st.swept_catches;
      EXPECT_TRUE(ps.x[0].allFinite());
      if (rel0.z() > 0.0f && rel1.z() <= 0.0f) {
        const Vec3 at = rel0 + (rel0.z() / (rel0.z() - rel1.z())) * (rel1 - rel0);
        const Vec3 r = radii + Vec3::Constant(col.margin());
        // Through the inner three quarters of the cross-section (a chord between two points on
        // the surface of a particle sliding round the side cuts slightly inside).
        if (Vec3(at.x() / r.x(), at.y() / r.y(), 0.0f).norm() < 0.75f) through = true;
      }
    }
    if (through) ++tunnelled;
  }
  return tunnelled;
}

TEST(Collider, ContinuousStopsTunnelling) {
  for (int response = 0; response < 2; ++response) {
    const ContactResponse r = static_cast<ContactResponse>(response);
    for (float radius : {0.04f, 0.015f}) {
      for (float lateral : {0.0f, 0.5f * radius}) {
        uint32_t catches = 0;
        const int with = tunnelledPhases(true, r, radius, lateral, &catches);
        const int without = tunnelledPhases(false, r, radius, lateral, nullptr);
        std::printf("[ sweep    ] %s radius %2.0f mm, particle %4.1f mm off axis, 7 m/s at 120 Hz: passed through in "
                    "%2d/20 phases without the swept test, %d/20 with it (%u swept catches)\n",
                    response ? "exact " : "radial", radius * 1e3f, lateral * 1e3f, without, with, catches);
        EXPECT_EQ(with, 0);
        EXPECT_GT(without, 0);
        EXPECT_GT(catches, 0u);
      }
    }
  }
}

// Pure translation: the unit-space path of a resting particle is exactly linear, so the swept
// catch puts it where the surface met it. Head-on at 0.4 m per substep into a 5 cm ball: the
// particle ends at the ball's front pole (the remaining motion is all normal, nothing to slide).
TEST(Collider, SweptCatchIsExactForTranslation) {
  const Ellipsoid a = makeEllipsoid(Vec3(0.0f, 0.0f, -0.2f), Vec3::Constant(0.05f));
  const Ellipsoid b = makeEllipsoid(Vec3(0.0f, 0.0f, 0.2f), Vec3::Constant(0.05f));
  EllipsoidCollider col;
  col.setEllipsoids(&a, &b, 1);
  for (int response = 0; response < 2; ++response) {
    CollisionParams p;
    p.response = static_cast<ContactResponse>(response);
    p.static_friction = p.kinetic_friction = 0.0f;
    std::vector<Vec4> x = {Vec4(0.0f, 0.0f, 0.0f, 1.0f)};
    const std::vector<Vec4> prev = x;
    const CollisionStats st = col.collide(x.data(), prev.data(), 1, p);
    EXPECT_EQ(st.swept_catches, 1u);
    EXPECT_NEAR((x[0].head<3>() - Vec3(0.0f, 0.0f, 0.2f + 0.05f + col.margin())).norm(), 0.0f, 1e-6f);
  }
}

// Rotation: the unit-space path of a resting point is an arc, which the swept test replaces by
// its chord (exact for translation, off by the sagitta |q| (1 - cos(phi/2)) for a rotation phi
// per substep). A forearm swinging about the elbow at 40 rad/s (hand ~10 m/s, 0.33 rad per
// substep at 120 Hz) through resting particles: none passes through it with the swept test.
int swingThroughs(bool continuous, int* flung) {
  const float dt = 1.0f / 120.0f, omega = 40.0f, half = 0.13f;
  auto pose = [&](float phi) {
    const Mat3 R = Eigen::AngleAxisf(phi, Vec3::UnitZ()).toRotationMatrix();
    return makeEllipsoid(R * Vec3(0.0f, half, 0.0f), Vec3(0.04f, half, 0.04f), R);
  };
  Particles ps;
  for (int i = 0; i < 12; ++i) {  // ahead of the bone (which starts along +y, turning to -x)
    const float rho = 0.04f + 0.018f * static_cast<float>(i), ang = 0.5f + 0.1f * static_cast<float>(i % 4);
    ps.add(Vec3(-rho * std::sin(ang), rho * std::cos(ang), 0.005f * static_cast<float>(i % 3)));
  }
  EllipsoidCollider col;
  CollisionParams p;
  p.continuous = continuous;
  int throughs = 0;
  std::vector<bool> counted(ps.x.size(), false);
  for (int s = 0; s < 12; ++s) {
    const float phi0 = omega * dt * static_cast<float>(s), phi1 = omega * dt * static_cast<float>(s + 1);
    const Ellipsoid a = pose(phi0), b = pose(phi1);
    col.setEllipsoids(&a, &b, 1);
    std::vector<Vec3> before(ps.x.size());
    for (size_t i = 0; i < ps.x.size(); ++i) before[i] = ps.x[i].head<3>();
    ps.step(col, Vec3::Zero(), dt, p);
    for (size_t i = 0; i < ps.x.size(); ++i) {
      // Particle in the bone's frame (y along the bone from the elbow, -x = the way it swings)
      // at the substep's start and end; a pass-through crosses x = 0 well inside the limb.
      const Vec3 l0 = Eigen::AngleAxisf(-phi0, Vec3::UnitZ()).toRotationMatrix() * before[i];
      const Vec3 l1 = Eigen::AngleAxisf(-phi1, Vec3::UnitZ()).toRotationMatrix() * ps.x[i].head<3>();
      if (l0.x() < 0.0f && l1.x() >= 0.0f && !counted[i]) {
        const Vec3 at = l0 + (l0.x() / (l0.x() - l1.x())) * (l1 - l0);
        const float m = col.margin();
        const Vec3 u((at.y() - half) / (half + m), at.z() / (0.04f + m), 0.0f);
        if (u.norm() < 0.75f) {
          counted[i] = true;
          ++throughs;
        }
      }
    }
  }
  if (flung) {
    *flung = 0;
    for (const Vec4& x : ps.x) *flung += x.head<2>().norm() > 2.0f * half + 0.05f;
  }
  return throughs;
}

TEST(Collider, SweptTestHandlesRotation) {
  int flung = 0;
  const int with = swingThroughs(true, &flung);
  const int without = swingThroughs(false, nullptr);
  std::printf("[ swing    ] forearm at 40 rad/s through 12 resting particles, 120 Hz: %d pass through without the "
              "swept test, %d with it (%d flung off the hand end)\n", without, with, flung);
  EXPECT_EQ(with, 0);
  EXPECT_GT(without, 0);
}

// A body-like random scene: ellipsoids moving between start and end, particles scattered with
// random motion. Broad phase on and off must agree bit for bit.
struct Scene {
  std::vector<Ellipsoid> start, end;
  std::vector<Vec4> x, prev;
};

Scene randomScene(int ellipsoids, int particles, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), r01(0.0f, 1.0f);
  Scene s;
  for (int k = 0; k < ellipsoids; ++k) {
    const Quat q(test::draw4(u, rng).normalized());
    const float cx = 0.6f * u(rng);
    const float cy = 0.9f + 0.8f * u(rng);
    const float cz = 0.15f * u(rng);
    const Vec3 c(cx, cy, cz);
    const float rx = 0.02f + 0.1f * r01(rng);
    const float ry = 0.02f + 0.2f * r01(rng);
    const float rz = 0.02f + 0.1f * r01(rng);
    const Vec3 radii(rx, ry, rz);
    s.start.push_back(makeEllipsoid(c, radii, q.toRotationMatrix()));
    const float turn = 0.2f * u(rng);
    const Vec3 axis = test::draw3(u, rng).normalized();
    const Quat dq(Eigen::AngleAxisf(turn, axis));
    s.end.push_back(makeEllipsoid(c + test::draw3(u, rng) * 0.03f, radii, (dq * q).toRotationMatrix()));
  }
  for (int i = 0; i < particles; ++i) {
    const float px = 0.8f * u(rng);
    const float py = 0.9f + 1.0f * u(rng);
    const float pz = 0.25f * u(rng);
    const Vec3 p(px, py, pz);
    const float speed = r01(rng) < 0.1f ? 0.2f : 0.01f;  // a few fast ones for the swept test
    const Vec3 p0 = p + test::draw3(u, rng) * speed;
    s.x.emplace_back(p.x(), p.y(), p.z(), r01(rng) < 0.05f ? 0.0f : 1.0f);
    s.prev.emplace_back(p0.x(), p0.y(), p0.z(), 1.0f);
  }
  return s;
}

TEST(Collider, BroadPhaseOnOffIdentical) {
  for (int n : {40, 100, 130, 300}) {
    const Scene s = randomScene(n, test::repeatsUnderSanitizers(5000, 4), 100u + static_cast<unsigned>(n));
    EllipsoidCollider col;
    col.setEllipsoids(s.start.data(), s.end.data(), n);
    for (int response = 0; response < 2; ++response) {
      for (int cont = 0; cont < 2; ++cont) {
        CollisionParams p;
        p.response = static_cast<ContactResponse>(response);
        p.continuous = cont != 0;
        std::vector<Vec4> a = s.x, b = s.x;
        p.broad_phase = true;
        const CollisionStats sa = col.collide(a.data(), s.prev.data(), a.size(), p);
        p.broad_phase = false;
        const CollisionStats sb = col.collide(b.data(), s.prev.data(), b.size(), p);
        SCOPED_TRACE(::testing::Message() << n << " ellipsoids, response " << response << " continuous " << cont);
        EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec4)), 0);
        EXPECT_EQ(sa.tests, sb.tests);
        EXPECT_EQ(sa.contacts, sb.contacts);
        EXPECT_EQ(sa.swept_catches, sb.swept_catches);
        EXPECT_GT(sa.contacts, static_cast<uint32_t>(s.x.size()) / 50);  // 100 of 5 000
        if (cont) {
          EXPECT_GT(sa.swept_catches, 0u);
        }
        EXPECT_LE(maxDepth(col, a), EllipsoidCollider::kPenetrationTolerance);
      }
    }
  }
}

// Pass 0 for eight particles at once (CollisionParams::batch8, AVX) and for sixteen (batch16,
// AVX-512F) against one at a time: the same positions and counters bit for bit, with and without
// collision groups, the swept test, a start position, the broad phase; lanes with a non-finite
// start position, pinned or NaN particles and particles far from everything mixed in. 4 011
// particles: 250 batches of sixteen, then one of eight and three one at a time.
TEST(Collider, BatchesMatchOneAtATimeBitForBit) {
  // 40, 130 and 250 ellipsoids: one, three and four bitmask words per grid cell; the 40 also
  // scaled 10x (radii up to 2.2 m: the exact response's Newton iteration then needs its w lane).
  for (int n : {40, 130, 250, -40}) {
    Scene s = randomScene(std::abs(n), test::repeatsUnderSanitizers(4011, 4), 700u + static_cast<unsigned>(std::abs(n)));
    if (n < 0) {
      for (std::vector<Ellipsoid>* es : {&s.start, &s.end}) {
        for (Ellipsoid& e : *es) {
          e.centre *= 10.0f;
          e.radii *= 10.0f;
          e.refresh();
        }
      }
      for (std::vector<Vec4>* xs : {&s.x, &s.prev})
        for (Vec4& x : *xs) x.head<3>() *= 10.0f;
      n = -n;
    }
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (size_t i = 0; i < s.x.size(); i += 37) s.prev[i].x() = nan;      // no start position
    for (size_t i = 5; i < s.x.size(); i += 41) s.x[i].y() = nan;         // skipped
    for (size_t i = 9; i < s.x.size(); i += 43) s.x[i].head<3>() += Vec3(5.0f, 0.0f, 0.0f);  // far
    const float inf = std::numeric_limits<float>::infinity();
    for (size_t i = 13; i < s.x.size(); i += 47) s.x[i].z() = inf;       // skipped (the lane test)
    for (size_t i = 17; i < s.x.size(); i += 53) s.prev[i].z() = -inf;   // no start position
    std::vector<uint8_t> groups(static_cast<size_t>(n)), masks(s.x.size());
    for (size_t k = 0; k < groups.size(); ++k) groups[k] = static_cast<uint8_t>(1u << (k % 5));
    for (size_t i = 0; i < masks.size(); ++i) masks[i] = static_cast<uint8_t>((i / 6) % 3 == 0 ? 0x03 : 0x1C);
    for (int grouped = 0; grouped < 2; ++grouped) {
      EllipsoidCollider col;
      col.setEllipsoids(s.start.data(), s.end.data(), n);
      if (grouped) col.setGroups(groups, masks.data());
      for (int variant = 0; variant < 8; ++variant) {
        CollisionParams p;
        p.response = static_cast<ContactResponse>(variant & 1);
        p.continuous = (variant & 2) != 0;
        p.broad_phase = (variant & 4) != 0;
        const bool with_prev = variant != 6;
        p.batch8 = false;
        std::vector<Vec4> b = s.x;
        const CollisionStats sb = col.collide(b.data(), with_prev ? s.prev.data() : nullptr, b.size(), p);
        // Eight lanes (batch16 off), then sixteen (batch16 on: eight lanes where the CPU lacks
        // AVX-512F, and the last count % 16 particles in a batch of eight and one at a time).
        for (bool sixteen : {false, true}) {
          p.batch8 = true;
          p.batch16 = sixteen;
          std::vector<Vec4> a = s.x;
          const CollisionStats sa = col.collide(a.data(), with_prev ? s.prev.data() : nullptr, a.size(), p);
          SCOPED_TRACE(::testing::Message() << n << " ellipsoids, grouped " << grouped << " variant " << variant
                                            << (sixteen ? ", sixteen lanes" : ", eight lanes"));
          EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec4)), 0);
          EXPECT_EQ(sa.tests, sb.tests);
          EXPECT_EQ(sa.contacts, sb.contacts);
          EXPECT_EQ(sa.swept_catches, sb.swept_catches);
          EXPECT_EQ(sa.escapes, sb.escapes);
          EXPECT_GT(sa.contacts, static_cast<uint32_t>(s.x.size()) / 100);
        }
      }
    }
  }
}

// Pass 0's batches skip the swept test for a candidate whose lanes are all outside at the end and
// too far out for their paths to have crossed it (Quick::sweep_keep2, a bound on the path's length
// in unit space): every crossing must still be caught. Particles thrown through the ellipsoids
// (up to 0.4 m per span), ellipsoids turning up to 1.5 rad and moving 5 cm: the batches answer
// as one particle at a time, bit for bit, swept catches included.
TEST(Collider, SweptRejectionKeepsEveryCrossing) {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    Scene s = randomScene(60, test::repeatsUnderSanitizers(4000, 4), 900u + seed);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), r01(0.0f, 1.0f);
    for (size_t k = 0; k < s.end.size(); ++k) {
      const Quat dq(Eigen::AngleAxisf(1.5f * u(rng), test::draw3(u, rng).normalized()));
      s.end[k] = makeEllipsoid(s.start[k].centre + 0.05f * test::draw3(u, rng), s.start[k].radii,
                               (dq * Quat(s.start[k].rotation)).toRotationMatrix());
    }
    for (size_t i = 0; i < s.x.size(); ++i) {
      const float reach = r01(rng) < 0.5f ? 0.4f : 0.03f;
      s.prev[i].head<3>() = Vec3(s.x[i].head<3>()) + reach * test::draw3(u, rng);
    }
    EllipsoidCollider col;
    col.setEllipsoids(s.start.data(), s.end.data(), static_cast<int>(s.start.size()));
    for (int response = 0; response < 2; ++response) {
      CollisionParams p;
      p.continuous = true;
      p.response = static_cast<ContactResponse>(response);
      p.batch8 = false;
      std::vector<Vec4> one = s.x;
      const CollisionStats s1 = col.collide(one.data(), s.prev.data(), one.size(), p);
      p.batch8 = true;
      p.batch16 = true;
      std::vector<Vec4> batched = s.x;
      const CollisionStats sb = col.collide(batched.data(), s.prev.data(), batched.size(), p);
      SCOPED_TRACE(::testing::Message() << "seed " << seed << ", response " << response);
      EXPECT_EQ(std::memcmp(one.data(), batched.data(), one.size() * sizeof(Vec4)), 0);
      EXPECT_EQ(s1.swept_catches, sb.swept_catches);
      EXPECT_EQ(s1.contacts, sb.contacts);
      EXPECT_EQ(s1.tests, sb.tests);
      EXPECT_GT(s1.swept_catches, static_cast<uint32_t>(s.x.size()) / 200);
    }
  }
}

// setEllipsoids reuses the previous call's end frame for a start ellipsoid equal to it (the
// usual case between substeps): the collider must answer exactly as one given the same pair
// fresh, and must not reuse anything when the ellipsoid or the margin differs.
TEST(Collider, ReusedStartFrameAnswersAsAFreshCollider) {
  const Scene s = randomScene(40, test::repeatsUnderSanitizers(3000, 4), 77);
  std::vector<Ellipsoid> later = s.end;
  for (Ellipsoid& e : later) e.centre += Vec3(0.01f, -0.02f, 0.005f);
  CollisionParams p;
  auto run = [&](const EllipsoidCollider& col) {
    std::vector<Vec4> x = s.x;
    const CollisionStats st = col.collide(x.data(), s.prev.data(), x.size(), p);
    return std::make_pair(x, st.contacts);
  };
  for (float margin : {0.004f, 0.01f}) {
    EllipsoidCollider carried, fresh;
    carried.setEllipsoids(s.start.data(), s.end.data(), 40);  // default margin
    carried.setEllipsoids(s.end.data(), later.data(), 40, margin);  // reuses only at the same margin
    fresh.setEllipsoids(s.end.data(), later.data(), 40, margin);
    const auto a = run(carried), b = run(fresh);
    SCOPED_TRACE(::testing::Message() << "margin " << margin);
    EXPECT_EQ(std::memcmp(a.first.data(), b.first.data(), a.first.size() * sizeof(Vec4)), 0);
    EXPECT_EQ(a.second, b.second);
    EXPECT_GT(a.second, 0u);
  }
  // A start that is not the previous end (every ellipsoid moved a little): built afresh.
  EllipsoidCollider carried, fresh;
  std::vector<Ellipsoid> other = s.end;
  for (Ellipsoid& e : other) e.radii *= 1.05f;
  carried.setEllipsoids(s.start.data(), s.end.data(), 40);
  carried.setEllipsoids(other.data(), later.data(), 40);
  fresh.setEllipsoids(other.data(), later.data(), 40);
  const auto a = run(carried), b = run(fresh);
  EXPECT_EQ(std::memcmp(a.first.data(), b.first.data(), a.first.size() * sizeof(Vec4)), 0);
  EXPECT_EQ(a.second, b.second);
}

TEST(Collider, ParticlesAreIndependent) {
  const Scene s = randomScene(40, 3000, 9);
  EllipsoidCollider col;
  col.setEllipsoids(s.start.data(), s.end.data(), 40);
  CollisionParams p;
  std::vector<Vec4> whole = s.x, parts = s.x;
  col.collide(whole.data(), s.prev.data(), whole.size(), p);
  for (size_t i = 0; i < parts.size(); i += 7) {
    col.collide(parts.data() + i, s.prev.data() + i, std::min<size_t>(7, parts.size() - i), p);
  }
  EXPECT_EQ(std::memcmp(whole.data(), parts.data(), whole.size() * sizeof(Vec4)), 0);
}

TEST(Collider, PinnedParticlesNeverMove) {
  const Scene s = randomScene(40, 3000, 31);
  EllipsoidCollider col;
  col.setEllipsoids(s.start.data(), s.end.data(), 40);
  std::vector<Vec4> x = s.x;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (size_t i = 0; i < x.size(); i += 3) x[i].w() = (i % 2) ? 0.0f : (i % 5 ? -1.0f : nan);
  const std::vector<Vec4> before = x;
  CollisionParams p;
  const CollisionStats st = col.collide(x.data(), s.prev.data(), x.size(), p);
  EXPECT_GT(st.contacts, 0u);
  for (size_t i = 0; i < x.size(); i += 3) {
    EXPECT_EQ(std::memcmp(&x[i], &before[i], sizeof(Vec4)), 0) << i;
  }
}

TEST(Collider, DegenerateInputsStayFinite) {
  const Ellipsoid sphere = makeEllipsoid(Vec3(0.1f, 1.0f, 0.0f), Vec3::Constant(0.05f));
  const Ellipsoid ell = makeEllipsoid(Vec3(-0.2f, 1.2f, 0.3f), Vec3(0.1f, 0.03f, 0.06f),
                                      Eigen::AngleAxisf(0.4f, Vec3::UnitX()).toRotationMatrix());
  for (const Ellipsoid& e : {sphere, ell}) {
    EllipsoidCollider col;
    col.setEllipsoids(&e, &e, 1);
    for (int response = 0; response < 2; ++response) {
      for (int cont = 0; cont < 2; ++cont) {
        CollisionParams p;
        p.response = static_cast<ContactResponse>(response);
        p.continuous = cont != 0;
        // Exactly at the centre, no motion.
        std::vector<Vec4> x = {Vec4(e.centre.x(), e.centre.y(), e.centre.z(), 1.0f)};
        std::vector<Vec4> prev = x;
        const CollisionStats st = col.collide(x.data(), prev.data(), 1, p);
        EXPECT_EQ(st.contacts, 1u);
        ASSERT_TRUE(x[0].allFinite());
        EXPECT_LE(depthInside(col.inflatedEnd(0), x[0].head<3>()), EllipsoidCollider::kPenetrationTolerance);
        // Pushed out along the smallest axis: the nearest exit.
        const float moved = (x[0].head<3>() - e.centre).norm();
        EXPECT_NEAR(moved, e.radii.minCoeff() + col.margin(), 1e-5f);
        // Resting exactly on the surface, no motion: nothing happens, nothing NaN.
        const Vec3 on = e.fromUnit(Vec3(0.0f, 1.0f, 0.0f) * ((e.radii.y() + col.margin()) / e.radii.y()));
        x = {Vec4(on.x(), on.y(), on.z(), 1.0f)};
        prev = x;
        col.collide(x.data(), prev.data(), 1, p);
        ASSERT_TRUE(x[0].allFinite());
        EXPECT_LT((x[0].head<3>() - on).norm(), 1e-5f);
        // No previous positions at all.
        x = {Vec4(e.centre.x(), e.centre.y(), e.centre.z(), 1.0f)};
        col.collide(x.data(), nullptr, 1, p);
        ASSERT_TRUE(x[0].allFinite());
      }
    }
  }
  // Non-finite particles are skipped and do not disturb the others; bad ellipsoids are ignored.
  Ellipsoid bad = sphere;
  bad.radii = Vec3(std::numeric_limits<float>::quiet_NaN(), 0.1f, 0.1f);
  bad.refresh();
  const Ellipsoid pair_start[2] = {bad, sphere}, pair_end[2] = {bad, sphere};
  EllipsoidCollider col;
  col.setEllipsoids(pair_start, pair_end, 2);
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<Vec4> x = {Vec4(inf, 0, 0, 1), Vec4(0.1f, 1.0f, 0.0f, 1.0f)};
  std::vector<Vec4> prev = {Vec4(0, 0, 0, 1), Vec4(std::numeric_limits<float>::quiet_NaN(), 0, 0, 1)};
  col.collide(x.data(), prev.data(), 2, CollisionParams{});
  EXPECT_EQ(x[0].x(), inf);
  ASSERT_TRUE(x[1].allFinite());
  EXPECT_LE(depthInside(col.inflatedEnd(1), x[1].head<3>()), EllipsoidCollider::kPenetrationTolerance);
  // Zero radius and zero margin: clamped, still finite.
  Ellipsoid flat = sphere;
  flat.radii = Vec3(0.05f, 0.0f, 0.05f);
  col.setEllipsoids(&flat, &flat, 1, 0.0f);
  x = {Vec4(0.1f, 1.0f, 0.0f, 1.0f)};
  col.collide(x.data(), x.data(), 1, CollisionParams{});
  ASSERT_TRUE(x[0].allFinite());
  // Nonsense parameters: NaN / infinite / negative friction, an unknown response value.
  col.setEllipsoids(&sphere, &sphere, 1);
  CollisionParams wild;
  wild.static_friction = std::numeric_limits<float>::quiet_NaN();
  wild.kinetic_friction = inf;
  wild.response = static_cast<ContactResponse>(7);
  x = {Vec4(0.1f, 1.0f, 0.0f, 1.0f), Vec4(0.1f, 1.03f, 0.0f, 1.0f)};
  prev = {Vec4(0.1f, 1.0f, 0.0f, 1.0f), Vec4(0.12f, 1.06f, 0.0f, 1.0f)};
  col.collide(x.data(), prev.data(), 2, wild);
  ASSERT_TRUE(x[0].allFinite());
  ASSERT_TRUE(x[1].allFinite());
  EXPECT_LE(depthInside(col.inflatedEnd(0), x[1].head<3>()), EllipsoidCollider::kPenetrationTolerance);
  wild.static_friction = -1.0f;
  col.collide(x.data(), prev.data(), 2, wild);
  ASSERT_TRUE(x[1].allFinite());
  // Empty collider.
  col.setEllipsoids(nullptr, nullptr, 0);
  EXPECT_EQ(col.collide(x.data(), nullptr, 1, CollisionParams{}).tests, 0u);
}

// Contacts with |q| in [lo, hi) of four ellipsoids (limb, flat torso ring, sphere, triaxial): the
// collider's exact response against the reference closest point.
void expectExactContactsMatchTheReference(float lo, float hi, const char* what);

TEST(Collider, ExactShallowContactsMatchTheReference) {
  // Contacts with |q| in [0.8, 1) take the float Newton path of the collider (the double solver
  // only as fallback); the result must be the reference closest point: same distance to 1e-5 of
  // the largest radius (on g++'s old sample the worst of 20 000 points was 1.2e-7 m; on this
  // sample one point of the 3 cm-thin ellipsoid is 7.9e-7 m off, 6.6e-6 of its 0.12 m radius, all
  // others under 1.2e-7 m; since the iteration stops at |F| < 1e-5 instead of 2e-6, the limb's
  // worst is 5.1e-7 m and the flat ring's 4.1e-7), on the surface, and never a longer push than
  // the radial one.
  expectExactContactsMatchTheReference(0.8f, 0.9999f, "shallow");
}

TEST(Collider, ExactDeeperContactsMatchTheReference) {
  // |q| in [0.5, 0.8): the float Newton path too since 2026-12-01 (the double solver before; 75
  // such contacts a frame on the default scene, each one particle at a time). The same bounds.
  expectExactContactsMatchTheReference(0.5f, 0.8f, "deeper");
}

void expectExactContactsMatchTheReference(float lo, float hi, const char* what) {
  const Ellipsoid shapes[] = {
      makeEllipsoid(Vec3(0.1f, 1.2f, 0.3f), Vec3(0.05f, 0.15f, 0.05f),
                    Eigen::AngleAxisf(0.4f, Vec3(1, 2, 0).normalized()).toRotationMatrix()),
      makeEllipsoid(Vec3(0.0f, 1.0f, 0.0f), Vec3(0.15f, 0.014f, 0.11f)),  // flat torso ring
      makeEllipsoid(Vec3(-0.2f, 0.5f, 0.1f), Vec3(0.08f, 0.08f, 0.08f)),   // sphere
      makeEllipsoid(Vec3(0.3f, 0.9f, -0.2f), Vec3(0.12f, 0.07f, 0.03f),
                    Eigen::AngleAxisf(1.1f, Vec3(0, 1, 1).normalized()).toRotationMatrix())};
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), depth(lo, hi);
  for (const Ellipsoid& e : shapes) {
    EllipsoidCollider col;
    col.setEllipsoids(&e, &e, 1, 0.0f);
    std::vector<Vec4> pts;
    while (pts.size() < 5000) {
      // Drawn one statement each: arguments of one call are evaluated in an order the compiler
      // picks (g++ right to left, clang left to right), which gave the two builds other samples.
      const float qx = u(rng), qy = u(rng), qz = u(rng);
      Vec3 q(qx, qy, qz);
      if (!(q.norm() > 0.1f)) continue;
      q *= depth(rng) / q.norm();
      pts.emplace_back(Vec4(0, 0, 0, 1));
      pts.back().head<3>() = e.fromUnit(q);
    }
    std::vector<Vec4> exact = pts;
    CollisionParams p;
    p.continuous = false;
    p.static_friction = p.kinetic_friction = 0.0f;
    p.response = ContactResponse::Exact;
    col.collide(exact.data(), nullptr, exact.size(), p);
    const float r_max = e.radii.maxCoeff();
    float worst = 0.0f;
    for (size_t i = 0; i < pts.size(); ++i) {
      const Vec3 o = pts[i].head<3>();
      float d_ref = 0.0f;
      closestPointOnEllipsoid(e.radii, e.rotation.transpose() * (o - e.centre), &d_ref);
      const float d = (exact[i].head<3>() - o).norm();
      worst = std::max(worst, std::fabs(d - d_ref));
      EXPECT_NEAR(d, d_ref, 1e-5f * r_max) << "point " << i;
      EXPECT_LE(depthInside(e, exact[i].head<3>()), 1e-5f);
    }
    std::printf("[ exact    ] radii %.3f %.3f %.3f: 5000 %s contacts, worst |d - d_ref| = %.2g m\n",
                e.radii.x(), e.radii.y(), e.radii.z(), what, worst);
  }
}

// A step of several collision spans keeps one grid (ColliderMotion's hold boxes): every span's
// contacts must be those of a collider given the span's ellipsoids by setEllipsoids (its own grid
// from its swept boxes), bit for bit, and the step must build one grid, not one per span. Turns
// up to 2.6 rad per step stress the hold boxes' rotation bound.
TEST(Collider, SpanGridKeptAcrossStepSameContacts) {
  for (unsigned seed = 1; seed <= 6; ++seed) {
    Scene s = randomScene(120, test::repeatsUnderSanitizers(3000, 4), 700u + seed);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (size_t k = 0; k < s.end.size(); ++k) {  // larger turns than randomScene's
      const Quat dq(Eigen::AngleAxisf(2.6f * u(rng), test::draw3(u, rng).normalized()));
      s.end[k] = makeEllipsoid(s.end[k].centre, s.end[k].radii, (dq * Quat(s.end[k].rotation)).toRotationMatrix());
    }
    const int count = static_cast<int>(s.start.size());
    for (int stride : {1, 2, 3}) {
      EllipsoidCollider held, direct;
      ColliderMotion motion;
      std::string error;
      ASSERT_TRUE(motion.set(&held, s.start.data(), s.end.data(), count, 0.004f, error)) << error;
      const int n = 10;
      std::vector<Ellipsoid> a = s.start, b(s.start.size());
      const uint64_t builds_before = held.gridBuilds();
      for (int s0 = 0; s0 < n; s0 += stride) {
        const int s1 = std::min(n, s0 + stride);
        ASSERT_EQ(motion.beginSpan(s0, s1, n), &held);
        const float t = s1 >= n ? 1.0f : static_cast<float>(s1) / static_cast<float>(n);
        for (int k = 0; k < count; ++k) b[k] = t == 1.0f ? s.end[k] : interpolateEllipsoidPose(s.start[k], s.end[k], t);
        direct.setEllipsoids(a.data(), b.data(), count, 0.004f);
        for (int cont = 0; cont < 2; ++cont) {
          CollisionParams p;
          p.continuous = cont != 0;
          std::vector<Vec4> x_held = s.x, x_direct = s.x;
          const CollisionStats st_held = held.collide(x_held.data(), s.prev.data(), x_held.size(), p);
          const CollisionStats st_direct = direct.collide(x_direct.data(), s.prev.data(), x_direct.size(), p);
          SCOPED_TRACE(::testing::Message() << "seed " << seed << ", stride " << stride << ", span " << s0 << "-" << s1
                                            << ", continuous " << cont);
          EXPECT_EQ(std::memcmp(x_held.data(), x_direct.data(), x_held.size() * sizeof(Vec4)), 0);
          EXPECT_EQ(st_held.tests, st_direct.tests);
          EXPECT_EQ(st_held.contacts, st_direct.contacts);
          EXPECT_EQ(st_held.swept_catches, st_direct.swept_catches);
          EXPECT_GT(st_held.contacts, 0u);
        }
        a = b;
      }
      EXPECT_EQ(held.gridBuilds() - builds_before, 1u) << "seed " << seed << ", stride " << stride;
    }
  }
}

// Hold boxes that do not hold a span's swept boxes (here: empty ones at the centres) are not
// trusted: that span builds its own grid and the contacts stay those of setEllipsoids.
TEST(Collider, SpanGridFromSweptBoxesWhenHoldBoxesDoNotHold) {
  const Scene s = randomScene(60, test::repeatsUnderSanitizers(3000, 4), 811u);
  const int count = static_cast<int>(s.start.size());
  std::vector<Vec3> lo(s.start.size()), hi(s.start.size());
  for (size_t k = 0; k < s.start.size(); ++k) lo[k] = hi[k] = s.start[k].centre;
  EllipsoidCollider held, direct;
  held.setSpanEllipsoids(s.start.data(), s.end.data(), count, 0.004f, lo.data(), hi.data());
  direct.setEllipsoids(s.start.data(), s.end.data(), count, 0.004f);
  held.setSpanEllipsoids(s.end.data(), s.end.data(), count, 0.004f, nullptr, nullptr);  // a second span
  direct.setEllipsoids(s.end.data(), s.end.data(), count, 0.004f);
  EXPECT_EQ(held.gridBuilds(), 2u);
  CollisionParams p;
  std::vector<Vec4> x_held = s.x, x_direct = s.x;
  const CollisionStats a = held.collide(x_held.data(), s.prev.data(), x_held.size(), p);
  const CollisionStats b = direct.collide(x_direct.data(), s.prev.data(), x_direct.size(), p);
  EXPECT_EQ(std::memcmp(x_held.data(), x_direct.data(), x_held.size() * sizeof(Vec4)), 0);
  EXPECT_EQ(a.contacts, b.contacts);
  EXPECT_GT(a.contacts, 0u);
}

}  // namespace
}  // namespace drape
