// Recovery from tracking glitches (cloth/garment_recovery.cpp): a skeleton flipped upside down for
// half a second and then back gets the garment it had before the flip, not a second re-placement
// by skinning; a jump to a different pose, or one that comes back too late, is re-placed as
// before; a burst of 5 cm sensor noise ends with the garment restored to its state before the
// burst, swept to the current pose. Driven through drape::Context with the tracker in the loop.
#include "garment_scene.h"
#include "random_draws.h"
#include "test_data.h"

#include "cloth/garment_sim.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace drape {
namespace {

// The rest pose with a slow sideways sway (so the cloth is moving, not resting).
SkeletonPose swaying(const SkeletonPose& rest, double t) {
  SkeletonPose p = rest;
  const float x = 0.05f * static_cast<float>(std::sin(2.0 * t));
  for (Vec3& j : p.position) j += Vec3(x, 0.0f, 0.0f);
  return p;
}

// Every joint reflected through the pelvis: the skeleton upside down (a Kinect tracking glitch).
SkeletonPose flipped(const SkeletonPose& p) {
  SkeletonPose out = p;
  const Vec3 c = p.position[static_cast<size_t>(Joint::Pelvis)];
  for (Vec3& j : out.position) j = 2.0f * c - j;
  return out;
}

// Bent forward by `rad` at the middle of the spine: everything from the base of the neck up (head,
// shoulders, arms) turns round SpineMid. Relative to the pelvis the collar and the shoulders move
// by ~0.3 m at 70 degrees: another pose than the one the garment left.
SkeletonPose bent(const SkeletonPose& p, float rad) {
  SkeletonPose out = p;
  const Vec3 c = p.position[static_cast<size_t>(Joint::SpineMid)];
  const Mat3 R = Eigen::AngleAxisf(rad, Vec3::UnitX()).toRotationMatrix();
  for (int j = idx(Joint::SpineShoulder); j <= idx(Joint::HandR); ++j)
    out.position[static_cast<size_t>(j)] = R * (p.position[static_cast<size_t>(j)] - c) + c;
  return out;
}

struct JumpScene {
  std::unique_ptr<Context> ctx;
  GarmentSim* garment = nullptr;
  SkeletonPose rest;
  double t = 0.0;

  explicit JumpScene(int particles = 600) {
    ctx = std::make_unique<Context>(test::defaultDesc());
    PipelineOptions o = ctx->pipelineOptions();
    o.sleep = false;
    ctx->setPipelineOptions(o);
    std::string err;
    garment = test::addTemplate(*ctx, GarmentKind::TShirt, particles, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
    EXPECT_NE(garment, nullptr) << err;
    rest = restPose(ctx->shape());
  }
  void step(const SkeletonPose& pose) {
    std::string err;
    Recording rec;
    rec.layout = Layout::Kinect2;
    t += 1.0 / 30.0;
    ASSERT_EQ(test::pushAndStep(*ctx, rec, test::kinect2FromPose(pose, t), t, 1.0f / 30.0f, err), DRAPE_OK) << err;
  }
  std::vector<Vec3> positions() const {
    std::vector<Vec3> x(garment->particleCount());
    for (size_t i = 0; i < x.size(); ++i) x[i] = garment->positions()[i].head<3>();
    return x;
  }
};

float maxDistance(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  float d = 0.0f;
  for (size_t i = 0; i < a.size(); ++i) d = std::max(d, (a[i] - b[i]).norm());
  return d;
}

TEST(GarmentRecovery, FlipThatComesBackRestoresTheGarment) {
  JumpScene s;
  ASSERT_NE(s.garment, nullptr);
  for (int f = 0; f < 60; ++f) s.step(swaying(s.rest, s.t));
  const std::vector<Vec3> before = s.positions();
  const double t_flip = s.t;
  int resets = 0;
  for (int f = 0; f < 15; ++f) {
    s.step(flipped(swaying(s.rest, s.t)));
    resets += s.garment->lastStep().teleport_reset ? 1 : 0;
  }
  EXPECT_EQ(resets, 1) << "the flip is one pose jump: the garment is re-placed once";
  EXPECT_EQ(s.garment->poseJumpRestores(), 0u);
  const std::vector<Vec3> upside_down = s.positions();
  EXPECT_GT(maxDistance(before, upside_down), 0.5f) << "upside down, the shirt hangs elsewhere";

  s.step(swaying(s.rest, s.t));
  EXPECT_TRUE(s.garment->lastStep().teleport_reset);
  EXPECT_EQ(s.garment->poseJumpRestores(), 1u);
  // Back where it was, up to the sway since (5 cm amplitude) and one frame of simulation.
  const std::vector<Vec3> back = s.positions();
  const float sway = 0.05f * static_cast<float>(std::fabs(std::sin(2.0 * s.t) - std::sin(2.0 * t_flip)));
  EXPECT_LT(maxDistance(before, back), sway + 0.04f);
  // And it is a healthy garment: as stretched as before the flip, nothing inside the body parts.
  const GarmentAccuracy a = s.ctx->measureGarment(*s.garment);
  EXPECT_EQ(a.proxy_inside, 0u);
  for (int f = 0; f < 30; ++f) s.step(swaying(s.rest, s.t));
  EXPECT_EQ(s.garment->poseJumpRestores(), 1u);
}

TEST(GarmentRecovery, JumpToAnotherPoseIsReplacedNotRestored) {
  JumpScene s;
  ASSERT_NE(s.garment, nullptr);
  for (int f = 0; f < 60; ++f) s.step(s.rest);
  for (int f = 0; f < 10; ++f) s.step(flipped(s.rest));
  // Back upright but bent forward 70 degrees at the waist: the old garment would not fit.
  int resets = 0;
  for (int f = 0; f < 10; ++f) {
    s.step(bent(s.rest, 1.22f));
    resets += s.garment->lastStep().teleport_reset ? 1 : 0;
  }
  EXPECT_EQ(resets, 1) << "coming back upright is a pose jump";
  EXPECT_EQ(s.garment->poseJumpRestores(), 0u);
  EXPECT_EQ(s.ctx->measureGarment(*s.garment).proxy_inside, 0u);
}

TEST(GarmentRecovery, FlipThatComesBackTooLateIsReplaced) {
  JumpScene s(300);
  ASSERT_NE(s.garment, nullptr);
  for (int f = 0; f < 40; ++f) s.step(s.rest);
  for (int f = 0; f < 6 * 30; ++f) s.step(flipped(s.rest));  // longer than the 5 s kept
  s.step(s.rest);
  EXPECT_TRUE(s.garment->lastStep().teleport_reset);
  EXPECT_EQ(s.garment->poseJumpRestores(), 0u);
}

// Every joint moved by Gaussian noise of `sigma` metres per coordinate.
SkeletonPose jittered(const SkeletonPose& p, float sigma, std::mt19937& rng) {
  std::normal_distribution<float> n(0.0f, sigma);
  SkeletonPose out = p;
  for (Vec3& j : out.position) j += test::draw3(n, rng);
  return out;
}

TEST(GarmentRecovery, NoiseBurstEndsWithTheGarmentFromBeforeIt) {
  JumpScene s, control;
  ASSERT_NE(s.garment, nullptr);
  ASSERT_NE(control.garment, nullptr);
  std::mt19937 rng(11);
  for (int f = 0; f < 60; ++f) {
    s.step(swaying(s.rest, s.t));
    control.step(swaying(control.rest, control.t));
  }
  for (int f = 0; f < 60; ++f) {  // two seconds of 5 cm jitter on every joint
    s.step(jittered(swaying(s.rest, s.t), 0.05f, rng));
    control.step(swaying(control.rest, control.t));
  }
  EXPECT_EQ(s.garment->noiseBurstRestores(), 0u) << "restored before the burst ended";
  int frames_to_restore = -1;
  for (int f = 0; f < 45; ++f) {
    s.step(swaying(s.rest, s.t));
    control.step(swaying(control.rest, control.t));
    if (frames_to_restore < 0 && s.garment->noiseBurstRestores() == 1) frames_to_restore = f;
  }
  ASSERT_GE(frames_to_restore, 0) << "the burst's end was not seen within 1.5 s";
  EXPECT_LE(frames_to_restore, 30) << "restored later than a second after the burst";
  std::printf("[ recovery ] restored %d frames after the burst\n", frames_to_restore);
  // The restored garment follows the never-disturbed twin: mean distance of the particles.
  const std::vector<Vec3> a = s.positions(), b = control.positions();
  double sum = 0.0;
  for (size_t i = 0; i < a.size(); ++i) sum += (a[i] - b[i]).norm();
  EXPECT_LT(sum / static_cast<double>(a.size()), 0.02) << "mean distance to the undisturbed twin";
  EXPECT_EQ(s.ctx->measureGarment(*s.garment).proxy_inside, 0u);
}

TEST(GarmentRecovery, CleanMotionNeverLooksLikeANoiseBurst) {
  JumpScene s;
  ASSERT_NE(s.garment, nullptr);
  std::mt19937 rng(5);
  // 2 cm of jitter is within what the filters handle: no burst, no restore.
  for (int f = 0; f < 30; ++f) s.step(swaying(s.rest, s.t));
  for (int f = 0; f < 60; ++f) s.step(jittered(swaying(s.rest, s.t), 0.02f, rng));
  for (int f = 0; f < 30; ++f) s.step(swaying(s.rest, s.t));
  EXPECT_EQ(s.garment->noiseBurstRestores(), 0u);
  EXPECT_EQ(s.garment->poseJumpRestores(), 0u);
}

}  // namespace
}  // namespace drape
