// Batched vs one-by-one OpenCL frames, side by side in one run (docs/opencl.md, "Batching"):
// 1 context with 1 and with 4 T-shirts, and 4 contexts (people) with one T-shirt each, stepped
// through the C ABI on the bundled Kinect take (samples/data/Ges01_wavehand.csv, every context
// the same person). batched = 1: the context's garments batch (drape_context_step), and the 4
// contexts step with drape_step_contexts; batched = 0: every garment's frame its own launch
// (batching off) and the contexts one drape_context_step each. Per iteration: one 1/30 s frame
// of every context. Counters: launches per frame (every kernel launch, the per-garment
// drape_transform of the inertia carry included), garments.
// particles: the T-shirts' size (5 000: over the one-work-group limit, the per-phase path, whose
// phases batch too). normals = 1: every garment's vertex normals read each frame
// (drape_garment_read_mesh: on OpenCL computed on the device with the frame, on the CPU by
// vertexNormals). opencl = 0: the same on the CPU backend (the normals' CPU cost).
// Run: ./build/batch/tests/drape_benchmarks --benchmark_filter=Batch --benchmark_repetitions=3
//      --benchmark_report_aggregates_only=true
#include "drape/drape.h"
#if DRAPE_HAVE_OPENCL
#include "backends/opencl/cl_garment_solver.h"
#include "backends/opencl/cl_runtime.h"
#endif

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

namespace {

#if DRAPE_HAVE_OPENCL
std::string takePath() {
  std::string dir = __FILE__;
  dir = dir.substr(0, dir.find_last_of("/\\") + 1);
  return dir + "../../samples/data/Ges01_wavehand.csv";
}

struct Take {
  int32_t layout = 0;
  std::vector<std::vector<drape_joint>> joints;
};

bool loadTake(Take& take) {
  drape_recording* r = nullptr;
  if (drape_recording_open(takePath().c_str(), DRAPE_LAYOUT_AUTO, &r) != DRAPE_OK) return false;
  drape_recording_info info;
  info.struct_size = sizeof(info);
  bool ok = drape_recording_get_info(r, &info) == DRAPE_OK;
  take.layout = info.layout;
  for (uint32_t f = 0; ok && f < info.frame_count; ++f) {
    std::vector<drape_joint> j(info.joint_count);
    ok = drape_recording_read_frame(r, f, j.data(), info.joint_count, nullptr) == DRAPE_OK;
    take.joints.push_back(std::move(j));
  }
  drape_recording_destroy(r);
  return ok && !take.joints.empty();
}

// args: contexts, garments per context, batched, particles, normals, opencl.
void BM_BatchFrames(benchmark::State& state) {
  const int contexts = static_cast<int>(state.range(0)), garments = static_cast<int>(state.range(1));
  const bool batched = state.range(2) != 0;
  const uint32_t particles = static_cast<uint32_t>(state.range(3));
  const bool normals = state.range(4) != 0, opencl = state.range(5) != 0;
  std::vector<drape_garment*> all;
  std::vector<drape_vec3> scratch;
  Take take;
  if (!loadTake(take)) {
    state.SkipWithError("the bundled Kinect take did not load");
    return;
  }
  std::vector<drape_context*> ctx(static_cast<size_t>(contexts), nullptr);
  bool ok = true;
  for (drape_context*& c : ctx) {
    ok = ok && drape_context_create(nullptr, &c) == DRAPE_OK;
    for (int g = 0; ok && g < garments; ++g) {
      drape_garment_template t;
      drape_garment_template_init(&t);
      t.particles = particles;
      drape_garment* out = nullptr;
      ok = drape_context_add_garment_template(c, nullptr, &t, nullptr, &out) == DRAPE_OK;
      all.push_back(out);
    }
    drape_backend_desc b;
    drape_backend_desc_init(&b);
    b.backend = opencl ? DRAPE_BACKEND_OPENCL : DRAPE_BACKEND_CPU;
    drape_backend_info info;
    info.struct_size = sizeof(info);
    ok = ok && drape_context_set_backend(c, &b) == DRAPE_OK && drape_context_get_backend_info(c, &info) == DRAPE_OK &&
         info.active == b.backend;
  }
  drape::setClFrameBatching(batched);
  size_t frame = 0;
  double t = 0.0;
  auto step = [&]() {
    const std::vector<drape_joint>& j = take.joints[frame++ % take.joints.size()];
    drape_skeleton_frame f;
    std::memset(&f, 0, sizeof(f));
    f.struct_size = sizeof(f);
    f.layout = take.layout;
    f.joints = j.data();
    f.joint_count = static_cast<uint32_t>(j.size());
    f.timestamp_s = t;
    t += 1.0 / 30.0;
    for (drape_context* c : ctx) ok = ok && drape_context_push_skeleton(c, &f) == DRAPE_OK;
    if (batched) {
      ok = ok && drape_step_contexts(ctx.data(), static_cast<uint32_t>(ctx.size()), 1.0f / 30.0f) == DRAPE_OK;
    } else {
      for (drape_context* c : ctx) ok = ok && drape_context_step(c, 1.0f / 30.0f) == DRAPE_OK;
    }
    for (drape_garment* g : all) {
      if (!normals || !ok) break;
      uint32_t n = 0;
      ok = drape_garment_get_mesh_size(g, &n, nullptr) == DRAPE_OK;
      scratch.resize(n);
      ok = ok && drape_garment_read_mesh(g, nullptr, scratch.data(), n, nullptr, 0) == DRAPE_OK;
    }
  };
  for (int w = 0; w < 10 && ok; ++w) step();  // dressing, placing, the first frames
  const uint64_t launches0 = drape::ClRuntime::processLaunchCount();
  for (auto _ : state) {
    step();
    if (!ok) break;
  }
  const uint64_t launches = drape::ClRuntime::processLaunchCount() - launches0;
  drape::setClFrameBatching(true);
  for (drape_context* c : ctx) drape_context_destroy(c);
  if (!ok) {
    state.SkipWithError("no usable OpenCL device, or a step failed");
    return;
  }
  state.counters["launches_per_frame"] =
      static_cast<double>(launches) / static_cast<double>(std::max<int64_t>(1, state.iterations()));
  state.counters["garments"] = contexts * garments;
}

BENCHMARK(BM_BatchFrames)
    ->Args({1, 1, 1, 1000, 0, 1})
    ->Args({1, 4, 0, 1000, 0, 1})
    ->Args({1, 4, 1, 1000, 0, 1})
    ->Args({4, 1, 0, 1000, 0, 1})
    ->Args({4, 1, 1, 1000, 0, 1})
    // Large garments (per-phase path): one by one vs batched, one context and two.
    ->Args({1, 1, 1, 5000, 0, 1})
    ->Args({1, 2, 0, 5000, 0, 1})
    ->Args({1, 2, 1, 5000, 0, 1})
    ->Args({2, 1, 0, 5000, 0, 1})
    ->Args({2, 1, 1, 5000, 0, 1})
    // Normals read every frame: on the device (opencl 1) or by the CPU (opencl 0), vs not read.
    ->Args({1, 1, 1, 1000, 1, 1})
    ->Args({1, 1, 1, 1000, 0, 0})
    ->Args({1, 1, 1, 1000, 1, 0})
    ->Args({1, 4, 1, 1000, 1, 1})
    ->Args({1, 1, 1, 5000, 1, 1})
    ->Args({1, 1, 1, 5000, 0, 0})
    ->Args({1, 1, 1, 5000, 1, 0})
    ->ArgNames({"contexts", "garments", "batched", "particles", "normals", "opencl"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(60);
#endif

}  // namespace
