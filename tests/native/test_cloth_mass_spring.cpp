// The paper's mass-spring baseline (native/src/cloth/mass_spring_solver.h) on the hanging square,
// and the contrast with XPBD at a game frame rate: same substep count, XPBD stable, mass-spring
// explodes (caught by the NaN guard) or stretches far more.
#include "cloth/cloth_stats.h"
#include "cloth/mass_spring_solver.h"
#include "cloth/xpbd_solver.h"

#include "sanitizer_scale.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

namespace drape {
namespace {

GarmentTopology square(int n, bool vertical) {
  std::vector<float> positions;
  std::vector<uint32_t> indices;
  makeClothGrid(n, n, 1.0f, 1.0f, Vec3::Zero(), Vec3::UnitX(),
                vertical ? Vec3(-Vec3::UnitY()) : Vec3(Vec3::UnitZ()), positions, indices);
  TopologyParams p;
  p.area_density = 0.2f;
  p.pinned = {0, static_cast<uint32_t>(n - 1)};
  GarmentTopology t;
  std::string error;
  EXPECT_TRUE(buildGarmentTopology(positions.data(), positions.size() / 3, indices.data(),
                                   indices.size(), p, t, error))
      << error;
  return t;
}

bool allFinite(const Eigen::Vector4f* x, size_t n) {
  for (size_t i = 0; i < n; ++i)
    if (!x[i].allFinite()) return false;
  return true;
}

TEST(ClothMassSpring, HangingSquareWithEnoughSubsteps) {
  MassSpringSolver s(square(30, true));
  const int frames = test::repeatsUnderSanitizers(300, 5);  // 5 s (1 s under the sanitizers)
  for (int f = 0; f < frames; ++f) ASSERT_TRUE(s.step(1.0f / 60.0f, 48)) << "frame " << f;
  std::vector<float> scratch;
  const StretchStats st = stretchStats(s.topology(), s.positions(), scratch);
  std::printf("mass-spring 30x30, 48 substeps at 60 Hz, after %d frames: stretch max %.4f P99 %.4f "
              "mean %.4f, max speed %.3g m/s\n", frames,
              static_cast<double>(st.max), static_cast<double>(st.p99),
              static_cast<double>(st.mean),
              static_cast<double>(maxSpeed(s.velocities(), s.particleCount())));
  EXPECT_EQ(s.explosions(), 0u);
  EXPECT_TRUE(allFinite(s.positions(), s.particleCount()));
  EXPECT_TRUE(std::isfinite(st.p99));
  EXPECT_LT(st.max, 1.0f);  // not blown up
  EXPECT_EQ(s.positions()[0].head<3>(), Vec3::Zero());
}

TEST(ClothMassSpring, GameFrameRateContrastWithXpbd) {
  // Released horizontal, dt = 1/30 s, XPBD's default substep count for both.
  const int substeps = XpbdSolver::kDefaultSubsteps;
  XpbdSolver x(square(30, false));
  MassSpringSolver m(square(30, false));
  int ms_failed_steps = 0;
  for (int f = 0; f < 90; ++f) {  // 3 s
    ASSERT_TRUE(x.step(1.0f / 30.0f, substeps));
    if (!m.step(1.0f / 30.0f, substeps)) ++ms_failed_steps;
  }
  std::vector<float> scratch;
  const StretchStats sx = stretchStats(x.topology(), x.positions(), scratch);
  const StretchStats sm = stretchStats(m.topology(), m.positions(), scratch);
  std::printf("dt 1/30 s, %d substeps, 3 s: XPBD stretch P99 %.4f max %.4f; mass-spring stretch "
              "P99 %.4f max %.4f, explosions %u\n",
              substeps, static_cast<double>(sx.p99), static_cast<double>(sx.max),
              static_cast<double>(sm.p99), static_cast<double>(sm.max), m.explosions());
  EXPECT_TRUE(allFinite(x.positions(), x.particleCount()));
  EXPECT_LT(sx.p99, 0.05f);
  EXPECT_LT(x.positions()[435].y(), -0.3f);  // XPBD's cloth did fall and swing
  // The guard keeps mass-spring's state finite; it either exploded or stretched far more.
  EXPECT_TRUE(allFinite(m.positions(), m.particleCount()));
  EXPECT_EQ(static_cast<int>(m.explosions()), ms_failed_steps);
  EXPECT_TRUE(m.explosions() > 0 || sm.p99 > 5.0f * sx.p99);
}

TEST(ClothMassSpring, ExplosionRestoresTheLastGoodState) {
  MassSpringSolver s(square(10, true));
  MassSpringParams p;
  p.stretch_stiffness = 1e6f;  // far beyond the stability limit at h = 1/60 s
  std::string error;
  ASSERT_TRUE(s.setParams(p, error)) << error;
  int failures = 0;
  for (int f = 0; f < 20; ++f) {
    const std::vector<Eigen::Vector4f> before(s.positions(), s.positions() + s.particleCount());
    if (!s.step(1.0f / 60.0f, 1)) {
      ++failures;
      EXPECT_EQ(std::memcmp(before.data(), s.positions(), before.size() * sizeof(before[0])), 0)
          << "frame " << f << ": the failed step must leave the state it started from";
    }
  }
  EXPECT_GT(failures, 0);
  EXPECT_EQ(static_cast<int>(s.explosions()), failures);
  EXPECT_TRUE(allFinite(s.positions(), s.particleCount()));
}

TEST(ClothMassSpring, RejectsBadArguments) {
  MassSpringSolver s(square(6, true));
  std::string error;
  MassSpringParams p;
  p.stretch_stiffness = -1.0f;
  EXPECT_FALSE(s.setParams(p, error));
  EXPECT_FALSE(error.empty());
  p = MassSpringParams{};
  p.explosion_speed = 0.0f;
  EXPECT_FALSE(s.setParams(p, error));
  EXPECT_EQ(s.params().stretch_stiffness, MassSpringParams{}.stretch_stiffness);
  EXPECT_FALSE(s.step(0.0f, 10));
  EXPECT_FALSE(s.step(1.0f / 60.0f, 0));
  EXPECT_EQ(s.explosions(), 0u);  // rejected calls are not explosions
  const Vec3 one[1] = {Vec3::Zero()};
  EXPECT_FALSE(s.setPinTargets(one, 1, error));
}

}  // namespace
}  // namespace drape
