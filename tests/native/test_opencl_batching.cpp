// Batched OpenCL frames (docs/opencl.md, "Batching"): the garments of one context, and of several
// contexts stepped with drape_step_contexts, run their device frames in one launch; the results
// are the same bits as each garment's own launch (batching off: the one-by-one reference), on a
// real Kinect take. Plus the launch count per frame, AUTO's mix of CPU and device garments, and
// drape_step_contexts' argument checks (those run without a device).
#include "capi_test_support.h"
#include "sanitizer_scale.h"
#include "test_data.h"

#if DRAPE_HAVE_OPENCL
#include "backends/opencl/cl_garment_solver.h"
#include "backends/opencl/cl_runtime.h"
#endif

#include <cmath>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

namespace {

struct Take {
  drape_layout layout = DRAPE_LAYOUT_KINECT2;
  std::vector<std::vector<drape_joint>> joints;
  std::vector<double> t;
};

bool loadTake(const std::string& path, uint32_t frames, Take& take) {
  drape_recording* r = nullptr;
  if (drape_recording_open(path.c_str(), DRAPE_LAYOUT_AUTO, &r) != DRAPE_OK) return false;
  RecordingPtr rec(r);
  drape_recording_info info;
  info.struct_size = sizeof(info);
  if (drape_recording_get_info(r, &info) != DRAPE_OK || info.frame_count < frames) return false;
  take.layout = static_cast<drape_layout>(info.layout);
  for (uint32_t f = 0; f < frames; ++f) {
    std::vector<drape_joint> j(info.joint_count);
    double t = 0.0;
    if (drape_recording_read_frame(r, f, j.data(), info.joint_count, &t) != DRAPE_OK) return false;
    take.joints.push_back(std::move(j));
    take.t.push_back(t);
  }
  return true;
}

// A context (person) with T-shirts of the given particle counts on the given backend.
// inertia < 0: the default cloth parameters; else both inertias (1: no rigid carry, whose
// drape_transform launch is per garment: see LaunchesPerFrameDoNotGrowWithGarments).
struct World {
  ContextPtr ctx;
  std::vector<drape_garment*> garments;
};

World makeWorld(const std::vector<uint32_t>& particles, drape_backend backend, uint32_t min_particles = 0,
                float inertia = -1.0f) {
  World w;
  drape_context_desc d;
  EXPECT_EQ(drape_context_desc_init(&d), DRAPE_OK);
  w.ctx = makeContext(&d);
  for (uint32_t n : particles) {
    drape_garment_template t;
    EXPECT_EQ(drape_garment_template_init(&t), DRAPE_OK);
    t.particles = n;
    drape_garment* g = nullptr;
    EXPECT_EQ(drape_context_add_garment_template(w.ctx.get(), nullptr, &t, nullptr, &g), DRAPE_OK) << lastError();
    if (inertia >= 0.0f && g) {
      drape_cloth_params p;
      EXPECT_EQ(drape_cloth_params_init(&p), DRAPE_OK);
      p.linear_inertia = inertia;
      p.angular_inertia = inertia;
      EXPECT_EQ(drape_garment_set_params(g, &p), DRAPE_OK) << lastError();
    }
    w.garments.push_back(g);
  }
  drape_backend_desc b;
  EXPECT_EQ(drape_backend_desc_init(&b), DRAPE_OK);
  b.backend = backend;
  b.opencl_min_particles = min_particles;
  EXPECT_EQ(drape_context_set_backend(w.ctx.get(), &b), DRAPE_OK) << lastError();
  return w;
}

drape_result push(World& w, const Take& take, size_t f) {
  const drape_skeleton_frame fr = makeFrame(take.layout, take.joints[f], take.t[f]);
  return drape_context_push_skeleton(w.ctx.get(), &fr);
}

// Every garment's positions (xyzw floats), garment after garment.
std::vector<float> snapshot(const World& w) {
  std::vector<float> out;
  for (drape_garment* g : w.garments) {
    const float* x = nullptr;
    uint32_t n = 0;
    EXPECT_EQ(drape_garment_view_positions(g, &x, &n), DRAPE_OK) << lastError();
    out.insert(out.end(), x, x + 4 * n);
  }
  return out;
}

bool sameBits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

constexpr float kDt = 1.0f / 30.0f;

// Garment sizes: under the sanitizers half of each (still all different, and on either side of
// AUTO's threshold where a test uses one). Making a template is most of these tests' ASan time
// (62 % of LaunchesPerFrameDoNotGrowWithGarments), while what they check - the same bits batched
// and one by one, the launches per frame - is the same for every garment of the one-work-group
// path (up to 4 096 particles; the large-garment tests below keep their size).
constexpr uint32_t sized(uint32_t particles) {
  return drape::test::kSanitizedBuild ? particles / 2 : particles;
}

#if DRAPE_HAVE_OPENCL
// Batching on for the scope (restored after: other tests run with the default, on).
struct Batching {
  explicit Batching(bool on) { drape::setClFrameBatching(on); }
  ~Batching() { drape::setClFrameBatching(true); }
};

#define DRAPE_REQUIRE_DEVICE_WORLD(w)                                                       \
  if (backendInfo((w).ctx.get()).active != DRAPE_BACKEND_OPENCL)                            \
  GTEST_SKIP() << "no usable OpenCL device: " << backendInfo((w).ctx.get()).fallback_reason

// Steps `worlds` through the take's frames, together (drape_step_contexts) or one by one
// (drape_context_step each); returns every frame's snapshot of every world.
std::vector<std::vector<float>> runTake(std::vector<World*> worlds, const Take& take, bool together) {
  std::vector<std::vector<float>> out;
  std::vector<drape_context*> handles;
  for (World* w : worlds) handles.push_back(w->ctx.get());
  for (size_t f = 0; f < take.joints.size(); ++f) {
    for (World* w : worlds) EXPECT_EQ(push(*w, take, f), DRAPE_OK) << lastError();
    if (together) {
      EXPECT_EQ(drape_step_contexts(handles.data(), static_cast<uint32_t>(handles.size()), kDt), DRAPE_OK)
          << lastError();
    } else {
      for (World* w : worlds) EXPECT_EQ(drape_context_step(w->ctx.get(), kDt), DRAPE_OK) << lastError();
    }
    std::vector<float> all;
    for (World* w : worlds) {
      const std::vector<float> s = snapshot(*w);
      all.insert(all.end(), s.begin(), s.end());
    }
    out.push_back(std::move(all));
  }
  return out;
}

void expectSameRuns(const std::vector<std::vector<float>>& a, const std::vector<std::vector<float>>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t f = 0; f < a.size(); ++f) {
    ASSERT_FALSE(a[f].empty());
    EXPECT_TRUE(sameBits(a[f], b[f])) << "frame " << f << " differs";
    for (float v : a[f]) ASSERT_TRUE(std::isfinite(v)) << "frame " << f;
  }
  // The cloth moved: the comparison is of a real run, not of a garment standing still. (Over the
  // take's still first frames, garments carried into the first pose (cloth/placement_path.h)
  // move at most 4.6 and 8.1 mm in two of these tests under the sanitizers' half sizes.)
  float moved = 0.0f;
  for (size_t k = 0; k < a.front().size(); ++k) moved = std::max(moved, std::fabs(a.back()[k] - a.front()[k]));
  EXPECT_GT(moved, 0.001f);
}

#define DRAPE_LOAD_TAKE(take, frames)                                                      \
  DRAPE_REQUIRE_SHARED(take##_path, "kinect_v2_msft_labanotation/Ges01_wavehand.csv");      \
  Take take;                                                                               \
  ASSERT_TRUE(loadTake(take##_path, (frames), take)) << lastError()

TEST(OpenClBatching, GarmentsOfOneContextMatchOneByOneBitForBit) {
  DRAPE_LOAD_TAKE(take, 12);
  const std::vector<uint32_t> sizes = {sized(400), sized(800), sized(1200)};
  World one = makeWorld(sizes, DRAPE_BACKEND_OPENCL);
  DRAPE_REQUIRE_DEVICE_WORLD(one);
  EXPECT_EQ(backendInfo(one.ctx.get()).opencl_garments, 3u);
  std::vector<std::vector<float>> by_one;
  {
    Batching off(false);
    by_one = runTake({&one}, take, false);
  }
  World batched = makeWorld(sizes, DRAPE_BACKEND_OPENCL);
  const auto together = runTake({&batched}, take, false);
  expectSameRuns(together, by_one);
  EXPECT_STREQ(backendInfo(batched.ctx.get()).fallback_reason, "");
}

// drape_garment_stats' device_* split (the queue's profiling events): a garment stepped on its
// own reports its uploads, kernels and readback, and their sum fits inside its step's wall time;
// garments batched together report zeros (a batch is timed as a whole), as the CPU backend does.
TEST(OpenClBatching, DeviceTimesOfAGarmentAloneAndZeroInABatch) {
  DRAPE_LOAD_TAKE(take, 4);
  World alone = makeWorld({sized(600)}, DRAPE_BACKEND_OPENCL);
  DRAPE_REQUIRE_DEVICE_WORLD(alone);
  World two = makeWorld({sized(600), sized(700)}, DRAPE_BACKEND_OPENCL);
  ASSERT_EQ(backendInfo(two.ctx.get()).opencl_garments, 2u);
  runTake({&alone, &two}, take, false);
  drape_garment_stats s;
  s.struct_size = sizeof(s);
  ASSERT_EQ(drape_garment_get_stats(alone.garments[0], &s), DRAPE_OK) << lastError();
  EXPECT_GT(s.device_kernel_ms, 0.0);
  EXPECT_GT(s.device_readback_ms, 0.0);
  EXPECT_GT(s.device_upload_ms, 0.0);
  EXPECT_GE(s.device_host_ms, 0.0);
  const double sum = s.device_upload_ms + s.device_kernel_ms + s.device_readback_ms + s.device_host_ms;
  EXPECT_LE(sum, s.step_ms * 1.01 + 0.01) << "device split " << sum << " ms in a " << s.step_ms << " ms step";
  EXPECT_EQ(s.collide_ms, 0.0);  // collision runs inside the device frame
  for (drape_garment* g : two.garments) {
    ASSERT_EQ(drape_garment_get_stats(g, &s), DRAPE_OK) << lastError();
    EXPECT_GT(s.step_ms, 0.0);
    EXPECT_EQ(s.device_kernel_ms, 0.0);
    EXPECT_EQ(s.device_upload_ms + s.device_readback_ms + s.device_host_ms, 0.0);
  }
}

TEST(OpenClBatching, ContextsSteppedTogetherMatchSeparateStepsBitForBit) {
  DRAPE_LOAD_TAKE(take, 12);
  World a = makeWorld({sized(600)}, DRAPE_BACKEND_OPENCL), b = makeWorld({sized(500), sized(900)}, DRAPE_BACKEND_OPENCL);
  DRAPE_REQUIRE_DEVICE_WORLD(a);
  const auto separate = runTake({&a, &b}, take, false);
  World c = makeWorld({sized(600)}, DRAPE_BACKEND_OPENCL), d = makeWorld({sized(500), sized(900)}, DRAPE_BACKEND_OPENCL);
  const auto together = runTake({&c, &d}, take, true);
  expectSameRuns(together, separate);
}

// Launches per frame: the same for 1 and 4 garments batched, against one (or two) per garment one
// by one. With the default inertia scaling every garment is carried rigidly each frame
// (drape_transform): batched, all of them in one more launch.
TEST(OpenClBatching, LaunchesPerFrameDoNotGrowWithGarments) {
  DRAPE_LOAD_TAKE(take, 8);
  auto launchesPerFrame = [&](World& w, bool batching) {
    Batching scope(batching);
    uint64_t per_frame = 0;
    for (size_t f = 0; f < take.joints.size(); ++f) {
      EXPECT_EQ(push(w, take, f), DRAPE_OK) << lastError();
      const uint64_t before = drape::ClRuntime::processLaunchCount();
      EXPECT_EQ(drape_context_step(w.ctx.get(), kDt), DRAPE_OK) << lastError();
      // The first frames place the garments (settling frames, not batched): count a later one.
      if (f + 1 == take.joints.size()) per_frame = drape::ClRuntime::processLaunchCount() - before;
    }
    return per_frame;
  };
  const std::vector<uint32_t> four = {sized(500), sized(600), sized(700), sized(800)};
  for (const float inertia : {1.0f, -1.0f}) {
    SCOPED_TRACE(inertia < 0.0f ? "default inertia (rigid carry each frame)" : "inertia 1 (no carry)");
    const uint64_t per_garment = inertia < 0.0f ? 2 : 1;  // the frame (+ the carry)
    World one = makeWorld({sized(500)}, DRAPE_BACKEND_OPENCL, 0, inertia);
    DRAPE_REQUIRE_DEVICE_WORLD(one);
    World batched = makeWorld(four, DRAPE_BACKEND_OPENCL, 0, inertia);
    World by_one = makeWorld(four, DRAPE_BACKEND_OPENCL, 0, inertia);
    EXPECT_EQ(launchesPerFrame(one, true), per_garment);
    EXPECT_EQ(launchesPerFrame(batched, true), per_garment);
    EXPECT_EQ(launchesPerFrame(by_one, false), 4 * per_garment);
  }
}

TEST(OpenClBatching, TwoContextsCostOneLaunchPerFrame) {
  DRAPE_LOAD_TAKE(take, 8);
  World a = makeWorld({sized(500), sized(700)}, DRAPE_BACKEND_OPENCL, 0, 1.0f);
  DRAPE_REQUIRE_DEVICE_WORLD(a);
  World b = makeWorld({sized(600)}, DRAPE_BACKEND_OPENCL, 0, 1.0f);
  drape_context* both[2] = {a.ctx.get(), b.ctx.get()};
  uint64_t last = 0;
  for (size_t f = 0; f < take.joints.size(); ++f) {
    ASSERT_OK(push(a, take, f));
    ASSERT_OK(push(b, take, f));
    const uint64_t before = drape::ClRuntime::processLaunchCount();
    ASSERT_OK(drape_step_contexts(both, 2, kDt));
    last = drape::ClRuntime::processLaunchCount() - before;
  }
  EXPECT_EQ(last, 1u);  // no carry (inertia 1): the batched frame alone
}

// AUTO: the small garment stays on the CPU, the two larger go to the device and batch; the whole
// world matches the one-by-one run bit for bit (the CPU garment included).
TEST(OpenClBatching, MixedCpuAndDeviceGarmentsUnderAuto) {
  DRAPE_LOAD_TAKE(take, 10);
  const std::vector<uint32_t> sizes = {sized(400), sized(1200), sized(1500)};
  World batched = makeWorld(sizes, DRAPE_BACKEND_AUTO, sized(1000));
  DRAPE_REQUIRE_DEVICE_WORLD(batched);
  const drape_backend_info i = backendInfo(batched.ctx.get());
  EXPECT_EQ(i.opencl_garments, 2u);
  EXPECT_EQ(i.cpu_garments, 1u);
  const auto together = runTake({&batched}, take, false);
  World one = makeWorld(sizes, DRAPE_BACKEND_AUTO, sized(1000));
  std::vector<std::vector<float>> by_one;
  {
    Batching off(false);
    by_one = runTake({&one}, take, false);
  }
  expectSameRuns(together, by_one);
  // And the CPU garment is the CPU's own answer: the same garment alone in a CPU world.
  World cpu = makeWorld({sized(400)}, DRAPE_BACKEND_CPU);
  const auto cpu_run = runTake({&cpu}, take, false);
  const size_t n0 = cpu_run.back().size();
  EXPECT_TRUE(std::memcmp(cpu_run.back().data(), together.back().data(), n0 * sizeof(float)) == 0);
}

// Large garments (over 4 096 particles: the per-phase path) batch too, each phase launched once
// for all of them. 5 000-particle T-shirts: the template makes them larger than the one
// work-group limit, which the test checks, so they really take the per-phase path.
constexpr uint32_t kLarge = 5000;

void expectLarge(const World& w, size_t garment) {
  const float* x = nullptr;
  uint32_t n = 0;
  ASSERT_EQ(drape_garment_view_positions(w.garments[garment], &x, &n), DRAPE_OK) << lastError();
  EXPECT_GT(n, 4096u) << "not on the per-phase path";
}

// Steps `one` (from `make`, on the device: large garments first and last, a small one between)
// through the take with batching off (each garment its own launches), then a second world from
// `make` with it on; expects the same bits and returns the batched run.
std::vector<std::vector<float>> expectLargeBatchedAsOneByOne(World& one, const std::function<World()>& make,
                                                             const Take& take) {
  expectLarge(one, 0);
  expectLarge(one, 2);
  std::vector<std::vector<float>> by_one;
  {
    Batching off(false);
    by_one = runTake({&one}, take, false);
  }
  World batched = make();
  std::vector<std::vector<float>> together = runTake({&batched}, take, false);
  expectSameRuns(together, by_one);
  return together;
}

// Two large garments and a small one in one context: bit for bit as one by one (one frame launch
// for the small one, each phase once for both large ones). Two contexts (large; small) through
// drape_step_contexts: as stepping each (each alone there).
TEST(OpenClBatching, LargeGarmentsMatchOneByOneBitForBit) {
  DRAPE_LOAD_TAKE(take, 4);
  const std::vector<uint32_t> sizes = {kLarge, 600, kLarge};
  const auto make = [&] { return makeWorld(sizes, DRAPE_BACKEND_OPENCL); };
  World one = make();
  DRAPE_REQUIRE_DEVICE_WORLD(one);
  expectLargeBatchedAsOneByOne(one, make, take);
  World a = makeWorld({kLarge}, DRAPE_BACKEND_OPENCL), b = makeWorld({600}, DRAPE_BACKEND_OPENCL);
  const auto separate = runTake({&a, &b}, take, false);
  World c = makeWorld({kLarge}, DRAPE_BACKEND_OPENCL), d = makeWorld({600}, DRAPE_BACKEND_OPENCL);
  expectSameRuns(runTake({&c, &d}, take, true), separate);
}

// Garments of one context with strain-limit passes of their own (drape_cloth_params.
// strain_limit_passes 8, 2 and 5 at a 5 % limit): batched, the per-phase launches run the most
// passes any garment asks for and the kernels stop each garment at its own (cl_phase_launch.cpp),
// the small garment's frame launch its own: bit for bit as one by one. And the passes act on the
// device: the same garments all at 2 passes end elsewhere.
TEST(OpenClBatching, LargeGarmentsWithTheirOwnStrainLimitPassesMatchOneByOne) {
  DRAPE_LOAD_TAKE(take, 4);
  const std::vector<uint32_t> sizes = {kLarge, 600, kLarge};
  auto withPasses = [&](std::vector<uint32_t> passes) {
    World w = makeWorld(sizes, DRAPE_BACKEND_OPENCL);
    for (size_t k = 0; k < w.garments.size(); ++k) {
      drape_cloth_params p;
      EXPECT_EQ(drape_cloth_params_init(&p), DRAPE_OK);
      p.strain_limit = 0.05f;
      p.strain_limit_passes = passes[k];
      EXPECT_EQ(drape_garment_set_params(w.garments[k], &p), DRAPE_OK) << lastError();
    }
    return w;
  };
  const auto make = [&] { return withPasses({8, 2, 5}); };
  World one = make();
  DRAPE_REQUIRE_DEVICE_WORLD(one);
  const auto together = expectLargeBatchedAsOneByOne(one, make, take);
  World two = withPasses({2, 2, 2});
  const auto all_two = runTake({&two}, take, false);
  EXPECT_FALSE(sameBits(all_two.back(), together.back()));
}

// Launches per frame on the per-phase path (~25 per substep) do not grow with the number of large
// garments: 1 or 2 large garments batched cost the launches of one alone; a small one adds its
// batch's frame launch; one by one, each large garment pays its own.
TEST(OpenClBatching, LargeGarmentLaunchesDoNotGrowWithTheirNumber) {
  DRAPE_LOAD_TAKE(take, 6);
  // Frames [first, first + 3): the launches of the last (the first frame places the garments).
  auto launchesPerFrame = [&](World& w, bool batching, size_t first = 0) {
    Batching scope(batching);
    uint64_t per_frame = 0;
    for (size_t f = first; f < first + 3; ++f) {
      EXPECT_EQ(push(w, take, f), DRAPE_OK) << lastError();
      const uint64_t before = drape::ClRuntime::processLaunchCount();
      EXPECT_EQ(drape_context_step(w.ctx.get(), kDt), DRAPE_OK) << lastError();
      per_frame = drape::ClRuntime::processLaunchCount() - before;
    }
    return per_frame;
  };
  World one = makeWorld({kLarge}, DRAPE_BACKEND_OPENCL, 0, 1.0f);
  DRAPE_REQUIRE_DEVICE_WORLD(one);
  expectLarge(one, 0);
  const uint64_t alone = launchesPerFrame(one, true);
  EXPECT_GT(alone, 10u * 15u);  // 10 substeps of ~20 phase launches (small colour groups fused): the per-phase path
  World two = makeWorld({kLarge, kLarge}, DRAPE_BACKEND_OPENCL, 0, 1.0f);
  EXPECT_EQ(launchesPerFrame(two, true), alone);
  EXPECT_EQ(launchesPerFrame(two, false, 3), 2 * alone);  // the same garments, one by one
  World mixed = makeWorld({600, kLarge}, DRAPE_BACKEND_OPENCL, 0, 1.0f);
  EXPECT_EQ(launchesPerFrame(mixed, true), alone + 1);
}
#endif  // DRAPE_HAVE_OPENCL

// drape_step_contexts' checks (no device needed): each rejected call changes nothing.
TEST(CApiStepContexts, ArgumentChecksChangeNothing) {
  World a = makeWorld({300}, DRAPE_BACKEND_CPU), b = makeWorld({300}, DRAPE_BACKEND_CPU);
  ContextPtr fresh = makeContext();  // no skeleton frame yet
  const std::vector<drape_joint> j = poseJoints(DRAPE_LAYOUT_KINECT2, 0.0);
  const drape_skeleton_frame fr = makeFrame(DRAPE_LAYOUT_KINECT2, j, 0.0);
  ASSERT_OK(drape_context_push_skeleton(a.ctx.get(), &fr));
  ASSERT_OK(drape_context_push_skeleton(b.ctx.get(), &fr));
  ASSERT_OK(drape_context_step(a.ctx.get(), kDt));
  ASSERT_OK(drape_context_step(b.ctx.get(), kDt));
  const std::vector<float> a0 = snapshot(a), b0 = snapshot(b);
  drape_context* ab[2] = {a.ctx.get(), b.ctx.get()};
  drape_context* dup[2] = {a.ctx.get(), a.ctx.get()};
  drape_context* with_null[2] = {a.ctx.get(), nullptr};
  drape_context* with_fresh[2] = {a.ctx.get(), fresh.get()};
  std::vector<drape_context*> many(DRAPE_MAX_STEP_CONTEXTS + 1, a.ctx.get());
  const char* fn = "drape_step_contexts";
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, fn, drape_step_contexts(nullptr, 2, kDt));
  EXPECT_FAILS(DRAPE_ERROR_OUT_OF_RANGE, fn, drape_step_contexts(ab, 0, kDt));
  EXPECT_FAILS(DRAPE_ERROR_OUT_OF_RANGE, fn,
               drape_step_contexts(many.data(), static_cast<uint32_t>(many.size()), kDt));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, fn, drape_step_contexts(with_null, 2, kDt));
  EXPECT_FAILS(DRAPE_ERROR_INVALID_ARGUMENT, fn, drape_step_contexts(dup, 2, kDt));
  EXPECT_FAILS(DRAPE_ERROR_NONFINITE, fn, drape_step_contexts(ab, 2, std::nanf("")));
  EXPECT_FAILS(DRAPE_ERROR_NONFINITE, fn, drape_step_contexts(ab, 2, INFINITY));
  EXPECT_FAILS(DRAPE_ERROR_OUT_OF_RANGE, fn, drape_step_contexts(ab, 2, 0.0f));
  EXPECT_FAILS(DRAPE_ERROR_OUT_OF_RANGE, fn, drape_step_contexts(ab, 2, 10.5f));
  // The second context cannot step (no frame yet): the first does not step either.
  EXPECT_FAILS(DRAPE_ERROR_CALL_ORDER, fn, drape_step_contexts(with_fresh, 2, kDt));
  // A destroyed context is a stale handle.
  drape_context* gone = nullptr;
  ASSERT_OK(drape_context_create(nullptr, &gone));
  ASSERT_OK(drape_context_destroy(gone));
  drape_context* with_stale[2] = {a.ctx.get(), gone};
  EXPECT_FAILS(DRAPE_ERROR_INVALID_HANDLE, fn, drape_step_contexts(with_stale, 2, kDt));
  EXPECT_TRUE(sameBits(snapshot(a), a0));
  EXPECT_TRUE(sameBits(snapshot(b), b0));
  drape_garment_stats st;
  st.struct_size = sizeof(st);
  ASSERT_OK(drape_garment_get_stats(a.garments[0], &st));
  const auto steps_before = st.steps;
  // Accepted: the same as stepping each (CPU contexts here), and both advance.
  World c = makeWorld({300}, DRAPE_BACKEND_CPU), d = makeWorld({300}, DRAPE_BACKEND_CPU);
  ASSERT_OK(drape_context_push_skeleton(c.ctx.get(), &fr));
  ASSERT_OK(drape_context_push_skeleton(d.ctx.get(), &fr));
  ASSERT_OK(drape_context_step(c.ctx.get(), kDt));
  ASSERT_OK(drape_context_step(d.ctx.get(), kDt));
  const std::vector<drape_joint> j1 = poseJoints(DRAPE_LAYOUT_KINECT2, 1.0 / 30.0);
  const drape_skeleton_frame fr1 = makeFrame(DRAPE_LAYOUT_KINECT2, j1, 1.0 / 30.0);
  for (World* w : {&a, &b, &c, &d}) ASSERT_OK(drape_context_push_skeleton(w->ctx.get(), &fr1));
  ASSERT_OK(drape_step_contexts(ab, 2, kDt));
  ASSERT_OK(drape_context_step(c.ctx.get(), kDt));
  ASSERT_OK(drape_context_step(d.ctx.get(), kDt));
  EXPECT_TRUE(sameBits(snapshot(a), snapshot(c)));
  EXPECT_TRUE(sameBits(snapshot(b), snapshot(d)));
  EXPECT_FALSE(sameBits(snapshot(a), a0));
  ASSERT_OK(drape_garment_get_stats(a.garments[0], &st));
  EXPECT_EQ(st.steps, steps_before + 1);
}

}  // namespace
