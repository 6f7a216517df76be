// Rim edges collided as edges (EllipsoidCollider::collideRims, proxies/collision_rims.cpp;
// GarmentTopology::rims; docs/collision.md, "Rim edges").
#include <gtest/gtest.h>

#include "cloth_grid.h"
#include "cloth/garment_topology.h"
#include "cloth/xpbd_solver.h"
#include "common/cpu.h"
#include "proxies/collision.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <set>
#include <tuple>
#include <vector>

namespace drape {
namespace {

Ellipsoid rimTestEllipsoid(const Vec3& centre, const Vec3& radii, const Mat3& rotation = Mat3::Identity()) {
  Ellipsoid e;
  e.centre = centre;
  e.radii = radii;
  e.rotation = rotation;
  e.refresh();
  return e;
}

// |q|^2 of edge (a, b)'s point nearest the centre in the unit space of `e` (radii + margin), and
// its parameter t along the edge: what collideRims tests.
float rimDepth2(const Ellipsoid& e, float margin, const Vec3& a, const Vec3& b, float* t_out = nullptr) {
  const Eigen::Array3f r = e.radii.array() + margin;
  const Vec3 q0 = (e.rotation.transpose() * (a - e.centre)).array() / r;
  const Vec3 q1 = (e.rotation.transpose() * (b - e.centre)).array() / r;
  const Vec3 d = q1 - q0;
  const float t = std::clamp(-q0.dot(d) / d.squaredNorm(), 0.0f, 1.0f);
  if (t_out) *t_out = t;
  return (q0 + t * d).squaredNorm();
}

struct RimCase {
  std::vector<Eigen::Vector4f> x;
  std::vector<uint32_t> a{0}, b{1};
};

RimCase twoParticles(const Vec3& p, const Vec3& q, float wa = 1.0f, float wb = 1.0f) {
  RimCase c;
  c.x = {Eigen::Vector4f(p.x(), p.y(), p.z(), wa), Eigen::Vector4f(q.x(), q.y(), q.z(), wb)};
  return c;
}

constexpr float kMargin = 0.004f;

TEST(CollideRims, AnEdgeAcrossALimbIsPushedOffItSideways) {
  // A 4 cm thick limb along z; an edge along x 1 cm above its axis, both ends 5 cm away: only the
  // edge's interior is inside (a limb between two cuff particles).
  const Ellipsoid limb = rimTestEllipsoid(Vec3::Zero(), Vec3(0.02f, 0.02f, 0.2f));
  EllipsoidCollider c;
  c.setEllipsoids(&limb, &limb, 1, kMargin);
  RimCase r = twoParticles(Vec3(-0.05f, 0.01f, 0.03f), Vec3(0.05f, 0.01f, 0.03f));
  ASSERT_LT(rimDepth2(limb, kMargin, r.x[0].head<3>(), r.x[1].head<3>()), 0.75f);
  CollisionStats st;
  EXPECT_EQ(c.collideRims(r.x.data(), r.x.size(), r.a.data(), r.b.data(), 1, CollisionParams{}, st), 1u);
  EXPECT_GE(st.contacts, 1u);
  const Vec3 a = r.x[0].head<3>(), b = r.x[1].head<3>();
  // Off the limb: the edge's deepest point on its surface (radii + margin), to float rounding.
  EXPECT_GT(rimDepth2(limb, kMargin, a, b), 0.999f);
  // Across the limb (up, the side the edge was on), not along it: z unchanged, x unchanged.
  EXPECT_NEAR(a.z(), 0.03f, 1e-6f);
  EXPECT_NEAR(b.z(), 0.03f, 1e-6f);
  EXPECT_NEAR(a.x(), -0.05f, 1e-6f);
  EXPECT_NEAR(b.x(), 0.05f, 1e-6f);
  EXPECT_GT(a.y(), 0.02f);
  EXPECT_NEAR(a.y(), b.y(), 1e-6f);  // symmetric: both ends moved alike
  EXPECT_FALSE(c.collideRims(r.x.data(), r.x.size(), r.a.data(), r.b.data(), 1, CollisionParams{}, st));
}

TEST(CollideRims, AShallowChordAndAnEdgeEndingInsideAreLeftToTheParticles) {
  const Ellipsoid ball = rimTestEllipsoid(Vec3::Zero(), Vec3(0.1f, 0.1f, 0.1f));
  EllipsoidCollider c;
  c.setEllipsoids(&ball, &ball, 1, kMargin);
  CollisionStats st;
  // A chord 0.95 of the radius from the centre: |q|^2 ~ 0.9, above the 0.75 threshold.
  RimCase shallow = twoParticles(Vec3(-0.2f, 0.0988f, 0.0f), Vec3(0.2f, 0.0988f, 0.0f));
  const RimCase before = shallow;
  EXPECT_EQ(c.collideRims(shallow.x.data(), 2, shallow.a.data(), shallow.b.data(), 1, CollisionParams{}, st), 0u);
  EXPECT_EQ(shallow.x, before.x);
  // An edge whose nearest point to the centre is its end (the end particle's own contact).
  RimCase ending = twoParticles(Vec3(0.0f, 0.0f, 0.0f), Vec3(0.3f, 0.0f, 0.0f));
  const RimCase before2 = ending;
  EXPECT_EQ(c.collideRims(ending.x.data(), 2, ending.a.data(), ending.b.data(), 1, CollisionParams{}, st), 0u);
  EXPECT_EQ(ending.x, before2.x);
}

TEST(CollideRims, APinnedEndStaysAndTheFreeEndTakesThePush) {
  const Ellipsoid limb = rimTestEllipsoid(Vec3::Zero(), Vec3(0.02f, 0.02f, 0.2f));
  EllipsoidCollider c;
  c.setEllipsoids(&limb, &limb, 1, kMargin);
  RimCase r = twoParticles(Vec3(-0.05f, 0.005f, 0.0f), Vec3(0.05f, 0.005f, 0.0f), 0.0f, 1.0f);
  CollisionStats st;
  EXPECT_EQ(c.collideRims(r.x.data(), 2, r.a.data(), r.b.data(), 1, CollisionParams{}, st), 1u);
  EXPECT_EQ(r.x[0], Eigen::Vector4f(-0.05f, 0.005f, 0.0f, 0.0f));
  EXPECT_GT(r.x[1].y(), 0.03f);  // the free end rose so far that the edge clears the limb
  float t = 0.0f;
  const float d2 = rimDepth2(limb, kMargin, r.x[0].head<3>(), r.x[1].head<3>(), &t);
  EXPECT_GE(d2, 0.75f);  // no longer deep across it (one projection: the edge tilted, its nearest point moved)
  // Both ends pinned: nothing can move.
  RimCase both = twoParticles(Vec3(-0.05f, 0.005f, 0.0f), Vec3(0.05f, 0.005f, 0.0f), 0.0f, 0.0f);
  const RimCase before = both;
  EXPECT_EQ(c.collideRims(both.x.data(), 2, both.a.data(), both.b.data(), 1, CollisionParams{}, st), 0u);
  EXPECT_EQ(both.x, before.x);
}

TEST(CollideRims, OnlyEllipsoidsBothEndsMayTouch) {
  const Ellipsoid limb = rimTestEllipsoid(Vec3::Zero(), Vec3(0.02f, 0.02f, 0.2f));
  EllipsoidCollider c;
  c.setEllipsoids(&limb, &limb, 1, kMargin);
  const std::vector<uint8_t> groups = {2};
  for (const auto& [ma, mb, moves] : {std::tuple<uint8_t, uint8_t, bool>{2, 2, true}, {2, 1, false}, {1, 1, false}}) {
    const std::vector<uint8_t> masks = {ma, mb};
    c.setGroups(groups, masks.data());
    RimCase r = twoParticles(Vec3(-0.05f, 0.005f, 0.0f), Vec3(0.05f, 0.005f, 0.0f));
    CollisionStats st;
    EXPECT_EQ(c.collideRims(r.x.data(), 2, r.a.data(), r.b.data(), 1, CollisionParams{}, st), moves ? 1u : 0u)
        << int(ma) << " " << int(mb);
  }
}

TEST(CollideRims, BadIndicesAndNonFiniteEndsAreSkipped) {
  const Ellipsoid limb = rimTestEllipsoid(Vec3::Zero(), Vec3(0.02f, 0.02f, 0.2f));
  EllipsoidCollider c;
  c.setEllipsoids(&limb, &limb, 1, kMargin);
  RimCase r = twoParticles(Vec3(-0.05f, 0.005f, 0.0f), Vec3(0.05f, 0.005f, 0.0f));
  const uint32_t far[] = {5}, self[] = {0};
  CollisionStats st;
  EXPECT_EQ(c.collideRims(r.x.data(), 2, r.a.data(), far, 1, CollisionParams{}, st), 0u);
  EXPECT_EQ(c.collideRims(r.x.data(), 2, self, self, 1, CollisionParams{}, st), 0u);
  EXPECT_EQ(c.collideRims(nullptr, 2, r.a.data(), r.b.data(), 1, CollisionParams{}, st), 0u);
  r.x[1].x() = NAN;
  EXPECT_EQ(c.collideRims(r.x.data(), 2, r.a.data(), r.b.data(), 1, CollisionParams{}, st), 0u);
  EXPECT_EQ(r.x[0], Eigen::Vector4f(-0.05f, 0.005f, 0.0f, 1.0f));
}

TEST(CollideRims, SixteenEdgesAtOnceMatchOneAtATimeBitForBit) {
  // The screen that answers sixteen rim edges at once where no candidate may push them
  // (rimScreenSixteen) against the scalar pass alone (batch16 off): positions bit for bit, the
  // edges pushed, the tests and contacts counted. Loops of rim edges through six ellipsoids of
  // four groups, ends at every depth (many pushed, many grazing near the push's threshold), mixed
  // masks, pinned, gated and non-finite ends, bad indices.
  if (!cpuHasAvx512()) GTEST_SKIP() << "this CPU has no AVX-512F: the screen never runs here";
  const Ellipsoid shapes[] = {
      rimTestEllipsoid(Vec3(0.0f, 0.0f, 0.0f), Vec3(0.03f, 0.03f, 0.2f)),
      rimTestEllipsoid(Vec3(0.1f, 0.05f, 0.1f), Vec3(0.06f, 0.04f, 0.05f),
                       Eigen::AngleAxisf(0.7f, Vec3(1, 1, 0).normalized()).toRotationMatrix()),
      rimTestEllipsoid(Vec3(-0.1f, 0.0f, -0.1f), Vec3(0.05f, 0.05f, 0.05f)),
      rimTestEllipsoid(Vec3(0.0f, -0.12f, 0.05f), Vec3(0.02f, 0.15f, 0.02f),
                       Eigen::AngleAxisf(0.3f, Vec3(0, 0, 1)).toRotationMatrix()),
      rimTestEllipsoid(Vec3(0.15f, -0.05f, -0.1f), Vec3(0.08f, 0.02f, 0.06f)),
      rimTestEllipsoid(Vec3(-0.05f, 0.1f, 0.15f), Vec3(0.04f, 0.04f, 0.12f),
                       Eigen::AngleAxisf(1.2f, Vec3(0, 1, 0)).toRotationMatrix())};
  const std::vector<uint8_t> groups = {1, 2, 1, 4, 8, 2};
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.25f, 0.25f), unit(0.0f, 1.0f);
  const size_t n = 600;
  std::vector<Eigen::Vector4f> x(n);
  std::vector<uint8_t> masks(n), gate(n);
  for (size_t i = 0; i < n; ++i) {
    const float px = u(rng), py = u(rng), pz = u(rng), w = unit(rng);
    x[i] = Eigen::Vector4f(px, py, pz, w < 0.1f ? 0.0f : w < 0.5f ? 0.5f : 1.0f);
    const float m = unit(rng);
    masks[i] = m < 0.05f ? 0 : m < 0.6f ? 0xFF : m < 0.8f ? 3 : m < 0.9f ? 6 : 9;
    gate[i] = unit(rng) < 0.95f ? 1 : 0;
  }
  x[17].y() = NAN;
  x[300].x() = std::numeric_limits<float>::infinity();
  // Rims: loops of 8 to 40 consecutive particles, closed, then a few bad edges.
  std::vector<uint32_t> a, b;
  for (uint32_t start = 0; start + 8 < n;) {
    const uint32_t len = 8 + static_cast<uint32_t>(unit(rng) * 32.0f);
    const uint32_t end = std::min<uint32_t>(start + len, static_cast<uint32_t>(n));
    for (uint32_t i = start; i < end; ++i) {
      a.push_back(i);
      b.push_back(i + 1 < end ? i + 1 : start);
    }
    start = end;
  }
  a.insert(a.begin() + 40, {5, 7, 9});
  b.insert(b.begin() + 40, {5, static_cast<uint32_t>(n) + 3, 10});
  for (const bool gated : {false, true}) {
    for (const bool grouped : {false, true}) {
      EllipsoidCollider c;
      c.setEllipsoids(shapes, shapes, 6, kMargin);
      if (grouped) c.setGroups(groups, masks.data());
      CollisionStats st[2];
      size_t pushed[2];
      std::vector<Eigen::Vector4f> out[2] = {x, x};
      for (int wide = 0; wide < 2; ++wide) {
        CollisionParams p;
        p.batch16 = wide == 1;
        pushed[wide] = c.collideRims(out[wide].data(), n, a.data(), b.data(), a.size(), p, st[wide],
                                     gated ? gate.data() : nullptr);
      }
      EXPECT_EQ(std::memcmp(out[0].data(), out[1].data(), n * sizeof(Eigen::Vector4f)), 0) << gated << grouped;
      EXPECT_EQ(pushed[0], pushed[1]);
      EXPECT_EQ(st[0].tests, st[1].tests);
      EXPECT_EQ(st[0].contacts, st[1].contacts);
      EXPECT_GT(pushed[0], 20u) << "the scene pushes edges";
      std::printf("[ rims     ] gated %d grouped %d: %zu edges, %zu pushed, %u tests\n", gated, grouped, a.size(),
                  pushed[0], st[0].tests);
    }
  }
}

TEST(GarmentTopologyRims, TheRimsAreTheBoundaryEdgesColouredApart) {
  test::ClothGrid g;
  g.nx = 7, g.ny = 5;
  const GarmentTopology t = test::clothGridTopology(g, TopologyParams{});
  // A rectangle's boundary loop: its perimeter's edges, each once.
  ASSERT_EQ(t.rims.size(), static_cast<size_t>(2 * (g.nx - 1) + 2 * (g.ny - 1)));
  std::set<std::pair<uint32_t, uint32_t>> edges;
  for (size_t k = 0; k < t.rims.size(); ++k) {
    const uint32_t a = t.rims.a[k], b = t.rims.b[k];
    EXPECT_TRUE(edges.insert({std::min(a, b), std::max(a, b)}).second);
    const auto onBorder = [&](uint32_t i) {
      const uint32_t x = i % g.nx, y = i / g.nx;
      return x == 0 || y == 0 || x == static_cast<uint32_t>(g.nx - 1) || y == static_cast<uint32_t>(g.ny - 1);
    };
    EXPECT_TRUE(onBorder(a) && onBorder(b)) << a << " " << b;
    EXPECT_NEAR(t.rims.rest[k], (t.rest_positions[a] - t.rest_positions[b]).norm(), 1e-6f);
  }
  // No two edges of a colour share a particle (the device runs a colour in parallel).
  for (size_t col = 0; col < t.rims.colours(); ++col) {
    std::set<uint32_t> used;
    for (uint32_t k = t.rims.colour_offsets[col]; k < t.rims.colour_offsets[col + 1]; ++k) {
      EXPECT_TRUE(used.insert(t.rims.a[k]).second);
      EXPECT_TRUE(used.insert(t.rims.b[k]).second);
    }
  }
}

// A hanging sheet, pinned along its top, and a thin rod (2 cm thick, upright in the sheet's
// plane, between two hem particles 9 cm apart) moving through the sheet's hem from behind: the
// particles alone let the rod pass through the cloth; with the rims the hem is caught on the rod
// and carried along, and no rim edge is left across it.
struct RodRun {
  float hem_carried = 0.0f;   // how far the hem's farthest particle went with the rod (z, metres)
  float deepest_rim2 = 1e9f;  // the smallest |q|^2 of a rim edge's interior in the rod, any frame
};

// gate: XpbdSolver::setRimGate's bytes (empty: every rim; a single 0: every byte 0, none).
RodRun rodThroughTheHem(bool rims, std::vector<uint8_t> gate = {}) {
  test::ClothGrid g;
  g.nx = 12, g.ny = 6;
  g.height = 0.5f;
  g.origin = Vec3(-0.5f, 0.0f, 0.0f);
  TopologyParams tp;
  for (uint32_t i = 0; i < static_cast<uint32_t>(g.nx); ++i) tp.pinned.push_back(i);  // the top row
  const GarmentTopology t = test::clothGridTopology(g, tp);
  XpbdParams p;
  p.collision.rims = rims;
  XpbdSolver s(t);
  std::string err;
  EXPECT_TRUE(s.setParams(p, err)) << err;
  if (gate.size() == 1) gate.assign(t.particleCount(), gate[0]);
  s.setRimGate(gate);
  EllipsoidCollider collider;
  const float x_mid = -0.5f + 5.5f / static_cast<float>(g.nx - 1);  // between hem particles 5 and 6
  const Vec3 radii(0.01f, 0.2f, 0.01f);
  RodRun run;
  const size_t hem0 = static_cast<size_t>(g.nx) * static_cast<size_t>(g.ny - 1);
  for (int f = 0; f < 20; ++f) {
    const float z0 = -0.1f + 0.015f * static_cast<float>(f), z1 = z0 + 0.015f;
    const Ellipsoid e0 = rimTestEllipsoid(Vec3(x_mid, -0.45f, z0), radii);
    const Ellipsoid e1 = rimTestEllipsoid(Vec3(x_mid, -0.45f, z1), radii);
    EXPECT_TRUE(s.setColliderMotion(&collider, &e0, &e1, 1, kMargin, err)) << err;
    EXPECT_TRUE(s.step(1.0f / 30.0f, 10));
    for (size_t k = 0; k < t.rims.size(); ++k) {
      float tt = 0.0f;
      const float d2 = rimDepth2(e1, kMargin, s.positions()[t.rims.a[k]].head<3>(), s.positions()[t.rims.b[k]].head<3>(), &tt);
      if (tt > 0.02f && tt < 0.98f) run.deepest_rim2 = std::min(run.deepest_rim2, d2);
    }
  }
  for (size_t i = hem0; i < t.particleCount(); ++i) run.hem_carried = std::max(run.hem_carried, s.positions()[i].z());
  return run;
}

TEST(CollideRims, AThinRodCatchesTheHemInsteadOfPassingThroughTheCloth) {
  const RodRun off = rodThroughTheHem(false), on = rodThroughTheHem(true);
  std::printf("[ figures  ] rod through the hem: rims off: hem carried %.3f m, deepest rim |q|^2 %.3f; rims on: %.3f m, %.3f\n",
              off.hem_carried, off.deepest_rim2, on.hem_carried, on.deepest_rim2);
  // Without rims the rod crosses the hem's edge deep and leaves the hem hanging where it was.
  EXPECT_LT(off.deepest_rim2, 0.5f);
  EXPECT_LT(off.hem_carried, 0.01f);
  // With them no rim edge is left deep across it after any step (the pass leaves an edge at
  // 0.75 or beyond; the moved ends collided again may tilt it a little), and the rod carries the hem.
  EXPECT_GE(on.deepest_rim2, 0.6f);
  EXPECT_GT(on.hem_carried, 0.1f);
  // The gate: every particle on is every rim; every particle off is no rim, the same run to the bit
  // as rims off (a rim keeps a limb in, not out: GarmentSim gates off the openings already off).
  const RodRun all = rodThroughTheHem(true, {1}), none = rodThroughTheHem(true, {0});
  EXPECT_EQ(all.hem_carried, on.hem_carried);
  EXPECT_EQ(none.hem_carried, off.hem_carried);
  EXPECT_EQ(none.deepest_rim2, off.deepest_rim2);
}

}  // namespace
}  // namespace drape
