// Side by side in one run: collision against the tracking ellipsoids (paper rule and Drape rule)
// versus collision against the true body mesh through a BVH — time per call and penetration into
// the true body afterwards. Particles: N points within +-3 cm of the body surface of a real frame
// (Ges01_wavehand.csv, frame 80, default 1.70 m / 65 kg body), the situation of a shirt in contact.
// Counters: pen_p99_mm / pen_max_mm = depth of particles inside the body mesh after collision
// (signed distance < 0), deeper2mm = fraction deeper than 2 mm, contacts per call.
// Run: ./build/release/tests/drape_benchmarks --benchmark_filter=ProxyVsMesh --benchmark_repetitions=5
#include "body/body_model.h"
#include "proxies/collision.h"
#include "proxies/mesh_bvh.h"
#include "proxies/mesh_collider.h"
#include "proxies/proxy_builder.h"
#include "recording/recording.h"
#include "skeleton/layouts.h"
#include "skeleton/tracker.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <random>

namespace drape {
namespace {

struct Scene {
  std::unique_ptr<BodyModel> body;
  SkeletonPose pose;
  TriangleBvh bvh;
  bool ok = false;
};

const Scene& scene() {
  static Scene s = [] {
    Scene out;
    const char* env = std::getenv("DRAPE_SHARED_DATA");
    const std::string path =
        std::string(env ? env : DRAPE_SHARED_DATA_DIR) + "/kinect_v2_msft_labanotation/Ges01_wavehand.csv";
    Recording rec;
    std::string err;
    if (!readRecordingFile(path, 0, rec, err)) return out;
    const ResolvedShape shape = resolveShape(BodyShapeInput{});
    out.body = std::make_unique<BodyModel>(shape, BodyModelParams{});
    SkeletonTracker tracker;
    for (size_t i = 0; i <= 80 && i < rec.frames.size(); ++i) {
      SkeletonPose raw;
      mapToCanonical(rec.layout, rec.frames[i].joints.data(), static_cast<int>(rec.frames[i].joints.size()), raw, err);
      tracker.push(raw, rec.frames[i].time_s);
    }
    out.pose = tracker.pose();
    out.body->update(out.pose);
    out.ok = out.bvh.build(out.body->positions(), out.body->indices());
    return out;
  }();
  return s;
}

std::vector<Eigen::Vector4f> particles(size_t n) {
  const Scene& s = scene();
  std::mt19937 rng(12345);
  const auto& P = s.body->positions();
  const auto& I = s.body->indices();
  std::uniform_int_distribution<size_t> tri(0, I.size() / 3 - 1);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), off(-0.03f, 0.03f);
  std::vector<Eigen::Vector4f> out(n);
  for (auto& p : out) {
    const size_t t = tri(rng);
    float a = u(rng), b = u(rng);
    if (a + b > 1.0f) {
      a = 1.0f - a;
      b = 1.0f - b;
    }
    const Vec3 &p0 = P[I[3 * t]], &p1 = P[I[3 * t + 1]], &p2 = P[I[3 * t + 2]];
    const Vec3 n = (p1 - p0).cross(p2 - p0).normalized();
    const Vec3 q = p0 + a * (p1 - p0) + b * (p2 - p0) + off(rng) * n;
    p = Eigen::Vector4f(q.x(), q.y(), q.z(), 1.0f);
  }
  return out;
}

void penetrationCounters(benchmark::State& state, const std::vector<Eigen::Vector4f>& after) {
  std::vector<float> depth;
  depth.reserve(after.size());
  size_t deeper2 = 0;
  for (const auto& p : after) {
    const float d = std::max(0.0f, -scene().bvh.signedDistance(p.head<3>()));
    depth.push_back(d);
    if (d > 0.002f) ++deeper2;
  }
  std::sort(depth.begin(), depth.end());
  state.counters["pen_p99_mm"] = 1000.0 * depth[depth.size() * 99 / 100];
  state.counters["pen_max_mm"] = 1000.0 * depth.back();
  state.counters["deeper2mm"] = static_cast<double>(deeper2) / static_cast<double>(after.size());
}

void BM_ProxyVsMesh_Ellipsoids(benchmark::State& state) {
  if (!scene().ok) return state.SkipWithError("shared recording not found");
  const size_t n = static_cast<size_t>(state.range(0));
  const ProxyRule rule = static_cast<ProxyRule>(state.range(1));
  ProxyBuilder proxies(rule);
  proxies.build(*scene().body, scene().pose);
  EllipsoidCollider collider;
  const auto& e = proxies.ellipsoids();
  collider.setEllipsoids(e.data(), e.data(), static_cast<int>(e.size()));
  const std::vector<Eigen::Vector4f> start = particles(n);
  std::vector<Eigen::Vector4f> work(n);
  CollisionParams params;
  uint32_t contacts = 0;
  for (auto _ : state) {
    state.PauseTiming();
    work = start;
    state.ResumeTiming();
    contacts = collider.collide(work.data(), start.data(), n, params).contacts;
    benchmark::DoNotOptimize(work.data());
  }
  state.counters["contacts"] = contacts;
  state.counters["ellipsoids"] = static_cast<double>(e.size());
  penetrationCounters(state, work);
  state.SetLabel(rule == ProxyRule::Paper ? "paper rule" : "drape rule");
}
BENCHMARK(BM_ProxyVsMesh_Ellipsoids)
    ->Args({2000, 0})->Args({2000, 1})->Args({20000, 0})->Args({20000, 1})
    ->Unit(benchmark::kMicrosecond);

void BM_ProxyVsMesh_BodyMeshBvh(benchmark::State& state) {
  if (!scene().ok) return state.SkipWithError("shared recording not found");
  const size_t n = static_cast<size_t>(state.range(0));
  const std::vector<Eigen::Vector4f> start = particles(n);
  std::vector<Eigen::Vector4f> work(n);
  uint32_t contacts = 0;
  for (auto _ : state) {
    state.PauseTiming();
    work = start;
    state.ResumeTiming();
    contacts = collideWithMesh(scene().bvh, work.data(), n, EllipsoidCollider::kDefaultMargin).contacts;
    benchmark::DoNotOptimize(work.data());
  }
  state.counters["contacts"] = contacts;
  penetrationCounters(state, work);
  state.SetLabel("body mesh BVH");
}
BENCHMARK(BM_ProxyVsMesh_BodyMeshBvh)->Arg(2000)->Arg(20000)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace drape
