// drape-bench's openings meter (samples/bench/metrics.h, OpeningsMeter), which counts the frames in
// which Bullet's cloth and Drape's have an opening off its body part by one rule for both: on a
// dressed T-shirt it tracks the hem, collar and two sleeves, as the library does, and finds none
// off on the synthetic take, as the library does; a garment moved a metre aside has every opening
// off; a sleeve lifted past the arm's shoulder end is off, and on again when put back.
#include "capi_test_support.h"
#include "metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace {

// A T-shirt stepped on the synthetic Kinect v2 pose (capi_test_support.h), and what the meter and
// the library read of it.
struct Scene {
  ContextPtr ctx = makeContext();
  drape_garment* garment = nullptr;
  uint32_t nv = 0, ni = 0;
  std::vector<uint32_t> indices;
  std::vector<drape_vec3> x;
  std::vector<drape_ellipsoid> ellipsoids;
  drape_garment_accuracy accuracy{};

  Scene() {
    drape_garment_template t;
    EXPECT_EQ(drape_garment_template_init(&t), DRAPE_OK);
    t.particles = 1000;
    EXPECT_EQ(drape_context_add_garment_template(ctx.get(), nullptr, &t, nullptr, &garment), DRAPE_OK) << lastError();
    EXPECT_EQ(drape_garment_get_mesh_size(garment, &nv, &ni), DRAPE_OK);
    indices.resize(ni);
    x.resize(nv);
    EXPECT_EQ(drape_garment_read_mesh(garment, nullptr, nullptr, 0, indices.data(), ni), DRAPE_OK);
  }
  // Frame i (30 Hz) pushed and stepped, then read.
  void step(int i) {
    const std::vector<drape_joint> j = poseJoints(DRAPE_LAYOUT_KINECT2, i / 30.0);
    const drape_skeleton_frame f = makeFrame(DRAPE_LAYOUT_KINECT2, j, i / 30.0);
    ASSERT_EQ(drape_context_push_skeleton(ctx.get(), &f), DRAPE_OK) << lastError();
    ASSERT_EQ(drape_context_step(ctx.get(), 1.0f / 30.0f), DRAPE_OK) << lastError();
    ASSERT_EQ(drape_garment_read_mesh(garment, x.data(), nullptr, nv, nullptr, 0), DRAPE_OK);
    uint32_t ne = 0;
    ASSERT_EQ(drape_context_get_ellipsoid_count(ctx.get(), &ne), DRAPE_OK);
    ellipsoids.resize(ne);
    ASSERT_EQ(drape_context_read_ellipsoids(ctx.get(), ellipsoids.data(), ne, nullptr), DRAPE_OK);
    accuracy.struct_size = sizeof accuracy;
    ASSERT_EQ(drape_garment_measure(garment, &accuracy), DRAPE_OK);
  }
};

}  // namespace

TEST(BenchOpeningsMeter, TracksWhatTheLibraryTracksAndFindsTheSameOff) {
  Scene s;
  for (int i = 0; i < 10; ++i) s.step(i);
  bench::OpeningsMeter meter;
  meter.bind(s.indices, s.x.data(), s.nv, s.ellipsoids);
  EXPECT_EQ(meter.tracked(), 4u);  // hem and collar round the spine, a cuff round each arm
  EXPECT_EQ(meter.tracked(), s.accuracy.openings);
  uint32_t library_off_frames = 0;
  for (int i = 10; i < 40; ++i) {
    s.step(i);
    meter.addFrame(s.x.data(), s.ellipsoids);
    library_off_frames += s.accuracy.openings_off > 0 ? 1u : 0u;
  }
  EXPECT_EQ(meter.offFraction(), library_off_frames / 30.0);
  EXPECT_EQ(library_off_frames, 0u);

  // The whole garment a metre aside: nothing goes round anything any more.
  std::vector<drape_vec3> aside = s.x;
  for (drape_vec3& p : aside) p.x += 1.0f;
  meter.addFrame(aside.data(), s.ellipsoids);
  EXPECT_DOUBLE_EQ(meter.offFraction(), 1.0 / 31.0);
}

TEST(BenchOpeningsMeter, ASleeveLiftedPastTheShoulderIsOffAndOnAgainWhenPutBack) {
  Scene s;
  for (int i = 0; i < 10; ++i) s.step(i);
  bench::OpeningsMeter meter;
  meter.bind(s.indices, s.x.data(), s.nv, s.ellipsoids);
  ASSERT_EQ(meter.tracked(), 4u);
  // The cloth on the right arm's side of the spine, further out than 0.6 of the arm's mean offset,
  // is that sleeve: lifted by 0.6 m its cuff lies above the shoulder, beyond the arm's end.
  const float spine_x = s.ellipsoids[0].centre.x;
  float side = 0.0f;
  int arm = 0;
  for (const drape_ellipsoid& e : s.ellipsoids) {
    if (e.chain != 3) continue;  // the right arm
    side += e.centre.x - spine_x;
    ++arm;
  }
  ASSERT_GT(arm, 0);
  side /= static_cast<float>(arm);
  std::vector<drape_vec3> lifted = s.x;
  int moved = 0;
  for (drape_vec3& p : lifted) {
    if ((p.x - spine_x) * side > 0.0f && std::fabs(p.x - spine_x) > 0.6f * std::fabs(side)) {
      p.y += 0.6f;
      ++moved;
    }
  }
  ASSERT_GT(moved, 20);
  meter.addFrame(lifted.data(), s.ellipsoids);
  EXPECT_EQ(meter.offFraction(), 1.0);
  meter.addFrame(s.x.data(), s.ellipsoids);
  EXPECT_EQ(meter.offFraction(), 0.5);
}
