// The adaptive pipeline (capi/adaptive.h, docs/adaptive.md): proxy culling builds only what the
// garments reach and leaves the cloth bit-identical, the body mesh is computed when read and is
// then the same, garments sleep on a still pose and wake at once, without a jump.
#include "garment_scene.h"
#include "sanitizer_scale.h"
#include "test_data.h"

#include "cloth/garment_reach.h"
#include "skeleton/layouts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>

namespace drape {
namespace {

PipelineOptions fullPipeline() {
  PipelineOptions o;
  o.cull_proxies = false;
  o.stages_on_demand = false;
  o.sleep = false;
  return o;
}

// The chains through which the garment collides with the ellipsoids it reaches now: each
// reachable ellipsoid's collision groups that some particle of the garment collides with (a
// shoulder fill is the arm's and the torso's: a skirt's waistband reaches it as torso).
std::set<Chain> reachedChains(Context& ctx, const GarmentSim& g) {
  uint8_t masks = 0;
  for (uint8_t m : g.particleMasks()) masks = static_cast<uint8_t>(masks | m);
  std::set<Chain> out;
  const auto& sources = ctx.proxies().sources();
  for (int k : g.reachable()) {
    const uint8_t groups = static_cast<uint8_t>(collisionGroups(sources[static_cast<size_t>(k)]) & masks);
    for (int c = 0; c < kChainCount; ++c)
      if (groups & (1u << c)) out.insert(static_cast<Chain>(c));
  }
  return out;
}

// Pushes `pose` (Kinect v2) at time t and steps dt.
void stepPose(Context& ctx, const SkeletonPose& pose, double t, float dt) {
  std::string err;
  Recording rec;
  rec.layout = Layout::Kinect2;
  const RecordingFrame f = test::kinect2FromPose(pose, t);
  ASSERT_EQ(test::pushAndStep(ctx, rec, f, t, dt, err), DRAPE_OK) << err;
}

struct Culled {
  GarmentKind kind;
  std::set<Chain> allowed;   // chains it may reach
  std::set<Chain> required;  // chains it must reach
  std::set<Chain> partly;    // chains of which it must reach some ellipsoids but not all
};

class ProxyCulling : public ::testing::TestWithParam<Culled> {};

TEST_P(ProxyCulling, BuildsOnlyWhatTheGarmentReaches) {
  Context ctx(test::defaultDesc());
  std::string err;
  GarmentSim* g = test::addTemplate(ctx, GetParam().kind, 1000, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
  ASSERT_NE(g, nullptr) << err;
  const SkeletonPose pose = restPose(ctx.shape());
  for (int f = 0; f < 3; ++f) stepPose(ctx, pose, f / 30.0, 1.0f / 30.0f);
  const SkipCounters c = ctx.skipCounters();
  EXPECT_GT(c.proxies_built, 0u);
  EXPECT_LT(c.proxies_built, c.proxies_available);
  EXPECT_EQ(c.proxies_built, g->reachable().size());
  EXPECT_TRUE(c.stages_skipped_last & kStageProxies);
  const std::set<Chain> chains = reachedChains(ctx, *g);
  for (Chain ch : chains) EXPECT_TRUE(GetParam().allowed.count(ch)) << "reaches chain " << chainName(ch);
  for (Chain ch : GetParam().required) EXPECT_TRUE(chains.count(ch)) << "does not reach chain " << chainName(ch);
  const auto& src = ctx.proxies().sources();
  for (Chain ch : GetParam().partly) {
    size_t n = 0, of = 0;
    for (const ProxySource& x : src) of += x.chain == ch ? 1 : 0;
    for (int k : g->reachable()) n += src[static_cast<size_t>(k)].chain == ch ? 1 : 0;
    EXPECT_GT(n, 0u) << chainName(ch);
    EXPECT_LT(n, of) << chainName(ch);
  }
  std::printf("[ figures  ] garment %d: %u of %u ellipsoids built:", static_cast<int>(GetParam().kind), c.proxies_built,
              c.proxies_available);
  // Per chain, and the shoulder fills (two chains each, ProxySource::also_chain) apart.
  const auto& sources = ctx.proxies().sources();
  auto isFill = [&](size_t k) { return sources[k].also_chain >= 0; };
  for (int ch = -1; ch < kChainCount; ++ch) {
    auto counts = [&](size_t k) { return ch < 0 ? isFill(k) : !isFill(k) && static_cast<int>(sources[k].chain) == ch; };
    int n = 0, of = 0;
    for (size_t k = 0; k < sources.size(); ++k) of += counts(k) ? 1 : 0;
    for (int k : g->reachable()) n += counts(static_cast<size_t>(k)) ? 1 : 0;
    if (ch >= 0) std::printf(" %s %d/%d", chainName(static_cast<Chain>(ch)), n, of);
    else std::printf(" shoulder_fills %d/%d;", n, of);
  }
  std::printf("\n");
}

// What each garment reaches standing (docs/adaptive.md has the counts): a skirt neither arm and
// not the feet; a T-shirt not the legs below the thigh; trousers no arm. The head chain starts at
// the base of the neck, within reach of a collar and (with the reach margin) of a waistband's
// upper cloth, so it is allowed everywhere.
INSTANTIATE_TEST_SUITE_P(
    Garments, ProxyCulling,
    ::testing::Values(Culled{GarmentKind::Skirt,
                             {Chain::Torso, Chain::Head, Chain::LegL, Chain::LegR},
                             {Chain::Torso, Chain::LegL, Chain::LegR},
                             {Chain::LegL, Chain::LegR}},
                      Culled{GarmentKind::TShirt,
                             {Chain::Torso, Chain::Head, Chain::ArmL, Chain::ArmR, Chain::LegL, Chain::LegR},
                             {Chain::Torso, Chain::ArmL, Chain::ArmR},
                             {Chain::LegL, Chain::LegR}},
                      Culled{GarmentKind::Trousers,
                             {Chain::Torso, Chain::Head, Chain::LegL, Chain::LegR},
                             {Chain::Torso, Chain::LegL, Chain::LegR},
                             {}}));

// The built set is the union over the garments, recomputed as garments come and go.
TEST(ProxyCulling, UnionFollowsGarmentsAddedAndRemoved) {
  Context ctx(test::defaultDesc());
  std::string err;
  GarmentSim* skirt = test::addTemplate(ctx, GarmentKind::Skirt, 400, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
  ASSERT_NE(skirt, nullptr) << err;
  const SkeletonPose pose = restPose(ctx.shape());
  double t = 0.0;
  auto frame = [&] {
    stepPose(ctx, pose, t, 1.0f / 30.0f);
    t += 1.0 / 30.0;
  };
  frame();
  const uint32_t skirtOnly = ctx.skipCounters().proxies_built;
  EXPECT_FALSE(reachedChains(ctx, *skirt).count(Chain::ArmL));
  GarmentSim* shirt = test::addTemplate(ctx, GarmentKind::TShirt, 400, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
  ASSERT_NE(shirt, nullptr) << err;
  frame();
  const uint32_t both = ctx.skipCounters().proxies_built;
  EXPECT_GT(both, skirtOnly);
  EXPECT_TRUE(reachedChains(ctx, *shirt).count(Chain::ArmL));
  std::set<int> u(skirt->reachable().begin(), skirt->reachable().end());
  u.insert(shirt->reachable().begin(), shirt->reachable().end());
  EXPECT_EQ(u.size(), both);  // exactly the union
  ASSERT_TRUE(ctx.removeGarment(shirt));
  frame();
  EXPECT_EQ(ctx.skipCounters().proxies_built, skirtOnly);
}

TEST(ProxyCulling, NoGarmentBuildsNoEllipsoidUntilRead) {
  Context ctx(test::defaultDesc());
  stepPose(ctx, restPose(ctx.shape()), 0.0, 1.0f / 30.0f);
  EXPECT_EQ(ctx.skipCounters().proxies_built, 0u);
  // Reading them builds them all, equal to a full pipeline's.
  Context full(test::defaultDesc());
  full.setPipelineOptions(fullPipeline());
  stepPose(full, restPose(full.shape()), 0.0, 1.0f / 30.0f);
  const auto& a = ctx.proxies().ellipsoids();
  const auto& b = full.proxies().ellipsoids();
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].centre, b[k].centre) << k;
    EXPECT_EQ(a[k].radii, b[k].radii) << k;
    EXPECT_EQ(a[k].rotation, b[k].rotation) << k;
  }
  EXPECT_EQ(ctx.skipCounters().proxies_built, a.size());
}

TEST(ProxyCulling, ReachSpheresFollowTheCut) {
  Context ctx(test::defaultDesc());
  std::string err;
  GarmentSim* skirt = test::addTemplate(ctx, GarmentKind::Skirt, 600, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
  ASSERT_NE(skirt, nullptr) << err;
  GarmentTemplateParams tp;
  tp.kind = GarmentKind::Skirt;
  tp.target_particles = 600;
  tp.length_scale = 1.5f;
  GarmentMesh mesh;
  ASSERT_TRUE(makeGarmentTemplate(ctx.restBody(), tp, mesh, err)) << err;
  auto longer = GarmentSim::create(mesh, TopologyParams{}, ClothSolverKind::Xpbd, GarmentSimParams{}, 0.2f,
                                   ctx.restBody(), ctx.restEllipsoids(), ctx.restEllipsoidGroups(), err);
  ASSERT_NE(longer, nullptr) << err;
  auto maxRadius = [](const std::vector<ReachSphere>& s) {
    float r = 0.0f;
    for (const ReachSphere& x : s) r = std::max(r, x.radius_m);
    return r;
  };
  const float a = maxRadius(garmentReach(*skirt, ReachParams{}));
  const float b = maxRadius(garmentReach(*longer, ReachParams{}));
  EXPECT_GT(a, 0.3f);  // a skirt hangs more than 30 cm from the waist
  EXPECT_GT(b, a + 0.1f);
}

// Replays a real take in two contexts, one with the given options and one with everything off,
// and requires every garment position to be bit-identical after every step.
void expectIdenticalCloth(GarmentKind kind, const char* file) {
  const std::string path = test::sharedFile(file);
  if (path.empty()) GTEST_SKIP() << file << " not found under " << test::sharedDataDir();
  Recording rec;
  std::string err;
  ASSERT_TRUE(readRecordingFile(path, 0, rec, err)) << err;
  Context full(test::defaultDesc()), culled(test::defaultDesc());
  full.setPipelineOptions(fullPipeline());
  PipelineOptions o;
  o.sleep = false;  // sleeping changes the result (within the error figures): tested below
  culled.setPipelineOptions(o);
  // Under the sanitizers 400 particles instead of 800: the same garment reaches the same
  // ellipsoids at any resolution (what culling decides by), and bit-identity holds particle by
  // particle, so the other 400 only repeat the same comparison; making and stepping them twice was
  // the ASan cost.
  const int particles = test::kSanitizedBuild ? 400 : 800;
  GarmentSim* gf = test::addTemplate(full, kind, particles, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
  GarmentSim* gc = test::addTemplate(culled, kind, particles, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
  ASSERT_TRUE(gf && gc) << err;
  const size_t frames = std::min<size_t>(rec.frames.size(), 90);
  double prev = rec.frames.front().time_s - 1.0 / 30.0;
  size_t culledFrames = 0;
  for (size_t i = 0; i < frames; ++i) {
    const RecordingFrame& f = rec.frames[i];
    const float dt = static_cast<float>(f.time_s - prev);
    prev = f.time_s;
    ASSERT_EQ(test::pushAndStep(full, rec, f, f.time_s, dt, err), DRAPE_OK) << err;
    ASSERT_EQ(test::pushAndStep(culled, rec, f, f.time_s, dt, err), DRAPE_OK) << err;
    culledFrames += culled.skipCounters().proxies_built < culled.skipCounters().proxies_available ? 1 : 0;
    ASSERT_EQ(std::memcmp(gf->positions(), gc->positions(), gf->particleCount() * sizeof(Eigen::Vector4f)), 0)
        << "frame " << i;
  }
  EXPECT_EQ(culledFrames, frames);
  // The body mesh read on demand is the one the full pipeline computed.
  const BodyModel& a = full.bodyMesh(true);
  const BodyModel& b = culled.bodyMesh(true);
  EXPECT_EQ(std::memcmp(a.positions().data(), b.positions().data(), a.positions().size() * sizeof(Vec3)), 0);
  EXPECT_EQ(std::memcmp(a.normals().data(), b.normals().data(), a.normals().size() * sizeof(Vec3)), 0);
}

TEST(ProxyCulling, SkirtClothBitIdenticalOnRealTake) {
  expectIdenticalCloth(GarmentKind::Skirt, "kinect_v2_msft_labanotation/Ges02_balancinghands.csv");
}
TEST(ProxyCulling, TShirtClothBitIdenticalOnRealTake) {
  expectIdenticalCloth(GarmentKind::TShirt, "kinect_v2_msft_labanotation/Ges01_wavehand.csv");
}

TEST(StagesOnDemand, MeshComputedWhenReadAndEqualToEager) {
  Context lazy(test::defaultDesc()), eager(test::defaultDesc());
  PipelineOptions o;
  o.stages_on_demand = false;
  eager.setPipelineOptions(o);
  SkeletonPose pose = restPose(lazy.shape());
  for (Vec3& p : pose.position) p += Vec3(0.1f, 0.0f, 2.0f);
  stepPose(lazy, pose, 0.0, 1.0f / 30.0f);
  stepPose(eager, pose, 0.0, 1.0f / 30.0f);
  EXPECT_EQ(lazy.skipCounters().stages_skipped_last & (kStageBodyMesh | kStageBodyNormals),
            kStageBodyMesh | kStageBodyNormals);
  EXPECT_EQ(eager.skipCounters().stages_skipped_last & (kStageBodyMesh | kStageBodyNormals), 0u);
  lazy.bodyMesh(false);
  EXPECT_EQ(lazy.skipCounters().stages_skipped_last & (kStageBodyMesh | kStageBodyNormals), kStageBodyNormals);
  const BodyModel& a = lazy.bodyMesh(true);
  EXPECT_EQ(lazy.skipCounters().stages_skipped_last & (kStageBodyMesh | kStageBodyNormals), 0u);
  const BodyModel& b = eager.body();
  ASSERT_EQ(a.positions().size(), b.positions().size());
  EXPECT_EQ(std::memcmp(a.positions().data(), b.positions().data(), a.positions().size() * sizeof(Vec3)), 0);
  EXPECT_EQ(std::memcmp(a.normals().data(), b.normals().data(), a.normals().size() * sizeof(Vec3)), 0);
  // A second frame not read counts two more skipped stages once the third frame arrives.
  const uint64_t before = lazy.skipCounters().stages_skipped;
  stepPose(lazy, pose, 1.0 / 30.0, 1.0f / 30.0f);
  stepPose(lazy, pose, 2.0 / 30.0, 1.0f / 30.0f);
  EXPECT_GE(lazy.skipCounters().stages_skipped, before + 4);
}

// A still pose: the garment falls asleep after the delay, stays asleep, and wakes the very step
// the body moves, continuing from where it slept.
TEST(Sleeping, StillPoseSleepsAndMotionWakesAtOnce) {
  Context ctx(test::defaultDesc()), full(test::defaultDesc());
  full.setPipelineOptions(fullPipeline());
  std::string err;
  GarmentSim* g = test::addTemplate(ctx, GarmentKind::Skirt, 600, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
  GarmentSim* gf = test::addTemplate(full, GarmentKind::Skirt, 600, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
  ASSERT_TRUE(g && gf) << err;
  const SkeletonPose pose = restPose(ctx.shape());
  const float dt = 1.0f / 30.0f;
  int frame = 0, sleptAt = -1;
  for (; frame < 300 && sleptAt < 0; ++frame) {
    stepPose(ctx, pose, frame * dt, dt);
    stepPose(full, pose, frame * dt, dt);
    if (ctx.garmentAsleep(g)) sleptAt = frame;
  }
  ASSERT_GE(sleptAt, 0) << "never fell asleep on a still pose";
  EXPECT_GE(sleptAt * dt, ctx.pipelineOptions().sleep_delay_s);  // not before the delay
  const uint64_t stepsAsleep = g->steps();
  for (int i = 0; i < 10; ++i, ++frame) {
    stepPose(ctx, pose, frame * dt, dt);
    stepPose(full, pose, frame * dt, dt);
  }
  EXPECT_EQ(g->steps(), stepsAsleep);  // no step while asleep
  const SkipCounters c = ctx.skipCounters();
  EXPECT_EQ(c.garments_asleep, 1u);
  EXPECT_GE(c.frames_slept, 10u);
  EXPECT_TRUE(c.stages_skipped_last & kStageCloth);
  EXPECT_EQ(c.proxies_built, 0u);  // nothing awake to collide with
  EXPECT_EQ(g->lastStep().substeps, 0);
  // The sleeping skirt is where the never-sleeping one still creeps to, within the creep of a
  // garment slower than sleep_speed_m_s.
  float gap = 0.0f;
  for (size_t i = 0; i < g->particleCount(); ++i)
    gap = std::max(gap, (g->positions()[i] - gf->positions()[i]).head<3>().norm());
  EXPECT_LT(gap, 5e-3f);
  // The body steps 30 cm aside: the skirt steps this very frame.
  std::vector<Vec3> before(g->particleCount()), beforeFull(gf->particleCount());
  for (size_t i = 0; i < before.size(); ++i) before[i] = g->positions()[i].head<3>();
  for (size_t i = 0; i < beforeFull.size(); ++i) beforeFull[i] = gf->positions()[i].head<3>();
  SkeletonPose moved = pose;
  for (Vec3& p : moved.position) p += Vec3(0.3f, 0.0f, 0.0f);
  stepPose(ctx, moved, frame * dt, dt);
  stepPose(full, moved, frame * dt, dt);
  ++frame;
  EXPECT_EQ(g->steps(), stepsAsleep + 1);
  EXPECT_FALSE(ctx.garmentAsleep(g));
  EXPECT_EQ(ctx.skipCounters().garments_asleep, 0u);
  EXPECT_FALSE(ctx.skipCounters().stages_skipped_last & kStageCloth);
  // No pop: every particle moves as far as in the never-sleeping pipeline (within the gap the
  // sleep left plus a millimetre), and the woken skirt is no farther from that one than before.
  float jumpDiff = 0.0f, gapAfter = 0.0f, jump = 0.0f;
  for (size_t i = 0; i < before.size(); ++i) {
    const float d = (g->positions()[i].head<3>() - before[i]).norm();
    const float df = (gf->positions()[i].head<3>() - beforeFull[i]).norm();
    jump = std::max(jump, d);
    jumpDiff = std::max(jumpDiff, std::fabs(d - df));
    gapAfter = std::max(gapAfter, (g->positions()[i] - gf->positions()[i]).head<3>().norm());
  }
  std::printf("[ figures  ] slept at frame %d, gap %.2f mm, skirt moved %.1f mm at the wake, %.2f mm more or less "
              "than never sleeping, gap after %.2f mm\n",
              sleptAt, gap * 1e3f, jump * 1e3f, jumpDiff * 1e3f, gapAfter * 1e3f);
  EXPECT_LT(jumpDiff, gap + 1e-3f);
  EXPECT_LT(gapAfter, gap + 1e-3f);
}

TEST(Sleeping, ParametersAndHostWakeIt) {
  Context ctx(test::defaultDesc());
  std::string err;
  GarmentSim* g = test::addTemplate(ctx, GarmentKind::TShirt, 500, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
  ASSERT_NE(g, nullptr) << err;
  const SkeletonPose pose = restPose(ctx.shape());
  const float dt = 1.0f / 30.0f;
  int frame = 0;
  auto sleepNow = [&] {
    for (int i = 0; i < 300 && !ctx.garmentAsleep(g); ++i, ++frame) stepPose(ctx, pose, frame * dt, dt);
    ASSERT_TRUE(ctx.garmentAsleep(g));
  };
  sleepNow();
  uint64_t steps = g->steps();
  ctx.wakeGarment(g);  // what drape_garment_set_params does after new parameters
  stepPose(ctx, pose, frame * dt, dt);
  ++frame;
  EXPECT_EQ(g->steps(), steps + 1);
  sleepNow();
  steps = g->steps();
  ctx.wakeAll();
  stepPose(ctx, pose, frame * dt, dt);
  ++frame;
  EXPECT_EQ(g->steps(), steps + 1);
  // A shape change wakes it too.
  sleepNow();
  steps = g->steps();
  BodyShapeInput in;
  in.height_m = 1.72f;
  ASSERT_EQ(ctx.setShape(in, err), DRAPE_OK) << err;
  stepPose(ctx, pose, frame * dt, dt);
  EXPECT_EQ(g->steps(), steps + 1);
}

TEST(Sleeping, OffNeverSleeps) {
  Context ctx(test::defaultDesc());
  PipelineOptions o;
  o.sleep = false;
  ctx.setPipelineOptions(o);
  std::string err;
  GarmentSim* g = test::addTemplate(ctx, GarmentKind::Skirt, 400, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
  ASSERT_NE(g, nullptr) << err;
  const SkeletonPose pose = restPose(ctx.shape());
  for (int f = 0; f < 60; ++f) stepPose(ctx, pose, f / 30.0, 1.0f / 30.0f);
  EXPECT_EQ(g->steps(), 60u);
  EXPECT_EQ(ctx.skipCounters().frames_slept, 0u);
}

TEST(PipelineOptions, Validation) {
  PipelineOptions o;
  EXPECT_EQ(validate(o), "");
  o.sleep_delay_s = -1.0f;
  EXPECT_NE(validate(o), "");
  o = PipelineOptions{};
  bool nonfinite = false;
  o.reach_margin_m = std::nanf("");
  EXPECT_NE(validate(o, &nonfinite), "");
  EXPECT_TRUE(nonfinite);
}

}  // namespace
}  // namespace drape
