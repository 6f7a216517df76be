// Each OpenCL kernel on its own against the CPU function it mirrors (docs/opencl.md): the
// collision kernel against EllipsoidCollider::collide (moving ellipsoids, swept test, friction,
// groups, overlaps that need the escape step, both responses), one constraint colour group
// against the XPBD projection formula, vertex normals against vertexNormals, the transform
// kernel against XpbdSolver::transform; plus the program's build log reaching the error and the
// device choice failing cleanly. Tolerances: float rounding (the device may fuse multiply-adds
// and uses its own rsqrt), stated per test.
#include "cloth_grid.h"
#include "opencl_test_support.h"

#if DRAPE_HAVE_OPENCL
#include "backends/opencl/cl_frame_batch.h"
#include "backends/opencl/cl_shapes.h"
#include "backends/opencl/cl_stages.h"
#include "backends/opencl/cl_xpbd_solver.h"
#endif
#include "body/mesh_metrics.h"
#include "cloth/cloth_stats.h"
#include "cloth/garment_sim.h"
#include "cloth/garment_topology.h"
#include "cloth/xpbd_solver.h"
#include "proxies/collision.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace drape {
namespace {

#if DRAPE_HAVE_OPENCL
DclF4 f4(const Eigen::Vector4f& v) { return DclF4{v.x(), v.y(), v.z(), v.w()}; }
Eigen::Vector4f v4(const DclF4& v) { return Eigen::Vector4f(v.x, v.y, v.z, v.w); }

Ellipsoid makeEllipsoid(const Vec3& c, const Vec3& radii, float angle, const Vec3& axis) {
  Ellipsoid e;
  e.centre = c;
  e.radii = radii;
  e.rotation = Eigen::AngleAxisf(angle, axis.normalized()).toRotationMatrix();
  e.refresh();
  return e;
}

// A flat 1 m square of nx x nz particles in the XZ plane round the origin, pinned at the two
// corners of its first row: what the frame tests drape over their ellipsoids.
GarmentTopology flatSquare(int nx, int nz) {
  test::ClothGrid g;
  g.nx = nx, g.ny = nz;
  g.origin = Vec3(-0.5f, 0.0f, -0.5f);
  g.v = Vec3::UnitZ();
  TopologyParams tp;
  tp.pinned = {0, static_cast<uint32_t>(nx - 1)};
  return test::clothGridTopology(g, tp);
}

// Overlapping, moving, rotated ellipsoids (a torso, an arm against it, a small flat one) and
// particles scattered around and inside them, moving.
struct CollisionScene {
  std::vector<Ellipsoid> start, end;
  std::vector<uint8_t> groups, masks;
  std::vector<Eigen::Vector4f> x, prev;
};

CollisionScene collisionScene(unsigned seed) {
  CollisionScene s;
  s.start = {makeEllipsoid(Vec3(0, 1.2f, 0), Vec3(0.15f, 0.3f, 0.12f), 0.1f, Vec3(0, 0, 1)),
             makeEllipsoid(Vec3(0.2f, 1.3f, 0), Vec3(0.05f, 0.2f, 0.05f), 0.3f, Vec3(0, 0, 1)),
             makeEllipsoid(Vec3(-0.1f, 1.0f, 0.1f), Vec3(0.1f, 0.02f, 0.08f), 0.5f, Vec3(1, 1, 0))};
  s.end = {makeEllipsoid(Vec3(0.02f, 1.21f, 0.01f), Vec3(0.15f, 0.3f, 0.12f), 0.15f, Vec3(0, 0, 1)),
           makeEllipsoid(Vec3(0.18f, 1.32f, 0.03f), Vec3(0.05f, 0.2f, 0.05f), 0.45f, Vec3(0, 0, 1)),
           makeEllipsoid(Vec3(-0.12f, 1.0f, 0.12f), Vec3(0.1f, 0.02f, 0.08f), 0.6f, Vec3(1, 1, 0))};
  s.groups = {1, 2, 4};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < 4000; ++i) {
    // One draw per statement: the arguments of one call are evaluated in an order the compiler
    // picks (g++ right to left, clang left to right), which gave the two builds other scenes.
    const float px = u(rng), py = u(rng), pz = u(rng), dx = u(rng), dy = u(rng), dz = u(rng);
    const Vec3 p(0.3f * px, 1.2f + 0.4f * py, 0.2f * pz);
    const Vec3 d(0.03f * dx, 0.03f * dy, 0.03f * dz);
    const float w = i % 50 == 0 ? 0.0f : 1.0f;  // some pinned: never touched
    s.prev.emplace_back(p.x(), p.y(), p.z(), w);
    s.x.emplace_back(p.x() + d.x(), p.y() + d.y(), p.z() + d.z(), w);
    s.masks.push_back(static_cast<uint8_t>(i % 3 == 0 ? 0xFF : (i % 3 == 1 ? 1 : 3)));
  }
  return s;
}

struct CollisionCase {
  ContactResponse response;
  bool continuous, grouped;
  float max_escape;
};

class OpenClCollideKernel : public ::testing::TestWithParam<CollisionCase> {};

TEST_P(OpenClCollideKernel, MatchesCpuCollider) {
  DRAPE_REQUIRE_OPENCL(rt);
  const CollisionCase c = GetParam();
  CollisionScene s = collisionScene(7);
  CollisionParams p;
  p.response = c.response;
  p.continuous = c.continuous;
  p.max_escape_m = c.max_escape;
  const float margin = 0.004f;
  EllipsoidCollider cpu;
  cpu.setEllipsoids(s.start.data(), s.end.data(), 3, margin);
  if (c.grouped) cpu.setGroups(s.groups, s.masks.data());
  std::vector<Eigen::Vector4f> expect = s.x;
  const CollisionStats cs = cpu.collide(expect.data(), s.prev.data(), expect.size(), p);

  std::vector<DrapeClShape> shapes;
  std::vector<DclF4> bounds;
  packFrameShapes(s.start.data(), s.end.data(), 3, margin, c.grouped ? s.groups : std::vector<uint8_t>{}, 1, 1,
                  shapes, bounds);
  std::vector<DclF4> x, prev;
  for (size_t i = 0; i < s.x.size(); ++i) {
    x.push_back(f4(s.x[i]));
    prev.push_back(f4(s.prev[i]));
  }
  CollisionStats gs;
  std::string err;
  ASSERT_TRUE(clCollide(*rt, shapes, bounds, p, c.grouped ? s.masks : std::vector<uint8_t>{}, x, prev, gs, err)) << err;
  // Positions within 2 um (float rounding in the closest-point iterations), 0.3 mm for particles
  // the escape step marched out through overlapping ellipsoids (jumps of several cm, a chain of
  // ray-ellipsoid exits where rounding adds up: 245 um worst on this scene with the exact
  // response, under 50 um on the scene g++ drew before the draws were ordered); pinned ones
  // untouched; the same counters.
  float worst = 0.0f, worst_escaped = 0.0f;
  for (size_t i = 0; i < x.size(); ++i) {
    const float d = (v4(x[i]) - expect[i]).head<3>().norm();
    std::vector<Eigen::Vector4f> one{s.x[i]};
    const bool escaped = cpu.collide(one.data(), &s.prev[i], 1, p).escapes > 0;
    (escaped ? worst_escaped : worst) = std::max(escaped ? worst_escaped : worst, d);
    if (s.x[i].w() == 0.0f) EXPECT_EQ(v4(x[i]), s.x[i]);
  }
  EXPECT_LT(worst, 2e-6f);
  EXPECT_LT(worst_escaped, 3e-4f);
  EXPECT_GT(cs.contacts, 100u);  // the scene exercises contacts...
  EXPECT_EQ(gs.contacts, cs.contacts);
  EXPECT_EQ(gs.swept_catches, cs.swept_catches);
  EXPECT_EQ(gs.escapes, cs.escapes);
  EXPECT_EQ(gs.tests, cs.tests);
}

INSTANTIATE_TEST_SUITE_P(Cases, OpenClCollideKernel,
                         ::testing::Values(CollisionCase{ContactResponse::Exact, true, true, 0.01f},
                                           CollisionCase{ContactResponse::Exact, true, false, 0.0f},
                                           CollisionCase{ContactResponse::Radial, true, true, 0.0f},
                                           CollisionCase{ContactResponse::Exact, false, false, 0.01f}));

TEST(OpenClCollideKernel, EscapeStepRunsOnOverlaps) {
  // Without groups the arm and torso overlap: some particles need the escape step on both sides.
  DRAPE_REQUIRE_OPENCL(rt);
  CollisionScene s = collisionScene(11);
  EllipsoidCollider cpu;
  cpu.setEllipsoids(s.start.data(), s.end.data(), 3, 0.004f);
  std::vector<Eigen::Vector4f> expect = s.x;
  const CollisionStats cs = cpu.collide(expect.data(), s.prev.data(), expect.size(), CollisionParams{});
  ASSERT_GT(cs.escapes, 0u);
  std::vector<DrapeClShape> shapes;
  std::vector<DclF4> bounds, x, prev;
  packFrameShapes(s.start.data(), s.end.data(), 3, 0.004f, {}, 1, 1, shapes, bounds);
  for (size_t i = 0; i < s.x.size(); ++i) {
    x.push_back(f4(s.x[i]));
    prev.push_back(f4(s.prev[i]));
  }
  CollisionStats gs;
  std::string err;
  ASSERT_TRUE(clCollide(*rt, shapes, bounds, CollisionParams{}, {}, x, prev, gs, err)) << err;
  EXPECT_EQ(gs.escapes, cs.escapes);
  // Guarantee of the unlimited escape: nothing ends inside any (inflated) end ellipsoid.
  for (size_t i = 0; i < x.size(); ++i) {
    if (s.x[i].w() == 0.0f) continue;
    for (int k = 0; k < 3; ++k) {
      const Ellipsoid e = cpu.inflatedEnd(k);
      const float q = e.toUnit(v4(x[i]).head<3>()).norm();
      EXPECT_GT(q, 1.0f - 1e-3f) << "particle " << i << " inside ellipsoid " << k;
    }
  }
}

TEST(OpenClKernels, ProjectGroupMatchesCpuFormula) {
  DRAPE_REQUIRE_OPENCL(rt);
  // Disjoint pairs (one colour group): particle 2k with 2k + 1, various masses and stretches.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<DclF4> x;
  std::vector<DrapeClConstraint> c;
  for (uint32_t k = 0; k < 500; ++k) {
    const float wa = k % 7 == 0 ? 0.0f : 2.0f + u(rng), wb = k % 11 == 0 ? 0.0f : 1.5f + u(rng);
    x.push_back(DclF4{u(rng), u(rng), u(rng), wa});
    x.push_back(DclF4{u(rng), u(rng), u(rng), wb});
    c.push_back(DrapeClConstraint{2 * k, 2 * k + 1, 0.5f + 0.3f * u(rng), wa + wb});
  }
  // alpha~ = compliance / h^2 of the group: rigid (0) and compliant; the kernel forms inv_w
  // = 1 / (w_sum + alpha~) itself (0 for an inert constraint: both ends pinned, rigid).
  // Modes (DCL_MODE_*): distance, tether (one-sided), strain limit (the tether's inequality on
  // both ends, XpbdParams::strain_limit).
  for (const float alpha : {0.0f, 0.5f}) {
    for (const uint32_t mode : {DCL_MODE_DISTANCE, DCL_MODE_TETHER, DCL_MODE_LIMIT}) {
      SCOPED_TRACE(::testing::Message() << "mode " << mode << ", alpha " << alpha);
      std::vector<DclF4> got = x;
      std::string err;
      ASSERT_TRUE(clProjectGroup(*rt, c, 0, static_cast<uint32_t>(c.size()), mode, 1.1f, alpha, got, err)) << err;
      size_t slack = 0, b_moved = 0;
      for (size_t k = 0; k < c.size(); ++k) {
        // XpbdSolver's scalar path: C = |d| - rest (tether, limit: max(|d| - rest * scale, 0)).
        Eigen::Vector4f a = v4(x[c[k].a]), b = v4(x[c[k].b]);
        const Vec3 d = a.head<3>() - b.head<3>();
        const float len = d.norm();
        const float cc = mode != DCL_MODE_DISTANCE ? std::max(len - c[k].rest * 1.1f, 0.0f) : len - c[k].rest;
        const float wsum = c[k].w_sum + alpha;
        const float s = cc / len * (wsum > 0.0f ? 1.0f / wsum : 0.0f);
        a.head<3>() -= (a.w() * s) * d;
        if (mode != DCL_MODE_TETHER) b.head<3>() += (b.w() * s) * d;
        EXPECT_LT((v4(got[c[k].a]) - a).norm(), 2e-6f) << k;
        EXPECT_LT((v4(got[c[k].b]) - b).norm(), 2e-6f) << k;
        if (cc == 0.0f) {
          ++slack;  // an inequality that does not act: both ends untouched, bit for bit
          EXPECT_EQ(v4(got[c[k].a]), v4(x[c[k].a])) << k;
          EXPECT_EQ(v4(got[c[k].b]), v4(x[c[k].b])) << k;
        }
        if (v4(got[c[k].b]) != v4(x[c[k].b])) ++b_moved;
      }
      // The pairs cover both sides of the inequality, and only the tether leaves b where it was.
      if (mode != DCL_MODE_DISTANCE) EXPECT_GT(slack, 20u);
      EXPECT_LT(slack, c.size() - 100);
      if (mode == DCL_MODE_TETHER) EXPECT_EQ(b_moved, 0u);
      else EXPECT_GT(b_moved, 100u);
    }
  }
  std::vector<DclF4> got = x;
  std::string err;
  EXPECT_FALSE(clProjectGroup(*rt, c, 0, 1, 3u, 1.1f, 0.0f, got, err));
  EXPECT_NE(err.find("bad mode"), std::string::npos) << err;
}

TEST(OpenClKernels, VertexNormalsMatchCpu) {
  DRAPE_REQUIRE_OPENCL(rt);
  std::vector<float> flat;
  std::vector<uint32_t> indices;
  makeClothGrid(30, 20, 1.0f, 0.7f, Vec3::Zero(), Vec3::UnitX(), Vec3(0.0f, 0.3f, 1.0f), flat, indices);
  std::vector<Vec3> pos(flat.size() / 3);
  std::vector<DclF4> x(pos.size());
  for (size_t i = 0; i < pos.size(); ++i) {
    pos[i] = Vec3(flat[3 * i], flat[3 * i + 1] + 0.05f * std::sin(7.0f * flat[3 * i]), flat[3 * i + 2]);
    x[i] = DclF4{pos[i].x(), pos[i].y(), pos[i].z(), 1.0f};
  }
  std::vector<Vec3> expect(pos.size());
  vertexNormals(pos, indices, expect);
  std::vector<DclF4> got;
  std::string err;
  ASSERT_TRUE(clVertexNormals(*rt, x, indices, got, err)) << err;
  for (size_t i = 0; i < pos.size(); ++i)
    EXPECT_LT((Vec3(got[i].x, got[i].y, got[i].z) - expect[i]).norm(), 1e-5f) << i;
}

GarmentTopology hangingSquare(int n) {
  test::ClothGrid g;
  g.nx = g.ny = n;
  TopologyParams p;
  p.pinned = {0, static_cast<uint32_t>(n - 1)};
  return test::clothGridTopology(g, p);
}

TEST(OpenClKernels, TransformMatchesCpu) {
  DRAPE_REQUIRE_OPENCL(rt);
  const GarmentTopology t = hangingSquare(12);
  XpbdSolver cpu(t);
  std::string err;
  auto cl = ClXpbdSolver::create(rt, t, {}, {}, err);
  ASSERT_TRUE(cl) << err;
  for (int f = 0; f < 3; ++f) {  // some velocity first
    ASSERT_TRUE(cpu.step(1.0f / 30.0f));
    ASSERT_TRUE(cl->step(1.0f / 30.0f));
  }
  const Mat3 R = Eigen::AngleAxisf(0.4f, Vec3(0.2f, 1.0f, 0.1f).normalized()).toRotationMatrix();
  cpu.transform(R, Vec3(0.1f, -0.2f, 0.3f), Vec3(0.5f, 0.0f, -0.25f), 0.5f);
  cl->transform(R, Vec3(0.1f, -0.2f, 0.3f), Vec3(0.5f, 0.0f, -0.25f), 0.5f);
  for (size_t i = 0; i < t.particleCount(); ++i) {
    EXPECT_LT((cl->positions()[i] - cpu.positions()[i]).norm(), 1e-5f);
    EXPECT_LT((cl->velocities()[i] - cpu.velocities()[i]).norm(), 1e-4f);
  }
}

TEST(OpenClRuntime, BuildLogReachesTheError) {
  // A deliberately broken kernel appended through the internal hook: the build fails and the
  // error carries the compiler's log naming the bad identifier.
  if (!test::sharedClRuntime()) GTEST_SKIP() << "no usable OpenCL device";
  ClChoice c;
  c.extra_source = "__kernel void drape_broken(__global float* x) { x[0] = undefined_symbol_xyz; }\n";
  std::string err;
  EXPECT_FALSE(ClRuntime::create(c, err));
  EXPECT_NE(err.find("build failed"), std::string::npos) << err;
  EXPECT_NE(err.find("undefined_symbol_xyz"), std::string::npos) << err;
}

TEST(OpenClRuntime, BadDefineReachesTheError) {
  if (!test::sharedClRuntime()) GTEST_SKIP() << "no usable OpenCL device";
  ClChoice c;
  c.extra_options = "-DDRAPE_CL_WORK_GROUP=banana";  // redefined to garbage: kernels.cl cannot compile
  std::string err;
  EXPECT_FALSE(ClRuntime::create(c, err));
  EXPECT_NE(err.find("build failed"), std::string::npos) << err;
}

TEST(OpenClRuntime, ImpossibleDeviceIndexFails) {
  std::string list_err;
  const auto devices = listClDevices(list_err);
  if (devices.empty()) GTEST_SKIP() << "no OpenCL platform: " << list_err;
  ClChoice c;
  c.device = 999;
  std::string err;
  EXPECT_FALSE(ClRuntime::create(c, err));
  EXPECT_NE(err.find("device index 999"), std::string::npos) << err;
  c.device = -1;
  c.platform = 999;
  err.clear();
  EXPECT_FALSE(ClRuntime::create(c, err));
  EXPECT_NE(err.find("platform index 999"), std::string::npos) << err;
  // Every listed device has a name.
  for (const ClDeviceDesc& d : devices) EXPECT_FALSE(d.device_name.empty());
}
#else
TEST(OpenClKernels, Unavailable) { GTEST_SKIP() << "built without OpenCL"; }
#endif

}  // namespace
}  // namespace drape

namespace drape {
namespace {
#if DRAPE_HAVE_OPENCL
// The strain-limit tests' stretch compliance: soft enough that the cloth the ellipsoid lifts
// stretches past the limit (with the default, rigid edges it barely reaches it).
constexpr float kStrainTestStretchCompliance = 1e-2f;

// The frame kernel (every substep in one launch) against XpbdSolver::step: a hanging square
// swept by a moving ellipsoid, collision every second substep, one frame and then 20. Twice: at
// a fixed 1/30 s with the default compliances, and at a frame time that changes every frame (as
// a Kinect's does: the device adds alpha~ = compliance / h^2 per kind to each constraint's
// static w_a + w_b, the CPU refreshes its inv_w) with every kind compliant and each kind's
// compliance different, so a kind given another's alpha~ fails the first frames' 1e-5 bound.
// A third time with the strain limit on (XpbdParams::strain_limit, GarmentSimParams' 0.1, two
// passes in each step's last substep), and a fourth at 5 % in 8 passes (strain_limit_passes,
// docs/garments.md "More strain-limit passes"): the same bounds.
void frameMatchesXpbdStep(const std::shared_ptr<ClRuntime>& rt, bool varying, float strain_limit = 0.0f,
                          int strain_limit_passes = 2) {
  const GarmentTopology t = flatSquare(24, 24);
  std::string err;
  XpbdParams p;
  p.collision_stride = 2;
  p.drag = 0.3f;
  p.wind = Vec3(0.5f, 0.0f, 0.2f);
  if (varying) {
    p.stretch_compliance = 1e-7f;
    p.shear_compliance = 3e-5f;
    p.bend_compliance = 1e-2f;
    p.tether_compliance = 1e-6f;
  }
  p.strain_limit = strain_limit;
  p.strain_limit_passes = strain_limit_passes;
  // The CPU's own divergence: two runs nudged by 1 um (along x, along z) at the start; the
  // larger of their distances from the unnudged run is the reference (one nudge alone is a
  // noisy estimate of how fast this scene amplifies rounding).
  XpbdSolver cpu(t), nudged[2] = {XpbdSolver(t), XpbdSolver(t)};
  for (int k = 0; k < 2; ++k) {
    ASSERT_TRUE(nudged[k].setParams(p, err));
    for (size_t i = 0; i < t.particleCount(); ++i) nudged[k].mutablePositions()[i][k == 0 ? 0 : 2] += 1e-6f;
  }
  auto gpu = ClXpbdSolver::create(rt, t, {}, {}, err);
  ASSERT_TRUE(gpu) << err;
  ASSERT_TRUE(cpu.setParams(p, err));
  ASSERT_TRUE(gpu->setParams(p, err));
  EllipsoidCollider collider;
  uint32_t contacts = 0;
  float chaos = 0.0f;  // the largest self-divergence so far
  for (int f = 0; f < 20; ++f) {
    const float dt = varying ? (1.0f + 0.08f * std::sin(1.7f * static_cast<float>(f))) / 30.0f : 1.0f / 30.0f;
    const float a = 0.05f * static_cast<float>(f), b = 0.05f * static_cast<float>(f + 1);
    const Ellipsoid e0 = makeEllipsoid(Vec3(0.1f * a, -0.35f + a, 0.0f), Vec3(0.3f, 0.2f, 0.25f), a, Vec3(0, 1, 0));
    const Ellipsoid e1 = makeEllipsoid(Vec3(0.1f * b, -0.35f + b, 0.0f), Vec3(0.3f, 0.2f, 0.25f), b, Vec3(0, 1, 0));
    ASSERT_TRUE(cpu.setColliderMotion(&collider, &e0, &e1, 1, 0.004f, err));
    ASSERT_TRUE(gpu->setColliderMotion(&e0, &e1, 1, 0.004f, {}, err));
    for (XpbdSolver& s : nudged) {
      ASSERT_TRUE(s.setColliderMotion(&collider, &e0, &e1, 1, 0.004f, err));
      ASSERT_TRUE(s.step(dt, 10));
    }
    ASSERT_TRUE(cpu.step(dt, 10));
    ASSERT_TRUE(gpu->step(dt, 10)) << gpu->lastError();
    float worst = 0.0f;
    for (size_t i = 0; i < t.particleCount(); ++i)
      worst = std::max(worst, (gpu->positions()[i] - cpu.positions()[i]).head<3>().norm());
    for (const XpbdSolver& s : nudged)
      for (size_t i = 0; i < t.particleCount(); ++i)
        chaos = std::max(chaos, (s.positions()[i] - cpu.positions()[i]).head<3>().norm());
    // Float-rounding level while nothing has amplified it yet; then within 5x of what a 1 um
    // nudge of the initial state does to the CPU run itself (measured: 0.1-0.7x): the kernel
    // diverges from the CPU no faster than the CPU diverges from itself.
    if (f < 3) EXPECT_LT(worst, 1e-5f) << "frame " << f;
    EXPECT_LT(worst, 5.0f * chaos + 1e-5f) << "frame " << f << ", CPU self-divergence " << chaos;
    const float c0 = static_cast<float>(cpu.lastCollisionStats().contacts);
    // The same contacts while the runs agree to float rounding; then as close as the positions.
    if (worst < 1e-5f) EXPECT_EQ(gpu->lastCollisionStats().contacts, cpu.lastCollisionStats().contacts) << "frame " << f;
    EXPECT_NEAR(static_cast<float>(gpu->lastCollisionStats().contacts), c0, 0.05f * c0 + 5.0f) << "frame " << f;
    contacts += cpu.lastCollisionStats().contacts;
  }
  EXPECT_GT(contacts, 1000u);  // the ellipsoid did push the cloth
}

TEST(OpenClKernels, FrameMatchesXpbdStep) {
  DRAPE_REQUIRE_OPENCL(rt);
  frameMatchesXpbdStep(rt, false);
}

TEST(OpenClKernels, FrameMatchesXpbdStepWithAFrameTimeThatVaries) {
  DRAPE_REQUIRE_OPENCL(rt);
  frameMatchesXpbdStep(rt, true);
}

TEST(OpenClKernels, FrameMatchesXpbdStepWithTheStrainLimit) {
  DRAPE_REQUIRE_OPENCL(rt);
  frameMatchesXpbdStep(rt, false, GarmentSimParams{}.xpbd.strain_limit);
}

TEST(OpenClKernels, FrameMatchesXpbdStepWithEightStrainLimitPasses) {
  DRAPE_REQUIRE_OPENCL(rt);
  frameMatchesXpbdStep(rt, false, 0.05f, 8);
}

// The largest strain (|d| / rest - 1) over the structural (stretch) edges, 0 when none is
// stretched (stretchStats' max, which may be negative).
float maxStretch(const GarmentTopology& t, const Eigen::Vector4f* x) {
  std::vector<float> scratch;
  return std::max(0.0f, stretchStats(t, x, scratch).max);
}

// The CPU run of the device parity tests and its two twins nudged by 1 um at the start (along x,
// along z): the larger of their distances from it is the CPU's own divergence, the bound's scale.
struct CpuWithNudges {
  XpbdSolver cpu, nudged[2];
  CpuWithNudges(const GarmentTopology& t, const XpbdParams& p) : cpu(t), nudged{XpbdSolver(t), XpbdSolver(t)} {
    std::string err;
    EXPECT_TRUE(cpu.setParams(p, err)) << err;
    for (int k = 0; k < 2; ++k) {
      EXPECT_TRUE(nudged[k].setParams(p, err)) << err;
      for (size_t i = 0; i < t.particleCount(); ++i) nudged[k].mutablePositions()[i][k == 0 ? 0 : 2] += 1e-6f;
    }
  }
};

// A device solver of `t` on `path` with `p` (null, with a test failure, when that fails).
std::unique_ptr<ClXpbdSolver> deviceSolver(const std::shared_ptr<ClRuntime>& rt, const GarmentTopology& t,
                                           ClXpbdSolver::Path path, const XpbdParams& p) {
  std::string err;
  std::unique_ptr<ClXpbdSolver> s = ClXpbdSolver::create(rt, t, {}, {}, err);
  EXPECT_TRUE(s) << err;
  if (!s) return s;
  s->setPath(path);
  EXPECT_TRUE(s->setParams(p, err)) << err;
  return s;
}

// The strain limit on both device paths (one work-group, per-phase launches) against
// XpbdSolver::step, on the hanging square of frameMatchesXpbdStep with softer stretch edges
// (so that the cloth the ellipsoid lifts overstretches): the two device paths the same bits; the
// device within the CPU's bounds of frameMatchesXpbdStep (1e-5 m for the first frames, then 5x
// the CPU's own divergence under a 1 um nudge); the largest edge strain of the device and the CPU
// runs within what those position bounds allow; and the limit does act on the device: without it
// the positions differ and the largest strain is well above the limit's.
TEST(OpenClKernels, StrainLimitMatchesCpuOnBothDevicePaths) {
  DRAPE_REQUIRE_OPENCL(rt);
  const GarmentTopology t = flatSquare(24, 24);
  std::string err;
  float min_rest = 1e9f;
  for (float r : t.stretch.rest) min_rest = std::min(min_rest, r);
  XpbdParams on;
  on.collision_stride = 2;
  on.stretch_compliance = kStrainTestStretchCompliance;
  on.strain_limit = 0.1f;
  on.strain_limit_passes = 2;
  XpbdParams off = on;
  off.strain_limit = 0.0f;
  CpuWithNudges runs(t, on);
  XpbdSolver& cpu = runs.cpu;
  XpbdSolver(&nudged)[2] = runs.nudged;
  // Device: limit on through the work-group frame and the per-phase launches, off (work-group).
  std::unique_ptr<ClXpbdSolver> group = deviceSolver(rt, t, ClXpbdSolver::Path::WorkGroup, on);
  std::unique_ptr<ClXpbdSolver> phases = deviceSolver(rt, t, ClXpbdSolver::Path::Phases, on);
  std::unique_ptr<ClXpbdSolver> unlimited = deviceSolver(rt, t, ClXpbdSolver::Path::WorkGroup, off);
  ASSERT_TRUE(group && phases && unlimited);
  EllipsoidCollider collider;
  float chaos = 0.0f, apart = 0.0f, stretch_on = 0.0f, stretch_off = 0.0f;
  for (int f = 0; f < 20; ++f) {
    const float a = 0.05f * static_cast<float>(f), b = 0.05f * static_cast<float>(f + 1);
    const Ellipsoid e0 = makeEllipsoid(Vec3(0.1f * a, -0.35f + a, 0.0f), Vec3(0.3f, 0.2f, 0.25f), a, Vec3(0, 1, 0));
    const Ellipsoid e1 = makeEllipsoid(Vec3(0.1f * b, -0.35f + b, 0.0f), Vec3(0.3f, 0.2f, 0.25f), b, Vec3(0, 1, 0));
    ASSERT_TRUE(cpu.setColliderMotion(&collider, &e0, &e1, 1, 0.004f, err));
    ASSERT_TRUE(cpu.step(1.0f / 30.0f, 10));
    for (XpbdSolver& s : nudged) {
      ASSERT_TRUE(s.setColliderMotion(&collider, &e0, &e1, 1, 0.004f, err));
      ASSERT_TRUE(s.step(1.0f / 30.0f, 10));
    }
    for (ClXpbdSolver* s : {group.get(), phases.get(), unlimited.get()}) {
      ASSERT_TRUE(s->setColliderMotion(&e0, &e1, 1, 0.004f, {}, err)) << err;
      ASSERT_TRUE(s->step(1.0f / 30.0f, 10)) << s->lastError();
    }
    EXPECT_FALSE(group->usesPhases());
    EXPECT_TRUE(phases->usesPhases());
    float worst = 0.0f;
    for (size_t i = 0; i < t.particleCount(); ++i) {
      ASSERT_EQ(group->positions()[i], phases->positions()[i]) << "frame " << f << " particle " << i;
      worst = std::max(worst, (group->positions()[i] - cpu.positions()[i]).head<3>().norm());
      apart = std::max(apart, (group->positions()[i] - unlimited->positions()[i]).head<3>().norm());
    }
    for (const XpbdSolver& s : nudged)
      for (size_t i = 0; i < t.particleCount(); ++i)
        chaos = std::max(chaos, (s.positions()[i] - cpu.positions()[i]).head<3>().norm());
    const float bound = f < 3 ? 1e-5f : 5.0f * chaos + 1e-5f;
    EXPECT_LT(worst, bound) << "frame " << f << ", CPU self-divergence " << chaos;
    // Each end of an edge within `bound`: its strain within 2 bound / rest of the CPU's.
    const float s_gpu = maxStretch(t, group->positions()), s_cpu = maxStretch(t, cpu.positions());
    EXPECT_NEAR(s_gpu, s_cpu, 2.0f * bound / min_rest) << "frame " << f;
    stretch_on = std::max(stretch_on, s_gpu);
    stretch_off = std::max(stretch_off, maxStretch(t, unlimited->positions()));
  }
  std::printf("[ figures  ] strain limit 0.1: largest edge strain over 20 frames %.4f (device, off: %.4f); "
              "device positions with and without the limit up to %.4f m apart\n",
              stretch_on, stretch_off, apart);
  EXPECT_GT(apart, 1e-3f);                     // the limit moved the device's particles
  EXPECT_GT(stretch_off, 0.15f);               // the scene does overstretch without the limit
  EXPECT_LT(stretch_on, stretch_off - 0.03f);  // and the limit took much of it out
}

// The rim tests' scene: a 1 m x 0.5 m sheet of 12 x 6 particles hanging from its pinned top row,
// and a thin upright rod (2 cm thick) at depth z, between hem particles 5 and 6 (9 cm apart).
struct RodScene {
  GarmentTopology sheet;
  size_t hem0 = 0;  // the hem's first particle
  float x_mid = 0.0f;
  RodScene() {
    test::ClothGrid grid;
    grid.nx = 12, grid.ny = 6;
    grid.height = 0.5f;
    grid.origin = Vec3(-0.5f, 0.0f, 0.0f);
    TopologyParams tp;
    for (uint32_t i = 0; i < static_cast<uint32_t>(grid.nx); ++i) tp.pinned.push_back(i);
    sheet = test::clothGridTopology(grid, tp);
    hem0 = static_cast<size_t>(grid.nx) * static_cast<size_t>(grid.ny - 1);
    x_mid = -0.5f + 5.5f / static_cast<float>(grid.nx - 1);
  }
  Ellipsoid rod(float z) const {
    return makeEllipsoid(Vec3(x_mid, -0.45f, z), Vec3(0.01f, 0.2f, 0.01f), 0.0f, Vec3(0, 1, 0));
  }
};

// The rim edges (EllipsoidCollider::collideRims) on both device paths against XpbdSolver::step:
// a sheet hanging from its top row and a thin upright rod moving through its hem between two hem
// particles (the scene of CollideRims.AThinRodCatchesTheHemInsteadOfPassingThroughTheCloth), which
// only the rim pass catches. The two device paths the same bits; the device within the CPU bounds
// of frameMatchesXpbdStep; and the rims do act on the device: the hem is carried along with them
// and left behind without.
TEST(OpenClKernels, RimEdgesMatchCpuOnBothDevicePaths) {
  DRAPE_REQUIRE_OPENCL(rt);
  const RodScene scene;
  const GarmentTopology& t = scene.sheet;
  ASSERT_GT(t.rims.size(), 0u);
  std::string err;
  XpbdParams on;
  XpbdParams off = on;
  off.collision.rims = false;
  CpuWithNudges runs(t, on);
  XpbdSolver& cpu = runs.cpu;
  XpbdSolver(&nudged)[2] = runs.nudged;
  std::unique_ptr<ClXpbdSolver> group = deviceSolver(rt, t, ClXpbdSolver::Path::WorkGroup, on);
  std::unique_ptr<ClXpbdSolver> phases = deviceSolver(rt, t, ClXpbdSolver::Path::Phases, on);
  std::unique_ptr<ClXpbdSolver> without = deviceSolver(rt, t, ClXpbdSolver::Path::WorkGroup, off);
  // The rim gate on the device (ClXpbdSolver::setRimGate, carried in the rim records): every rim
  // gated off on both paths is rims off, to the bit.
  std::unique_ptr<ClXpbdSolver> gated[2] = {deviceSolver(rt, t, ClXpbdSolver::Path::WorkGroup, on),
                                            deviceSolver(rt, t, ClXpbdSolver::Path::Phases, on)};
  ASSERT_TRUE(group && phases && without && gated[0] && gated[1]);
  for (auto& s : gated) s->setRimGate(std::vector<uint8_t>(t.particleCount(), 0));
  EllipsoidCollider collider;
  float chaos = 0.0f, carried = 0.0f, carried_without = 0.0f;
  for (int f = 0; f < 20; ++f) {
    const float z0 = -0.1f + 0.015f * static_cast<float>(f), z1 = z0 + 0.015f;
    const Ellipsoid e0 = scene.rod(z0), e1 = scene.rod(z1);
    ASSERT_TRUE(cpu.setColliderMotion(&collider, &e0, &e1, 1, 0.004f, err));
    ASSERT_TRUE(cpu.step(1.0f / 30.0f, 10));
    for (XpbdSolver& s : nudged) {
      ASSERT_TRUE(s.setColliderMotion(&collider, &e0, &e1, 1, 0.004f, err));
      ASSERT_TRUE(s.step(1.0f / 30.0f, 10));
    }
    for (ClXpbdSolver* s : {group.get(), phases.get(), without.get(), gated[0].get(), gated[1].get()}) {
      ASSERT_TRUE(s->setColliderMotion(&e0, &e1, 1, 0.004f, {}, err)) << err;
      ASSERT_TRUE(s->step(1.0f / 30.0f, 10)) << s->lastError();
    }
    // The first gated one opens after frame 2, before the rod reaches the hem (frame 6): its
    // records go up again and it runs as the ungated one from then on, to the bit; the second stays
    // gated off, as without rims.
    if (f == 2) gated[0]->setRimGate({});
    for (size_t i = 0; i < t.particleCount(); ++i) {
      ASSERT_EQ(gated[0]->positions()[i], group->positions()[i]) << "frame " << f << " particle " << i;
      ASSERT_EQ(gated[1]->positions()[i], without->positions()[i]) << "frame " << f << " particle " << i;
    }
    EXPECT_FALSE(group->usesPhases());
    EXPECT_TRUE(phases->usesPhases());
    float worst = 0.0f;
    for (size_t i = 0; i < t.particleCount(); ++i) {
      ASSERT_EQ(group->positions()[i], phases->positions()[i]) << "frame " << f << " particle " << i;
      worst = std::max(worst, (group->positions()[i] - cpu.positions()[i]).head<3>().norm());
    }
    for (const XpbdSolver& s : nudged)
      for (size_t i = 0; i < t.particleCount(); ++i)
        chaos = std::max(chaos, (s.positions()[i] - cpu.positions()[i]).head<3>().norm());
    EXPECT_LT(worst, f < 3 ? 1e-5f : 5.0f * chaos + 1e-5f) << "frame " << f << ", CPU self-divergence " << chaos;
  }
  for (size_t i = scene.hem0; i < t.particleCount(); ++i) {
    carried = std::max(carried, group->positions()[i].z());
    carried_without = std::max(carried_without, without->positions()[i].z());
  }
  std::printf("[ figures  ] rod through the hem on the device: hem carried %.3f m with the rims, %.3f without\n", carried,
              carried_without);
  EXPECT_GT(carried, 0.1f);
  EXPECT_LT(carried_without, 0.01f);
}

// A rim gate that changes between frames reaches a batch (ClFrameBatch re-uploads the member's
// rim records): three rod scenes of RimEdgesMatchCpuOnBothDevicePaths batched (two in the
// work-group frame, one per phase) against the same three stepped alone, gated off and then opened
// after frame 2 (before the rod reaches the hem) or kept off: the same bits every frame.
TEST(OpenClKernels, RimGateChangesReachABatch) {
  DRAPE_REQUIRE_OPENCL(rt);
  const RodScene scene;
  const GarmentTopology& t = scene.sheet;
  const std::vector<uint8_t> closed(t.particleCount(), 0);
  std::string err;
  std::vector<std::unique_ptr<ClXpbdSolver>> batched, alone;
  const ClXpbdSolver::Path paths[3] = {ClXpbdSolver::Path::WorkGroup, ClXpbdSolver::Path::WorkGroup,
                                       ClXpbdSolver::Path::Phases};
  for (int g = 0; g < 3; ++g)
    for (auto* list : {&batched, &alone}) {
      list->push_back(ClXpbdSolver::create(rt, t, {}, {}, err));
      ASSERT_TRUE(list->back()) << err;
      list->back()->setPath(paths[g]);
      ASSERT_TRUE(list->back()->setParams(XpbdParams{}, err)) << err;
      list->back()->setRimGate(closed);
    }
  ClFrameBatch batch(*rt);
  std::vector<ClXpbdSolver*> table;
  for (auto& s : batched) table.push_back(s.get());
  float carried[3] = {0.0f, 0.0f, 0.0f};
  for (int f = 0; f < 20; ++f) {
    if (f == 3)
      for (int g : {0, 2}) batched[g]->setRimGate({}), alone[g]->setRimGate({});
    const float z0 = -0.1f + 0.015f * static_cast<float>(f), z1 = z0 + 0.015f;
    const Ellipsoid e0 = scene.rod(z0), e1 = scene.rod(z1);
    for (int g = 0; g < 3; ++g) {
      for (ClXpbdSolver* s : {batched[g].get(), alone[g].get()})
        ASSERT_TRUE(s->setColliderMotion(&e0, &e1, 1, 0.004f, {}, err)) << err;
      ASSERT_TRUE(batched[g]->prepareFrame(1.0f / 30.0f, 10));
      ASSERT_TRUE(alone[g]->step(1.0f / 30.0f, 10)) << alone[g]->lastError();
    }
    ASSERT_TRUE(batch.run(table, err)) << err;
    for (int g = 0; g < 3; ++g)
      for (size_t i = 0; i < t.particleCount(); ++i)
        ASSERT_EQ(batched[g]->positions()[i], alone[g]->positions()[i]) << "frame " << f << " garment " << g << " particle " << i;
  }
  for (int g = 0; g < 3; ++g)
    for (size_t i = scene.hem0; i < t.particleCount(); ++i) carried[g] = std::max(carried[g], batched[g]->positions()[i].z());
  EXPECT_GT(carried[0], 0.1f);  // opened: the rod carried the hem
  EXPECT_GT(carried[2], 0.1f);
  EXPECT_LT(carried[1], 0.01f);  // kept closed: it went through
}

// The per-phase launches of a batch whose garments differ in substeps, strain-limit passes and
// stretch-group layout, one of them with the limit off: each garment's limit passes must run in
// its own last substep only (the host launches them after every substep that ends some garment,
// the kernel picks the garments), so the batch gives the bits of each garment stepped alone.
TEST(OpenClKernels, BatchedPhasesRunEachGarmentsStrainLimitInItsOwnLastSubstep) {
  DRAPE_REQUIRE_OPENCL(rt);
  const GarmentTopology ta = flatSquare(24, 24), tb = flatSquare(20, 30);
  struct Member {
    const GarmentTopology* t;
    float strain_limit;
    int passes, substeps;
  };
  const Member members[3] = {{&ta, 0.1f, 2, 10}, {&tb, 0.05f, 3, 7}, {&ta, 0.0f, 2, 12}};
  std::string err;
  std::vector<std::unique_ptr<ClXpbdSolver>> batched, alone;
  for (const Member& m : members) {
    XpbdParams p;
    p.collision_stride = 2;
    p.stretch_compliance = kStrainTestStretchCompliance;
    p.strain_limit = m.strain_limit;
    p.strain_limit_passes = m.passes;
    for (auto* list : {&batched, &alone}) {
      list->push_back(ClXpbdSolver::create(rt, *m.t, {}, {}, err));
      ASSERT_TRUE(list->back()) << err;
      list->back()->setPath(ClXpbdSolver::Path::Phases);
      ASSERT_TRUE(list->back()->setParams(p, err)) << err;
    }
  }
  ClFrameBatch batch(*rt);
  std::vector<ClXpbdSolver*> table;
  for (auto& s : batched) table.push_back(s.get());
  for (int f = 0; f < 6; ++f) {
    const float a = 0.05f * static_cast<float>(f), b = 0.05f * static_cast<float>(f + 1);
    const Ellipsoid e0 = makeEllipsoid(Vec3(0.1f * a, -0.35f + a, 0.0f), Vec3(0.3f, 0.2f, 0.25f), a, Vec3(0, 1, 0));
    const Ellipsoid e1 = makeEllipsoid(Vec3(0.1f * b, -0.35f + b, 0.0f), Vec3(0.3f, 0.2f, 0.25f), b, Vec3(0, 1, 0));
    for (size_t g = 0; g < 3; ++g) {
      for (ClXpbdSolver* s : {batched[g].get(), alone[g].get()})
        ASSERT_TRUE(s->setColliderMotion(&e0, &e1, 1, 0.004f, {}, err)) << err;
      ASSERT_TRUE(batched[g]->prepareFrame(1.0f / 30.0f, members[g].substeps));
      ASSERT_TRUE(alone[g]->step(1.0f / 30.0f, members[g].substeps)) << alone[g]->lastError();
    }
    ASSERT_TRUE(batch.run(table, err)) << err;
    for (size_t g = 0; g < 3; ++g) {
      ASSERT_TRUE(batched[g]->usesPhases());
      for (size_t i = 0; i < members[g].t->particleCount(); ++i)
        ASSERT_EQ(batched[g]->positions()[i], alone[g]->positions()[i])
            << "frame " << f << " garment " << g << " particle " << i;
    }
  }
}
#endif
}  // namespace
}  // namespace drape

namespace drape {
namespace {
#if DRAPE_HAVE_OPENCL
// Large garments run one launch per phase over global memory instead of the one-work-group
// frame: the same arithmetic per particle in the same order, so the same bits (the strain
// limit's passes too).
TEST(OpenClKernels, PhaseLaunchesMatchTheWorkGroupFrameBitForBit) {
  DRAPE_REQUIRE_OPENCL(rt);
  const GarmentTopology t = flatSquare(30, 30);
  std::string err;
  // Without and with the strain limit (its passes: one launch per stretch group there).
  for (const float strain_limit : {0.0f, 0.1f}) {
    SCOPED_TRACE(::testing::Message() << "strain_limit " << strain_limit);
    XpbdParams p;
    p.collision_stride = 2;
    p.iterations = 2;
    p.strain_limit = strain_limit;
    std::unique_ptr<ClXpbdSolver> solvers[2] = {ClXpbdSolver::create(rt, t, {}, {}, err),
                                                ClXpbdSolver::create(rt, t, {}, {}, err)};
    ASSERT_TRUE(solvers[0] && solvers[1]) << err;
    solvers[0]->setPath(ClXpbdSolver::Path::WorkGroup);
    solvers[1]->setPath(ClXpbdSolver::Path::Phases);
    EXPECT_FALSE(solvers[0]->usesPhases());
    EXPECT_TRUE(solvers[1]->usesPhases());
    for (auto& s : solvers) ASSERT_TRUE(s->setParams(p, err)) << err;
    for (int f = 0; f < 12; ++f) {
      const float a = 0.05f * static_cast<float>(f), b = 0.05f * static_cast<float>(f + 1);
      const Ellipsoid e0 = makeEllipsoid(Vec3(0.1f * a, -0.35f + a, 0.0f), Vec3(0.3f, 0.2f, 0.25f), a, Vec3(0, 1, 0));
      const Ellipsoid e1 = makeEllipsoid(Vec3(0.1f * b, -0.35f + b, 0.0f), Vec3(0.3f, 0.2f, 0.25f), b, Vec3(0, 1, 0));
      for (auto& s : solvers) {
        ASSERT_TRUE(s->setColliderMotion(&e0, &e1, 1, 0.004f, {}, err));
        const Vec3 pins[2] = {Vec3(-0.5f, 0.01f * f, -0.5f), Vec3(0.5f, 0.0f, -0.5f)};
        ASSERT_TRUE(s->setPinTargets(pins, 2, err));
        ASSERT_TRUE(s->step(1.0f / 30.0f, 10)) << s->lastError();
      }
      for (size_t i = 0; i < t.particleCount(); ++i)
        ASSERT_EQ(solvers[0]->positions()[i], solvers[1]->positions()[i]) << "frame " << f << " particle " << i;
      EXPECT_EQ(solvers[0]->lastCollisionStats().contacts, solvers[1]->lastCollisionStats().contacts);
      EXPECT_EQ(solvers[0]->lastCollisionStats().tests, solvers[1]->lastCollisionStats().tests);
    }
    EXPECT_GT(solvers[0]->lastCollisionStats().tests, 0u);
  }
}

// The automatic path: one work-group up to the device's limit (what fits in __local memory, 4 096
// particles on a CPU device such as PoCL, 1 200 on a GPU, where the per-phase launches win from
// ~1 100-1 300 particles with collision: docs/opencl.md, "Fifth lease"), the per-phase launches above.
TEST(OpenClKernels, AutomaticPathSwitchesAtTheDeviceLimit) {
  DRAPE_REQUIRE_OPENCL(rt);
  const size_t limit = rt->workGroupMaxParticles();
  EXPECT_EQ(limit, std::min(rt->localParticles(), rt->isGpu() ? ClRuntime::kGpuWorkGroupMaxParticles
                                                               : ClRuntime::kWorkGroupMaxParticles));
  const cl_device_type type = [&] {
    cl_device_type t = 0;
    clGetDeviceInfo(rt->device(), CL_DEVICE_TYPE, sizeof t, &t, nullptr);
    return t;
  }();
  EXPECT_EQ(rt->isGpu(), (type & CL_DEVICE_TYPE_GPU) != 0) << rt->deviceName();
  // Square grids of side floor(sqrt(limit)) (at most the limit) and one more (over it).
  size_t side = 1;
  while ((side + 1) * (side + 1) <= limit) ++side;
  for (const size_t n : {side, side + 1}) {
    std::vector<float> positions;
    std::vector<uint32_t> indices;
    const int k = static_cast<int>(n);
    makeClothGrid(k, k, 1.0f, 1.0f, Vec3(-0.5f, 0.0f, -0.5f), Vec3::UnitX(), Vec3::UnitZ(), positions, indices);
    TopologyParams tp;
    tp.pinned = {0, static_cast<uint32_t>(n - 1)};
    GarmentTopology t;
    std::string err;
    ASSERT_TRUE(buildGarmentTopology(positions.data(), positions.size() / 3, indices.data(), indices.size(), tp, t, err));
    auto s = ClXpbdSolver::create(rt, t, {}, {}, err);
    ASSERT_TRUE(s) << err;
    EXPECT_EQ(s->usesPhases(), n * n > limit) << n * n << " particles, limit " << limit << " on " << rt->deviceName();
    EXPECT_EQ(s->usesLocalMemory(), n * n <= limit);
  }
}
#endif
}  // namespace
}  // namespace drape
