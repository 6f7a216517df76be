// Garments on the OpenCL backend (docs/opencl.md, "Normals"): once the host reads normals, the
// frame computes them on the device (one more launch, alone or batched) and reads them back with
// the positions; they match the CPU's vertexNormals of the same positions within 1e-5, batched
// and one by one give the same bits, and a host that stops reading stops paying the launch.
// Also: a garment moved back to the CPU keeps the velocities it had on the device, and the
// stats' collide_ms is 0 on the device (the frame's time is all in integrate_ms).
#include "garment_scene.h"
#include "opencl_test_support.h"

#include "body/body_shape.h"
#include "body/mesh_metrics.h"
#include "capi/context.h"

#if DRAPE_HAVE_OPENCL
#include "backends/opencl/cl_garment_solver.h"
#include "cloth/garment_solver.h"
#endif

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

namespace drape {
namespace {

#if DRAPE_HAVE_OPENCL

struct Person {
  std::unique_ptr<Context> ctx;
  std::vector<GarmentSim*> garments;
};

// A context with T-shirts of the given sizes on `backend`; empty garments when OpenCL is not
// active (the caller skips).
Person makePerson(const std::vector<int>& sizes, drape_backend backend) {
  Person p;
  p.ctx = std::make_unique<Context>(test::defaultDesc());
  std::string err;
  for (int n : sizes) {
    GarmentSim* g = test::addTemplate(*p.ctx, GarmentKind::TShirt, n, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
    EXPECT_NE(g, nullptr) << err;
    p.garments.push_back(g);
  }
  drape_backend_desc b;
  EXPECT_EQ(drape_backend_desc_init(&b), DRAPE_OK);
  b.backend = backend;
  EXPECT_EQ(p.ctx->setBackend(b, err), DRAPE_OK) << err;
  return p;
}

bool onDevice(const Person& p) {
  for (const GarmentSim* g : p.garments)
    if (!g || g->backend() != GarmentBackend::OpenCl) return false;
  return true;
}

// Frame f of a pose whose arms swing, so that the cloth moves. Returns the step's launches.
uint64_t stepFrame(Person& p, int f) {
  SkeletonPose pose = restPose(p.ctx->shape(), 35.0f + 3.0f * static_cast<float>(f));
  std::string err;
  Recording rec;
  rec.layout = Layout::Kinect2;
  const double t = f / 30.0;
  const uint64_t before = ClRuntime::processLaunchCount();
  EXPECT_EQ(test::pushAndStep(*p.ctx, rec, test::kinect2FromPose(pose, t), t, 1.0f / 30.0f, err), DRAPE_OK) << err;
  return ClRuntime::processLaunchCount() - before;
}

// The CPU's normals of the garment's current positions.
std::vector<Vec3> cpuNormals(const GarmentSim& g) {
  std::vector<Vec3> x(g.particleCount()), n(g.particleCount());
  for (size_t i = 0; i < x.size(); ++i) x[i] = g.positions()[i].head<3>();
  vertexNormals(x, g.indices(), n);
  return n;
}

float maxDiff(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  float d = 0.0f;
  for (size_t i = 0; i < a.size(); ++i) d = std::max(d, (a[i] - b[i]).cwiseAbs().maxCoeff());
  return d;
}

// Runs frames 0..5; the host reads normals after frames 2 and 3 only. Returns every read's normals
// (all garments) and checks launches, device use and the tolerance on the way.
std::vector<std::vector<Vec3>> runReadingNormals(Person& p) {
  std::vector<std::vector<Vec3>> reads;
  uint64_t base = 0;
  for (int f = 0; f < 6; ++f) {
    const uint64_t launches = stepFrame(p, f);
    SCOPED_TRACE("frame " + std::to_string(f));
    if (f == 1) base = launches;  // no normals asked for yet
    // Asked for after frames 2 and 3: frames 3 and 4 compute them on the device, one launch more.
    if (f == 3 || f == 4) EXPECT_EQ(launches, base + 1);
    if (f == 5) EXPECT_EQ(launches, base);  // nobody read them after frame 4
    if (f < 2 || f > 3) continue;
    for (GarmentSim* g : p.garments) {
      const std::vector<Vec3>& n = g->normals();
      // After frame 3, the device's normals of these positions (frame 2's: the CPU's).
      if (f == 3) EXPECT_NE(g->solverFace()->deviceNormals(), nullptr);
      const std::vector<Vec3> cpu = cpuNormals(*g);
      EXPECT_EQ(n.size(), cpu.size());
      if (n.size() != cpu.size()) continue;
      EXPECT_LT(maxDiff(n, cpu), 1e-5f);
      float worst = 0.0f;
      for (const Vec3& v : n) worst = std::max(worst, std::fabs(v.norm() - 1.0f));
      EXPECT_LT(worst, 1e-5f);
      reads.push_back(n);
    }
  }
  return reads;
}

TEST(OpenClNormals, DeviceNormalsMatchCpuAloneAndBatched) {
  Person alone = makePerson({600}, DRAPE_BACKEND_OPENCL);
  if (!onDevice(alone)) GTEST_SKIP() << "no usable OpenCL device";
  runReadingNormals(alone);
  Person batched = makePerson({400, 600}, DRAPE_BACKEND_OPENCL);
  const auto together = runReadingNormals(batched);
  setClFrameBatching(false);
  Person by_one = makePerson({400, 600}, DRAPE_BACKEND_OPENCL);
  std::vector<std::vector<Vec3>> separate;
  {
    // One by one each garment adds its own normals launch: count them outside runReadingNormals.
    for (int f = 0; f < 6; ++f) {
      stepFrame(by_one, f);
      if (f < 2 || f > 3) continue;
      for (GarmentSim* g : by_one.garments) separate.push_back(g->normals());
    }
  }
  setClFrameBatching(true);
  ASSERT_EQ(together.size(), separate.size());
  for (size_t k = 0; k < together.size(); ++k)
    EXPECT_EQ(std::memcmp(together[k].data(), separate[k].data(), together[k].size() * sizeof(Vec3)), 0)
        << "read " << k;
}

// Back to the CPU, the garment keeps the velocities it had on the device (they are what the
// device computed: read back bit for bit), so the cloth keeps moving.
TEST(OpenClBackendSwitch, BackToCpuKeepsVelocities) {
  Person p = makePerson({600}, DRAPE_BACKEND_OPENCL);
  if (!onDevice(p)) GTEST_SKIP() << "no usable OpenCL device";
  for (int f = 0; f < 4; ++f) stepFrame(p, f);
  GarmentSim& g = *p.garments[0];
  // On the device, collision has no time of its own: the whole frame is integrate (drape.h).
  EXPECT_EQ(g.lastStep().collide_ms, 0.0);
  EXPECT_GT(g.lastStep().total_ms, 0.0);
  const std::vector<Eigen::Vector4f> v(g.velocities(), g.velocities() + g.particleCount());
  float fastest = 0.0f;
  for (const Eigen::Vector4f& u : v) fastest = std::max(fastest, u.head<3>().norm());
  EXPECT_GT(fastest, 0.01f);  // moving, so the carry-over is seen
  drape_backend_desc b;
  ASSERT_EQ(drape_backend_desc_init(&b), DRAPE_OK);
  b.backend = DRAPE_BACKEND_CPU;
  std::string err;
  ASSERT_EQ(p.ctx->setBackend(b, err), DRAPE_OK) << err;
  ASSERT_EQ(g.backend(), GarmentBackend::Cpu);
  for (size_t i = 0; i < v.size(); ++i)
    ASSERT_EQ(std::memcmp(g.velocities()[i].data(), v[i].data(), 3 * sizeof(float)), 0) << "particle " << i;
  // And the CPU garment's normals are the CPU's (no device anymore).
  EXPECT_EQ(g.solverFace()->deviceNormals(), nullptr);
  // The next step runs on the CPU, whose collision is timed.
  stepFrame(p, 4);
  EXPECT_GT(g.lastStep().collide_ms, 0.0);
}

#endif  // DRAPE_HAVE_OPENCL

}  // namespace
}  // namespace drape
