// A garment worn while the host changes the body shape (Context::setShape, GarmentSim::refitted):
// it keeps its particles, triangles and handle; its cut follows the new body, so it is stretched
// about as much as a garment made for that body, where keeping the old cut stretched it by
// hundreds of per cent (docs/garments.md, "Body shape changes"); changing back restores the
// original cut; the same shape again changes nothing; a refused shape changes nothing. Driven through drape::Context with the tracker in the loop.
#include "garment_scene.h"

#include "cloth/garment_sim.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace drape {
namespace {

BodyShapeInput bodyOfHeightBmi(float height_m, float bmi) {
  BodyShapeInput in;
  in.height_m = height_m;
  in.weight_kg = bmi * height_m * height_m;
  return in;
}

// A context with one T-shirt, stepped on the rest pose of its current shape with a slow sway.
struct Wearer {
  std::unique_ptr<Context> ctx;
  GarmentSim* garment = nullptr;
  double t = 0.0;

  float strain_limit = GarmentSimParams{}.xpbd.strain_limit;

  explicit Wearer(const BodyShapeInput& shape, bool dressed = true, float limit = GarmentSimParams{}.xpbd.strain_limit)
      : strain_limit(limit) {
    ctx = std::make_unique<Context>(test::defaultDesc());
    PipelineOptions o = ctx->pipelineOptions();
    o.sleep = false;
    ctx->setPipelineOptions(o);
    std::string err;
    EXPECT_EQ(ctx->setShape(shape, err), DRAPE_OK) << err;
    if (dressed) dress();
  }
  void dress() {
    std::string err;
    GarmentSimParams params;
    params.xpbd.strain_limit = strain_limit;
    garment = test::addTemplate(*ctx, GarmentKind::TShirt, 600, ClothSolverKind::Xpbd, params, err);
    EXPECT_NE(garment, nullptr) << err;
  }
  // One 1/30 s frame of the current shape's rest pose, swaying 5 cm sideways.
  void step() {
    SkeletonPose pose = restPose(ctx->shape());
    const float x = 0.05f * static_cast<float>(std::sin(2.0 * t));
    for (Vec3& j : pose.position) j += Vec3(x, 0.0f, 0.0f);
    std::string err;
    Recording rec;
    rec.layout = Layout::Kinect2;
    t += 1.0 / 30.0;
    ASSERT_EQ(test::pushAndStep(*ctx, rec, test::kinect2FromPose(pose, t), t, 1.0f / 30.0f, err), DRAPE_OK) << err;
  }
  // Median over `frames` frames of the per-frame P99 stretch; inside = particles inside an
  // ellipsoid, summed.
  float medianP99(int frames, uint64_t* inside = nullptr) {
    std::vector<float> p99;
    for (int f = 0; f < frames; ++f) {
      step();
      const GarmentAccuracy a = garment->measure(ctx->proxies().ellipsoids(), nullptr);
      p99.push_back(a.stretch.p99);
      if (inside) *inside += a.proxy_inside;
    }
    std::sort(p99.begin(), p99.end());
    return p99[p99.size() / 2];
  }
};

const BodyShapeInput kDefaultBody = bodyOfHeightBmi(1.70f, 65.0f / (1.70f * 1.70f));
const BodyShapeInput kTallHeavy = bodyOfHeightBmi(2.1f, 40.0f);
const BodyShapeInput kShortThin = bodyOfHeightBmi(1.2f, 16.0f);

// Refitted against made for the body, both without the strain limit (the comparison this test was
// calibrated on), then the refit with the limit (the default) against the refit without it. With
// the limit the garment made for the 1.2 m body falls to a median P99 of 0.114 while the refitted
// one stays at 0.207 (0.229 without the limit): 21 edges, none pinned, 1.06-1.12 m above the
// floor, stay 15-66 % long after the limit's passes (a diagnostic, not kept), a tight spot the
// fresh cut does not have (docs/garments.md, "A strain limit at the end of each step").
TEST(GarmentRefit, FitsTheNewBodyAboutAsWellAsAGarmentMadeForIt) {
  for (const BodyShapeInput& other : {kTallHeavy, kShortThin}) {
    float refitted_by_limit[2] = {0.0f, 0.0f};
    for (int with_limit = 0; with_limit < 2; ++with_limit) {
      const float limit = with_limit ? GarmentSimParams{}.xpbd.strain_limit : 0.0f;
      Wearer worn(kDefaultBody, true, limit);
      ASSERT_NE(worn.garment, nullptr);
      const size_t particles = worn.garment->particleCount();
      const std::vector<uint32_t> triangles = worn.garment->indices();
      const float before = worn.medianP99(30);
      std::string err;
      ASSERT_EQ(worn.ctx->setShape(other, err), DRAPE_OK) << err;
      ASSERT_EQ(worn.ctx->garmentCount(), 1u);
      EXPECT_EQ(&worn.ctx->garment(0), worn.garment) << "the same garment object (the C ABI handle)";
      EXPECT_EQ(worn.garment->particleCount(), particles);
      EXPECT_EQ(worn.garment->indices(), triangles);
      uint64_t inside = 0;
      const float refitted = worn.medianP99(45, &inside);
      refitted_by_limit[with_limit] = refitted;

      // The same template made for the other body, at the same moment of the same take: the tracker
      // calibrated its bone lengths on the first person (SkeletonTracker), so both garments meet
      // the same tracked skeleton.
      Wearer made(kDefaultBody, /*dressed=*/false, limit);
      for (int f = 0; f < 30; ++f) made.step();
      ASSERT_EQ(made.ctx->setShape(other, err), DRAPE_OK) << err;
      made.dress();
      ASSERT_NE(made.garment, nullptr);
      const float fresh = made.medianP99(45);
      std::printf("[ figures  ] %.1f m, %.0f kg, strain limit %.2f: P99 stretch before %.3f, refitted %.3f, made for it "
                  "%.3f; inside %llu\n",
                  other.height_m, other.weight_kg, limit, before, refitted, fresh, static_cast<unsigned long long>(inside));
      // Without the refit the old cut on these bodies reached P99 2.9-4.3 (docs/robustness.md).
      if (!with_limit) EXPECT_LT(refitted, fresh + 0.05f) << other.height_m << " m";
      EXPECT_LT(refitted, 0.4f) << other.height_m << " m";  // measured 0.06-0.23
      EXPECT_LT(static_cast<double>(inside), 0.005 * 45.0 * static_cast<double>(particles));
      for (size_t i = 0; i < particles; ++i) ASSERT_TRUE(worn.garment->positions()[i].allFinite());
    }
    // The limit does not make the refitted garment worse.
    EXPECT_LT(refitted_by_limit[1], refitted_by_limit[0] + 0.02f) << other.height_m << " m";
  }
}

TEST(GarmentRefit, ChangingBackRestoresTheOriginalCut) {
  Wearer w(kDefaultBody);
  ASSERT_NE(w.garment, nullptr);
  const DistanceConstraints original = w.garment->topology().stretch;
  std::string err;
  for (const BodyShapeInput& s : {kTallHeavy, kShortThin, kDefaultBody}) {
    ASSERT_EQ(w.ctx->setShape(s, err), DRAPE_OK) << err;
    w.step();
    if (&s == &kTallHeavy) {
      // The cut grew with the body: the summed rest length of the edges is longer.
      double a = 0.0, b = 0.0;
      for (float r : original.rest) a += r;
      for (float r : w.garment->topology().stretch.rest) b += r;
      EXPECT_GT(b, 1.1 * a);
    }
  }
  const DistanceConstraints& back = w.garment->topology().stretch;
  ASSERT_EQ(back.size(), original.size());
  // Carried from the original cut each time (not from the last refit), so only the ring skinning's
  // round trip on the same body separates the two.
  float worst = 0.0f;
  for (size_t k = 0; k < back.size(); ++k) {
    EXPECT_EQ(back.a[k], original.a[k]);
    EXPECT_EQ(back.b[k], original.b[k]);
    worst = std::max(worst, std::fabs(back.rest[k] / original.rest[k] - 1.0f));
  }
  std::printf("[ figures  ] worst relative rest-length change after a round trip: %.2e\n", worst);
  EXPECT_LT(worst, 0.01f);
}

TEST(GarmentRefit, TheSameShapeAgainChangesNothing) {
  Wearer a(kTallHeavy), b(kTallHeavy);
  ASSERT_NE(a.garment, nullptr);
  ASSERT_NE(b.garment, nullptr);
  std::string err;
  for (int f = 0; f < 20; ++f) {
    ASSERT_EQ(a.ctx->setShape(kTallHeavy, err), DRAPE_OK) << err;  // as a host might, every frame
    a.step();
    b.step();
  }
  for (size_t i = 0; i < a.garment->particleCount(); ++i)
    ASSERT_EQ(a.garment->positions()[i], b.garment->positions()[i]) << "particle " << i;
}

TEST(GarmentRefit, ARejectedShapeLeavesTheGarmentBitIdentical) {
  // (The other failure, a garment whose dressing on the new body is not finite, restores the old
  // shape the same way; no valid parameters reach it, so it is not provoked here.)
  Wearer w(kDefaultBody);
  ASSERT_NE(w.garment, nullptr);
  for (int f = 0; f < 10; ++f) w.step();
  std::vector<Eigen::Vector4f> before(w.garment->positions(), w.garment->positions() + w.garment->particleCount());
  const std::vector<float> rest = w.garment->topology().stretch.rest;
  std::string err;
  BodyShapeInput bad = kTallHeavy;
  bad.height_m = std::nanf("");
  EXPECT_EQ(w.ctx->setShape(bad, err), DRAPE_ERROR_NONFINITE);
  bad = kTallHeavy;
  bad.weight_kg = 1000.0f;
  EXPECT_EQ(w.ctx->setShape(bad, err), DRAPE_ERROR_OUT_OF_RANGE);
  for (size_t i = 0; i < before.size(); ++i) ASSERT_EQ(w.garment->positions()[i], before[i]);
  EXPECT_EQ(w.garment->topology().stretch.rest, rest);
}

}  // namespace
}  // namespace drape
