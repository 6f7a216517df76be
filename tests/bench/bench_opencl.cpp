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
#include "cloth/garment_sim.h"
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

#include "bench_garment_scene.h"

#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace drape {
namespace {

using Scene = bench::GarmentScene;
using bench::pingPong;

Scene& scene(int target, benchmark::State& state) {
  static std::map<int, std::unique_ptr<Scene>> cache;
  auto& s = cache[target];
  if (!s) s = bench::buildGarmentScene(target);
  if (!s->error.empty() || s->pins.empty()) state.SkipWithError(s->error.c_str());
  return *s;
}

constexpr int kSubsteps = 10;

XpbdParams benchParams() {
  return GarmentSimParams{}.xpbd;  // the garment default: collision stride 2, 1 cm escape, tether
                                   // slack 1.1, strain limit 0.1
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
// choice, ClXpbdSolver::Path::Auto; 1 = the one-work-group frame forced; 2 = the per-phase
// launches forced, to price the 4 096-particle threshold on a GPU).
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
    if (state.range(3) == 2) s->setPath(ClXpbdSolver::Path::Phases);
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
  // 500-2 600 (collision on): where the one work-group frame and the per-phase launches both fit
  // a GPU's local memory, each forced, to price Auto's choice between them on a GPU.
  for (int particles : {500, 1000, 1400, 2600}) {
    b->Args({0, particles, 1, 0});
    b->Args({1, particles, 1, 1});
    b->Args({1, particles, 1, 2});
  }
  for (int particles : {2000, 4000, 8000, 32000, 128000})
    for (int collide : {1, 0}) {
      for (int backend : {0, 1}) b->Args({backend, particles, collide, 0});
      if ((particles >= 8000 && particles <= 32000) || (particles == 2000 && collide == 1))
        b->Args({1, particles, collide, 1});  // work-group forced
      if (particles <= 4000) b->Args({1, particles, collide, 2});  // per-phase launches forced
    }
}
BENCHMARK(BM_BackendGarmentFrame)->Apply(backendArgs)->ArgNames({"opencl", "particles", "collide", "path"})
    ->Unit(benchmark::kMillisecond)->MinTime(0.5);

}  // namespace
}  // namespace drape
