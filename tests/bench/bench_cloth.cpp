// Cloth solver cost (native/src/cloth/): one 1/30 s frame of substepped XPBD (default substeps,
// no collision) on a hanging cloth grid of about 2 000, 8 000 and 32 000 particles, and the
// paper's mass-spring baseline for 2 000 particles at the same substep count and at 96 substeps
// per 1/30 s (the 48 per 1/60 s it needs to stay stable). GarmentFrame: a T-shirt dressed on a
// body driven by the bundled Kinect recording, with collision against the tracking ellipsoids.
// Run: ./build/perf/tests/drape_benchmarks --benchmark_filter='Cloth|Garment' --benchmark_repetitions=5
#include "body/body_model.h"
#include "body/body_shape.h"
#include "cloth/garment_templates.h"
#include "cloth/garment_topology.h"
#include "cloth/mass_spring_solver.h"
#include "cloth/xpbd_solver.h"
#include "proxies/proxy_builder.h"
#include "recording/recording.h"
#include "skeleton/layouts.h"
#include "skeleton/tracker.h"

#include "bench_garment_scene.h"

#include <benchmark/benchmark.h>

#include <chrono>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace drape {
namespace {

using bench::GarmentScene;
using bench::buildGarmentScene;
using bench::pingPong;

// n x n particles, 1 m square hanging in the XY plane, pinned along its whole top row (a shirt's
// shoulders and collar hang from many particles), two tethers per particle.
GarmentTopology hangingGrid(int n) {
  std::vector<float> positions;
  std::vector<uint32_t> indices;
  makeClothGrid(n, n, 1.0f, 1.0f, Vec3::Zero(), Vec3::UnitX(), -Vec3::UnitY(), positions, indices);
  TopologyParams p;
  for (int i = 0; i < n; i += 4) p.pinned.push_back(static_cast<uint32_t>(i));
  p.pinned.push_back(static_cast<uint32_t>(n - 1));
  GarmentTopology t;
  std::string error;
  buildGarmentTopology(positions.data(), positions.size() / 3, indices.data(), indices.size(), p,
                       t, error);
  return t;
}

// The pins sway sideways so the cloth keeps moving (no settled, cache-trivial state).
void swayTargets(const GarmentTopology& t, int frame, std::vector<Vec3>& targets) {
  const float dx = 0.05f * static_cast<float>(frame % 60 < 30 ? frame % 30 : 30 - frame % 30) / 30.0f;
  targets.resize(t.pinned.size());
  for (size_t k = 0; k < t.pinned.size(); ++k)
    targets[k] = t.rest_positions[t.pinned[k]] + Vec3(dx, 0.0f, 0.0f);
}

void BM_ClothXpbdFrame(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  XpbdSolver s(hangingGrid(n));
  std::vector<Vec3> targets;
  std::string error;
  int frame = 0;
  for (int f = 0; f < 30; ++f) {  // warm up: let it start swinging
    swayTargets(s.topology(), frame++, targets);
    s.setPinTargets(targets.data(), targets.size(), error);
    s.step(1.0f / 30.0f);
  }
  for (auto _ : state) {
    swayTargets(s.topology(), frame++, targets);
    s.setPinTargets(targets.data(), targets.size(), error);
    s.step(1.0f / 30.0f, XpbdSolver::kDefaultSubsteps);
    benchmark::DoNotOptimize(s.positions());
  }
  state.counters["particles"] = static_cast<double>(s.particleCount());
  state.counters["substeps"] = XpbdSolver::kDefaultSubsteps;
}
BENCHMARK(BM_ClothXpbdFrame)->Arg(45)->Arg(90)->Arg(179)->Unit(benchmark::kMillisecond);

void BM_ClothMassSpringFrame(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int substeps = static_cast<int>(state.range(1));
  MassSpringSolver s(hangingGrid(n));
  std::vector<Vec3> targets;
  std::string error;
  int frame = 0;
  for (auto _ : state) {
    swayTargets(s.topology(), frame++, targets);
    s.setPinTargets(targets.data(), targets.size(), error);
    s.step(1.0f / 30.0f, substeps);
    benchmark::DoNotOptimize(s.positions());
  }
  state.counters["particles"] = static_cast<double>(s.particleCount());
  state.counters["explosions"] = static_cast<double>(s.explosions());
}
BENCHMARK(BM_ClothMassSpringFrame)
    ->Args({45, XpbdSolver::kDefaultSubsteps})
    ->Args({45, 96})
    ->Unit(benchmark::kMillisecond);

// ---- GarmentFrame: the realistic scene --------------------------------------------------------

// One cloth step per recording frame at 1/30 s, 10 substeps, collision against the ~137 Drape
// ellipsoids interpolated across the substeps. Times setPinTargets + setColliderMotion + step.
// Counters: ns per particle per substep, total and split (constraints = predict, XPBD projection
// and velocity update; collision = per-substep collider setup + collide()). Arg lanes: 16 = the
// default where the CPU has AVX-512F (collision pass 0 sixteen particles at once, projection 16
// constraints at once, the update four particles at once); 8 = the AVX kernels (as a CPU without
// AVX-512F runs); 1 = the AVX kernels with the collider one particle at a time. Same results.
void BM_GarmentFrame(benchmark::State& state) {
  static std::map<int, std::unique_ptr<GarmentScene>> cache;
  const int target = static_cast<int>(state.range(0));
  auto& scene = cache[target];
  if (!scene) scene = buildGarmentScene(target);
  if (!scene->error.empty() || scene->pins.empty()) return state.SkipWithError(scene->error.c_str());
  XpbdSolver s(scene->topology);
  s.transform(scene->rotation, scene->pivot, scene->shift, 0.0f);
  EllipsoidCollider collider;
  std::string error;
  XpbdParams params;
  params.collision.batch8 = state.range(1) >= 8;
  params.collision.batch16 = state.range(1) == 16;
  s.setParams(params, error);
  s.setWideProjection(state.range(1) == 16);
  const size_t frames = scene->pins.size();
  constexpr int kSubsteps = XpbdSolver::kDefaultSubsteps;
  size_t frame = 0;
  auto advance = [&](size_t i) {
    const size_t f = pingPong(i, frames), prev = pingPong(i == 0 ? 0 : i - 1, frames);
    s.setPinTargets(scene->pins[f].data(), scene->pins[f].size(), error);
    const auto& a = scene->ellipsoids[prev];
    const auto& b = scene->ellipsoids[f];
    s.setColliderMotion(&collider, a.data(), b.data(), static_cast<int>(b.size()), 0.004f, error);
    s.step(1.0f / 30.0f, kSubsteps);
  };
  for (int f = 0; f < 30; ++f) {  // settle on the first frame's body
    s.setPinTargets(scene->pins[0].data(), scene->pins[0].size(), error);
    const auto& e = scene->ellipsoids[0];
    s.setColliderMotion(&collider, e.data(), e.data(), static_cast<int>(e.size()), 0.004f, error);
    s.step(1.0f / 30.0f, kSubsteps);
  }
  for (size_t i = 0; i < frames; ++i) advance(frame++);  // one pass over the take
  s.setTimingEnabled(true);
  double constraints_ns = 0.0, collision_ns = 0.0, contacts = 0.0, tests = 0.0, escapes = 0.0;
  for (auto _ : state) {
    advance(frame++);
    benchmark::DoNotOptimize(s.positions());
    constraints_ns += s.lastTimings().constraints_ns;
    collision_ns += s.lastTimings().collision_ns;
    contacts += s.lastCollisionStats().contacts;
    tests += s.lastCollisionStats().tests;
    escapes += s.lastCollisionStats().escapes;
  }
  const double per = static_cast<double>(state.iterations()) * kSubsteps *
                     static_cast<double>(s.particleCount());
  state.counters["particles"] = static_cast<double>(s.particleCount());
  state.counters["ellipsoids"] = static_cast<double>(scene->ellipsoids[0].size());
  state.counters["ns_constraints"] = constraints_ns / per;
  state.counters["ns_collision"] = collision_ns / per;
  state.counters["contacts_pct"] = 100.0 * contacts / per;
  state.counters["tests_per"] = tests / per;
  state.counters["escapes"] = escapes / static_cast<double>(state.iterations());
}
BENCHMARK(BM_GarmentFrame)
    ->ArgNames({"particles", "lanes"})
    ->ArgsProduct({{2000, 8000, 32000}, {1, 8, 16}})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace drape
