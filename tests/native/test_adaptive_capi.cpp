// The adaptive pipeline through the C ABI: options (defaults, round trip, every rejection leaving
// them as they were), skip statistics, sleeping and what wakes a garment, reads that build what
// was skipped.
#include "capi_test_support.h"

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

namespace {

drape_garment* addGarment(drape_context* ctx, int32_t kind, uint32_t particles) {
  drape_garment_template t;
  EXPECT_EQ(drape_garment_template_init(&t), DRAPE_OK);
  t.kind = kind;
  t.particles = particles;
  drape_garment* g = nullptr;
  EXPECT_EQ(drape_context_add_garment_template(ctx, nullptr, &t, nullptr, &g), DRAPE_OK) << lastError();
  return g;
}

// Pushes a still Kinect v2 pose (the synthetic one at t = 0, shifted by dx) at frame i, steps 1/30 s.
drape_result stillStep(drape_context* ctx, int i, float dx = 0.0f) {
  std::vector<drape_joint> j = poseJoints(DRAPE_LAYOUT_KINECT2, 0.0);
  for (drape_joint& q : j) q.position.x += dx;
  const drape_skeleton_frame f = makeFrame(DRAPE_LAYOUT_KINECT2, j, i / 30.0);
  if (drape_result r = drape_context_push_skeleton(ctx, &f)) return r;
  return drape_context_step(ctx, 1.0f / 30.0f);
}

drape_skip_stats skipStats(drape_context* ctx) {
  drape_skip_stats s;
  std::memset(&s, 0, sizeof(s));
  s.struct_size = sizeof(s);
  EXPECT_EQ(drape_context_get_skip_stats(ctx, &s), DRAPE_OK) << lastError();
  return s;
}

uint64_t garmentSteps(drape_garment* g) {
  drape_garment_stats s;
  std::memset(&s, 0, sizeof(s));
  s.struct_size = sizeof(s);
  EXPECT_EQ(drape_garment_get_stats(g, &s), DRAPE_OK) << lastError();
  return s.steps;
}

TEST(CApiPipeline, DefaultsAndRoundTrip) {
  drape_pipeline_options o;
  ASSERT_OK(drape_pipeline_options_init(&o));
  EXPECT_EQ(o.struct_size, sizeof(o));
  EXPECT_EQ(o.cull_proxies, 1u);
  EXPECT_EQ(o.stages_on_demand, 1u);
  EXPECT_EQ(o.sleep, 1u);
  EXPECT_FLOAT_EQ(o.sleep_delay_s, 0.5f);
  EXPECT_FLOAT_EQ(o.sleep_distance_m, 0.005f);
  EXPECT_FLOAT_EQ(o.sleep_speed_m_s, 0.02f);
  EXPECT_FLOAT_EQ(o.reach_margin_m, 0.1f);
  EXPECT_EQ(o.reserved, 0u);
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_pipeline_options_init", drape_pipeline_options_init(nullptr));

  ContextPtr ctx = makeContext();
  drape_pipeline_options got;
  std::memset(&got, 0, sizeof(got));
  got.struct_size = sizeof(got);
  ASSERT_OK(drape_context_get_pipeline_options(ctx.get(), &got));
  EXPECT_EQ(std::memcmp(&got, &o, sizeof(o)), 0);  // a new context has the defaults
  o.sleep = 0;
  o.cull_proxies = 0;
  o.sleep_delay_s = 2.0f;
  o.reach_margin_m = 0.25f;
  ASSERT_OK(drape_context_set_pipeline_options(ctx.get(), &o));
  ASSERT_OK(drape_context_get_pipeline_options(ctx.get(), &got));
  EXPECT_EQ(std::memcmp(&got, &o, sizeof(o)), 0);
}

TEST(CApiPipeline, BadOptionsAreRejectedAndChangeNothing) {
  ContextPtr ctx = makeContext();
  drape_pipeline_options good;
  ASSERT_OK(drape_pipeline_options_init(&good));
  good.sleep_delay_s = 1.0f;
  ASSERT_OK(drape_context_set_pipeline_options(ctx.get(), &good));
  const char* fn = "drape_context_set_pipeline_options";
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, fn, drape_context_set_pipeline_options(nullptr, &good));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, fn, drape_context_set_pipeline_options(ctx.get(), nullptr));
  drape_context* dead = nullptr;
  ASSERT_OK(drape_context_create(nullptr, &dead));
  ASSERT_OK(drape_context_destroy(dead));
  EXPECT_FAILS(DRAPE_ERROR_INVALID_HANDLE, fn, drape_context_set_pipeline_options(dead, &good));
  struct Case {
    void (*change)(drape_pipeline_options&);
    drape_result code;
  };
  const Case cases[] = {
      {[](drape_pipeline_options& o) { o.struct_size = 0; }, DRAPE_ERROR_INVALID_ARGUMENT},
      {[](drape_pipeline_options& o) { o.cull_proxies = 2; }, DRAPE_ERROR_OUT_OF_RANGE},
      {[](drape_pipeline_options& o) { o.stages_on_demand = 7; }, DRAPE_ERROR_OUT_OF_RANGE},
      {[](drape_pipeline_options& o) { o.sleep = 0xFFFFFFFFu; }, DRAPE_ERROR_OUT_OF_RANGE},
      {[](drape_pipeline_options& o) { o.sleep_delay_s = kNaN; }, DRAPE_ERROR_NONFINITE},
      {[](drape_pipeline_options& o) { o.sleep_delay_s = -0.1f; }, DRAPE_ERROR_OUT_OF_RANGE},
      {[](drape_pipeline_options& o) { o.sleep_delay_s = 61.0f; }, DRAPE_ERROR_OUT_OF_RANGE},
      {[](drape_pipeline_options& o) { o.sleep_distance_m = kInf; }, DRAPE_ERROR_NONFINITE},
      {[](drape_pipeline_options& o) { o.sleep_distance_m = 1.5f; }, DRAPE_ERROR_OUT_OF_RANGE},
      {[](drape_pipeline_options& o) { o.sleep_speed_m_s = -kInf; }, DRAPE_ERROR_NONFINITE},
      {[](drape_pipeline_options& o) { o.sleep_speed_m_s = 11.0f; }, DRAPE_ERROR_OUT_OF_RANGE},
      {[](drape_pipeline_options& o) { o.reach_margin_m = kNaN; }, DRAPE_ERROR_NONFINITE},
      {[](drape_pipeline_options& o) { o.reach_margin_m = -0.01f; }, DRAPE_ERROR_OUT_OF_RANGE},
      {[](drape_pipeline_options& o) { o.reserved = 1; }, DRAPE_ERROR_INVALID_ARGUMENT},
  };
  for (const Case& c : cases) {
    drape_pipeline_options bad = good;
    bad.sleep_delay_s = 3.0f;  // a valid change that must not be applied either
    c.change(bad);
    EXPECT_FAILS_MSG(c.code, drape_context_set_pipeline_options(ctx.get(), &bad));
    drape_pipeline_options got;
    std::memset(&got, 0, sizeof(got));
    got.struct_size = sizeof(got);
    ASSERT_OK(drape_context_get_pipeline_options(ctx.get(), &got));
    EXPECT_EQ(std::memcmp(&got, &good, sizeof(good)), 0);
  }
  drape_pipeline_options out;
  std::memset(&out, 0, sizeof(out));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_get_pipeline_options",
               drape_context_get_pipeline_options(ctx.get(), nullptr));
  EXPECT_FAILS_MSG(DRAPE_ERROR_INVALID_ARGUMENT, drape_context_get_pipeline_options(ctx.get(), &out));  // size 0
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_wake", drape_context_wake(nullptr));
  EXPECT_FAILS(DRAPE_ERROR_INVALID_HANDLE, "drape_context_wake", drape_context_wake(dead));
  drape_skip_stats s;
  std::memset(&s, 0, sizeof(s));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_get_skip_stats", drape_context_get_skip_stats(ctx.get(), nullptr));
  EXPECT_FAILS_MSG(DRAPE_ERROR_INVALID_ARGUMENT, drape_context_get_skip_stats(ctx.get(), &s));
  s.struct_size = sizeof(s);
  EXPECT_FAILS(DRAPE_ERROR_INVALID_HANDLE, "drape_context_get_skip_stats", drape_context_get_skip_stats(dead, &s));
}

TEST(CApiPipeline, SkipStatsAndReadsBuildWhatWasSkipped) {
  ContextPtr ctx = makeContext();
  drape_skip_stats s = skipStats(ctx.get());
  EXPECT_GT(s.proxies_available, 0u);
  EXPECT_EQ(s.proxies_built, 0u);
  EXPECT_EQ(s.updates, 0u);
  drape_garment* g = addGarment(ctx.get(), DRAPE_GARMENT_SKIRT, 400);
  ASSERT_NE(g, nullptr);
  ASSERT_OK(stillStep(ctx.get(), 0));
  s = skipStats(ctx.get());
  EXPECT_EQ(s.updates, 1u);
  EXPECT_EQ(s.garments, 1u);
  EXPECT_GT(s.proxies_built, 0u);
  EXPECT_LT(s.proxies_built, s.proxies_available);
  EXPECT_EQ(s.stages_skipped_last, static_cast<uint32_t>(DRAPE_STAGE_BODY_MESH | DRAPE_STAGE_BODY_NORMALS | DRAPE_STAGE_PROXIES));
  EXPECT_EQ(s.stages_skipped, 3u);
  // Reading the mesh and the ellipsoids computes them for this frame.
  uint32_t nv = 0, ne = 0;
  ASSERT_OK(drape_context_get_body_mesh_size(ctx.get(), &nv, nullptr));
  std::vector<drape_vec3> pos(nv), nrm(nv);
  ASSERT_OK(drape_context_read_body_mesh(ctx.get(), pos.data(), nullptr, nv, nullptr, 0));
  EXPECT_EQ(skipStats(ctx.get()).stages_skipped_last, static_cast<uint32_t>(DRAPE_STAGE_BODY_NORMALS | DRAPE_STAGE_PROXIES));
  ASSERT_OK(drape_context_read_body_mesh(ctx.get(), nullptr, nrm.data(), nv, nullptr, 0));
  ASSERT_OK(drape_context_get_ellipsoid_count(ctx.get(), &ne));
  std::vector<drape_ellipsoid> e(ne);
  ASSERT_OK(drape_context_read_ellipsoids(ctx.get(), e.data(), ne, nullptr));
  s = skipStats(ctx.get());
  EXPECT_EQ(s.stages_skipped_last, 0u);
  EXPECT_EQ(s.proxies_built, s.proxies_available);
  EXPECT_EQ(s.stages_skipped, 0u);
  // The same reads on a full pipeline give the same bytes.
  ContextPtr full = makeContext();
  drape_pipeline_options o;
  ASSERT_OK(drape_pipeline_options_init(&o));
  o.cull_proxies = o.stages_on_demand = o.sleep = 0;
  ASSERT_OK(drape_context_set_pipeline_options(full.get(), &o));
  ASSERT_NE(addGarment(full.get(), DRAPE_GARMENT_SKIRT, 400), nullptr);
  ASSERT_OK(stillStep(full.get(), 0));
  EXPECT_EQ(skipStats(full.get()).stages_skipped_last, 0u);
  EXPECT_EQ(skipStats(full.get()).proxies_built, skipStats(full.get()).proxies_available);
  std::vector<drape_vec3> pos2(nv), nrm2(nv);
  std::vector<drape_ellipsoid> e2(ne);
  ASSERT_OK(drape_context_read_body_mesh(full.get(), pos2.data(), nrm2.data(), nv, nullptr, 0));
  ASSERT_OK(drape_context_read_ellipsoids(full.get(), e2.data(), ne, nullptr));
  EXPECT_EQ(std::memcmp(pos.data(), pos2.data(), nv * sizeof(drape_vec3)), 0);
  EXPECT_EQ(std::memcmp(nrm.data(), nrm2.data(), nv * sizeof(drape_vec3)), 0);
  EXPECT_EQ(std::memcmp(e.data(), e2.data(), ne * sizeof(drape_ellipsoid)), 0);
}

TEST(CApiPipeline, SleepsOnAStillPoseAndWakes) {
  ContextPtr ctx = makeContext();
  drape_garment* g = addGarment(ctx.get(), DRAPE_GARMENT_SKIRT, 400);
  ASSERT_NE(g, nullptr);
  int frame = 0;
  auto sleepNow = [&] {
    for (int i = 0; i < 300 && skipStats(ctx.get()).garments_asleep == 0; ++i) ASSERT_OK(stillStep(ctx.get(), frame++));
    ASSERT_EQ(skipStats(ctx.get()).garments_asleep, 1u);
  };
  sleepNow();
  const uint64_t steps = garmentSteps(g);
  const uint64_t slept = skipStats(ctx.get()).frames_slept;
  ASSERT_OK(stillStep(ctx.get(), frame++));
  EXPECT_EQ(garmentSteps(g), steps);
  drape_skip_stats s = skipStats(ctx.get());
  EXPECT_EQ(s.frames_slept, slept + 1);
  EXPECT_EQ(s.garment_steps_slept, s.frames_slept);
  EXPECT_TRUE(s.stages_skipped_last & DRAPE_STAGE_CLOTH);
  // New cloth parameters wake it: it steps at the next step.
  drape_cloth_params p;
  ASSERT_OK(drape_cloth_params_init(&p));
  p.damping = 2.0f;
  ASSERT_OK(drape_garment_set_params(g, &p));
  ASSERT_OK(stillStep(ctx.get(), frame++));
  EXPECT_EQ(garmentSteps(g), steps + 1);
  EXPECT_EQ(skipStats(ctx.get()).garments_asleep, 0u);
  // The host wakes it.
  sleepNow();
  uint64_t now = garmentSteps(g);
  ASSERT_OK(drape_context_wake(ctx.get()));
  ASSERT_OK(stillStep(ctx.get(), frame++));
  EXPECT_EQ(garmentSteps(g), now + 1);
  // The body moves: it steps that very frame.
  sleepNow();
  now = garmentSteps(g);
  ASSERT_OK(stillStep(ctx.get(), frame++, 0.3f));
  EXPECT_EQ(garmentSteps(g), now + 1);
  EXPECT_EQ(skipStats(ctx.get()).garments_asleep, 0u);
  // Sleeping off: it never sleeps.
  drape_pipeline_options o;
  ASSERT_OK(drape_pipeline_options_init(&o));
  o.sleep = 0;
  ASSERT_OK(drape_context_set_pipeline_options(ctx.get(), &o));
  now = garmentSteps(g);
  for (int i = 0; i < 40; ++i) ASSERT_OK(stillStep(ctx.get(), frame++, 0.3f));
  EXPECT_EQ(garmentSteps(g), now + 40);
  EXPECT_EQ(skipStats(ctx.get()).garments_asleep, 0u);
}

}  // namespace
