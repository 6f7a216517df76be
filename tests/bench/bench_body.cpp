// Per-frame cost of the body stage: skeleton filter -> feature rings -> body mesh, on a real
// Kinect v2 recording, at K = 20 (the paper's setting) and K = 64. The paper's body stage took
// 0.78 ms per frame. Run: ./build/release/tests/drape_benchmarks --benchmark_filter=Body
#include "body/body_model.h"
#include "drape/drape.h"
#include "recording/recording.h"
#include "skeleton/layouts.h"
#include "skeleton/tracker.h"

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <string>
#include <vector>

namespace drape {
namespace {

std::string recordingPath() {
  const char* env = std::getenv("DRAPE_SHARED_DATA");
  return std::string(env ? env : DRAPE_SHARED_DATA_DIR) + "/kinect_v2_msft_labanotation/Ges01_wavehand.csv";
}

struct Frames {
  std::vector<SkeletonPose> poses;
  std::vector<double> times;
  Recording rec;
  bool ok = false;
};

const Frames& frames() {
  static Frames f = [] {
    Frames out;
    std::string err;
    if (!readRecordingFile(recordingPath(), 0, out.rec, err)) return out;
    for (const auto& fr : out.rec.frames) {
      SkeletonPose p;
      if (!mapToCanonical(out.rec.layout, fr.joints.data(), static_cast<int>(fr.joints.size()), p, err)) return out;
      out.poses.push_back(p);
      out.times.push_back(fr.time_s);
    }
    out.ok = !out.poses.empty();
    return out;
  }();
  return f;
}

// Filtered poses (tracker already run) so the body benchmark measures rings + mesh only.
std::vector<SkeletonPose> filteredPoses() {
  SkeletonTracker tracker;
  std::vector<SkeletonPose> out;
  for (size_t i = 0; i < frames().poses.size(); ++i) {
    tracker.push(frames().poses[i], frames().times[i]);
    out.push_back(tracker.pose());
  }
  return out;
}

void BM_SkeletonStage(benchmark::State& state) {
  if (!frames().ok) return state.SkipWithError("shared recording not found");
  SkeletonTracker tracker;
  size_t i = 0;
  double t = 0.0;
  for (auto _ : state) {
    tracker.push(frames().poses[i], t);
    benchmark::DoNotOptimize(tracker.pose());
    t += 1.0 / 30.0;
    i = (i + 1) % frames().poses.size();
  }
}
BENCHMARK(BM_SkeletonStage);

void BM_BodyStage(benchmark::State& state) {
  if (!frames().ok) return state.SkipWithError("shared recording not found");
  BodyModelParams params;
  params.ring_points = static_cast<int>(state.range(0));
  BodyModel body(resolveShape(BodyShapeInput{}), params);
  const std::vector<SkeletonPose> poses = filteredPoses();
  size_t i = 0;
  for (auto _ : state) {
    body.update(poses[i]);
    benchmark::DoNotOptimize(body.positions().data());
    i = (i + 1) % poses.size();
  }
  state.counters["vertices"] = static_cast<double>(body.positions().size());
  state.counters["triangles"] = static_cast<double>(body.indices().size() / 3);
}
BENCHMARK(BM_BodyStage)->Arg(20)->Arg(64)->Unit(benchmark::kMicrosecond);

// The whole frame through the public C ABI: push + update + read the body mesh.
void BM_FrameThroughCApi(benchmark::State& state) {
  if (!frames().ok) return state.SkipWithError("shared recording not found");
  drape_context_desc desc;
  drape_context_desc_init(&desc);
  desc.ring_points = static_cast<uint32_t>(state.range(0));
  drape_context* ctx = nullptr;
  if (drape_context_create(&desc, &ctx) != DRAPE_OK) return state.SkipWithError(drape_last_error());
  uint32_t nv = 0, ni = 0;
  drape_context_get_body_mesh_size(ctx, &nv, &ni);
  std::vector<drape_vec3> pos(nv), nrm(nv);
  const Recording& rec = frames().rec;
  std::vector<drape_joint> joints(rec.frames[0].joints.size());
  size_t i = 0;
  double t = 0.0;
  for (auto _ : state) {
    const auto& fr = rec.frames[i];
    for (size_t j = 0; j < joints.size(); ++j) {
      joints[j].position = {fr.joints[j].position.x(), fr.joints[j].position.y(), fr.joints[j].position.z()};
      joints[j].tracking_state = static_cast<int32_t>(fr.joints[j].state);
    }
    drape_skeleton_frame f{sizeof(drape_skeleton_frame), static_cast<int32_t>(rec.layout),
                           static_cast<uint32_t>(joints.size()), 0, t, joints.data(), nullptr};
    drape_context_push_skeleton(ctx, &f);
    drape_context_update(ctx);
    drape_context_read_body_mesh(ctx, pos.data(), nrm.data(), nv, nullptr, 0);
    benchmark::DoNotOptimize(pos.data());
    t += 1.0 / 30.0;
    i = (i + 1) % rec.frames.size();
  }
  drape_context_destroy(ctx);
}
BENCHMARK(BM_FrameThroughCApi)->Arg(20)->Arg(64)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace drape
