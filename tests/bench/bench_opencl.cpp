// CPU vs OpenCL, side by side in one run (docs/opencl.md): one 1/30 s frame of the XPBD garment
// step (10 substeps, collision every second substep against the Drape tracking ellipsoids
// interpolated across the substeps) on a T-shirt of about 2 000, 8 000, 32 000 and 128 000
// particles driven by the bundled Kinect recording. Per stage: the CPU solver's own split
// (constraints = predict + projection + velocities; collision = collider setup + collide), the
// OpenCL frame's upload / kernel / readback / host packing from the queue's profiling events; and
// each case once without collision (arg collide = 0), so the collision stage is the difference.
// Run: ./build/perf/tests/drape_benchmarks --benchmark_filter=Backend --benchmark_repetitions=3
//      --benchmark_report_aggregates_only=true
#include "body/body_model.h"
#include "body/body_shape.h"
#include "cloth/garment_templates.h"
#include "cloth/garment_topology.h"
#include "cloth/xpbd_solver.h"
#include "proxies/proxy_builder.h"
#include "recording/recording.h"
#include "skeleton/layouts.h"
#include "skeleton/tracker.h"
#if DRAPE_HAVE_OPENCL
#include "backends/opencl/cl_xpbd_solver.h"
#endif

#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace drape {
namespace {

std::string recordingPath() {
  std::string dir = __FILE__;
  dir = dir.substr(0, dir.find_last_of("/\\") + 1);
  return dir + "../../samples/data/Ges01_wavehand.csv";
}

// Per recording frame: the ellipsoids and the pin targets (as bench_cloth.cpp's GarmentScene).
struct Scene {
  GarmentTopology topology;
  std::vector<std::vector<Ellipsoid>> ellipsoids;
  std::vector<std::vector<Vec3>> pins;
  Mat3 rotation = Mat3::Identity();
  Vec3 pivot = Vec3::Zero(), shift = Vec3::Zero();
  std::string error;
};

std::unique_ptr<Scene> buildScene(int target_particles) {
  auto out = std::make_unique<Scene>();
  Recording rec;
  if (!readRecordingFile(recordingPath(), 0, rec, out->error)) return out;
  const ResolvedShape shape = resolveShape(BodyShapeInput{});
  BodyModel body(shape, BodyModelParams{});
  ProxyBuilder proxies(ProxyRule::Drape);
  body.update(restPose(shape));
  GarmentTemplateParams gp;
  gp.kind = GarmentKind::TShirt;
  gp.target_particles = target_particles;
  GarmentMesh mesh;
  if (!makeGarmentTemplate(body, gp, mesh, out->error)) return out;
  const RingPose collar_rest = body.rings()[static_cast<size_t>(mesh.pin_ring[0])];
  TopologyParams tp;
  tp.pinned = mesh.pinned;
  if (!buildGarmentTopology(mesh.positions.data()->data(), mesh.positions.size(), mesh.indices.data(),
                            mesh.indices.size(), tp, out->topology, out->error))
    return out;
  std::map<uint32_t, size_t> pin_index;
  for (size_t i = 0; i < mesh.pinned.size(); ++i) pin_index[mesh.pinned[i]] = i;
  SkeletonTracker tracker;
  for (const RecordingFrame& f : rec.frames) {
    SkeletonPose raw;
    if (!mapToCanonical(rec.layout, f.joints.data(), static_cast<int>(f.joints.size()), raw, out->error)) return out;
    tracker.push(raw, f.time_s);
    body.update(tracker.pose());
    proxies.build(body, tracker.pose());
    out->ellipsoids.push_back(proxies.ellipsoids());
    std::vector<Vec3> pins;
    for (uint32_t p : out->topology.pinned) {
      const size_t i = pin_index[p];
      const RingPose& r = body.rings()[static_cast<size_t>(mesh.pin_ring[i])];
      pins.push_back(r.centre + r.frame * mesh.pin_local[i]);
    }
    out->pins.push_back(std::move(pins));
    if (out->pins.size() == 1) {
      const RingPose& c = body.rings()[static_cast<size_t>(mesh.pin_ring[0])];
      out->rotation = c.frame * collar_rest.frame.transpose();
      out->pivot = collar_rest.centre;
      out->shift = c.centre - collar_rest.centre;
    }
  }
  return out;
}

Scene& scene(int target, benchmark::State& state) {
  static std::map<int, std::unique_ptr<Scene>> cache;
  auto& s = cache[target];
  if (!s) s = buildScene(target);
  if (!s->error.empty() || s->pins.empty()) state.SkipWithError(s->error.c_str());
  return *s;
}

size_t pingPong(size_t i, size_t n) {
  if (n < 2) return 0;
  const size_t period = 2 * (n - 1), k = i % period;
  return k < n ? k : period - k;
}

constexpr int kSubsteps = 10;

XpbdParams benchParams() {
  XpbdParams p;
  p.collision_stride = 2;  // the garment default (GarmentSimParams)
  p.collision.max_escape_m = 0.01f;
  p.tether_scale = 1.1f;
  return p;
}

// Drives any solver with the XpbdSolver interface (S::setColliderMotion differs: adapter F).
template <class S, class Motion>
void runFrames(S& s, Scene& sc, size_t& frame, int count, bool collide, Motion&& motion) {
  std::string error;
  const size_t frames = sc.pins.size();
  for (int k = 0; k < count; ++k, ++frame) {
    const size_t f = pingPong(frame, frames), prev = pingPong(frame == 0 ? 0 : frame - 1, frames);
    s.setPinTargets(sc.pins[f].data(), sc.pins[f].size(), error);
    if (collide) motion(sc.ellipsoids[prev], sc.ellipsoids[f]);
    s.step(1.0f / 30.0f, kSubsteps);
  }
}

// Args: backend (0 CPU, 1 OpenCL), target particles, collide (0/1), path (OpenCL: 0 = automatic
// choice, ClXpbdSolver::Path::Auto; 1 = the one-work-group frame forced).
void BM_BackendGarmentFrame(benchmark::State& state) {
  const bool opencl = state.range(0) == 1;
  const bool collide = state.range(2) == 1;
  Scene& sc = scene(static_cast<int>(state.range(1)), state);
  if (sc.pins.empty()) return;
  size_t frame = 0;
  std::string error;
  double a = 0.0, b = 0.0;
  size_t particles = sc.topology.particleCount();
  if (!opencl) {
    XpbdSolver s(sc.topology);
    s.setParams(benchParams(), error);
    s.transform(sc.rotation, sc.pivot, sc.shift, 0.0f);
    EllipsoidCollider collider;
    auto motion = [&](const std::vector<Ellipsoid>& e0, const std::vector<Ellipsoid>& e1) {
      s.setColliderMotion(&collider, e0.data(), e1.data(), static_cast<int>(e1.size()), 0.004f, error);
    };
    runFrames(s, sc, frame, 5, collide, motion);  // settle a little, off the rest pose
    s.setTimingEnabled(true);
    for (auto _ : state) {
      runFrames(s, sc, frame, 1, collide, motion);
      benchmark::DoNotOptimize(s.positions());
      a += s.lastTimings().constraints_ns;
      b += s.lastTimings().collision_ns;
    }
    const double n = static_cast<double>(state.iterations()) * 1e6;
    state.counters["constraints_ms"] = a / n;
    state.counters["collision_ms"] = b / n;
  } else {
#if DRAPE_HAVE_OPENCL
    static std::shared_ptr<ClRuntime> rt;
    static std::string why;
    if (!rt && why.empty()) rt = ClRuntime::create(ClChoice{}, why);
    if (!rt) return state.SkipWithError(("no OpenCL device: " + why).c_str());
    auto s = ClXpbdSolver::create(rt, sc.topology, {}, {}, error);
    if (!s) return state.SkipWithError(error.c_str());
    if (state.range(3) == 1) s->setPath(ClXpbdSolver::Path::WorkGroup);
    s->setParams(benchParams(), error);
    s->transform(sc.rotation, sc.pivot, sc.shift, 0.0f);
    auto motion = [&](const std::vector<Ellipsoid>& e0, const std::vector<Ellipsoid>& e1) {
      s->setColliderMotion(e0.data(), e1.data(), static_cast<int>(e1.size()), 0.004f, {}, error);
    };
    runFrames(*s, sc, frame, 5, collide, motion);
    double c = 0.0, d = 0.0;
    for (auto _ : state) {
      runFrames(*s, sc, frame, 1, collide, motion);
      benchmark::DoNotOptimize(s->positions());
      a += s->lastTimings().upload_ns;
      b += s->lastTimings().kernel_ns;
      c += s->lastTimings().readback_ns;
      d += s->lastTimings().host_ns;
    }
    const double n = static_cast<double>(state.iterations()) * 1e6;
    state.counters["upload_ms"] = a / n;
    state.counters["kernel_ms"] = b / n;
    state.counters["readback_ms"] = c / n;
    state.counters["host_ms"] = d / n;
    state.counters["local_mem"] = s->usesLocalMemory() ? 1.0 : 0.0;
    state.counters["phases"] = s->usesPhases() ? 1.0 : 0.0;
    state.SetLabel(rt->deviceName());
#else
    return state.SkipWithError("built without OpenCL");
#endif
  }
  state.counters["particles"] = static_cast<double>(particles);
}

void backendArgs(benchmark::internal::Benchmark* b) {
  for (int particles : {2000, 8000, 32000, 128000})
    for (int collide : {1, 0}) {
      for (int backend : {0, 1}) b->Args({backend, particles, collide, 0});
      if (particles >= 8000 && particles <= 32000) b->Args({1, particles, collide, 1});  // work-group forced
    }
}
BENCHMARK(BM_BackendGarmentFrame)->Apply(backendArgs)->ArgNames({"opencl", "particles", "collide", "workgroup"})
    ->Unit(benchmark::kMillisecond)->MinTime(0.5);

}  // namespace
}  // namespace drape
