// XPBD substeps against constraint iterations (XpbdParams::iterations): one 1/30 s frame of a
// ~2 000-particle hanging grid whose pins sway, at equal projection work (substeps x iterations =
// 10) and at the default 10 substeps with 1, 2, 4 and 8 iterations. What each costs beside what it
// buys in accuracy is drape-bench's job (docs/benchmarks.md); this is the kernel-level cost.
// Run: ./build/perf/tests/drape_benchmarks --benchmark_filter=Iterations --benchmark_repetitions=5
#include "cloth/garment_topology.h"
#include "cloth/xpbd_solver.h"

#include <benchmark/benchmark.h>

#include <string>
#include <vector>

namespace drape {
namespace {

// 45 x 45 particles (2 025), 1 m square hanging from every 4th particle of its top row.
GarmentTopology swayingGrid() {
  std::vector<float> positions;
  std::vector<uint32_t> indices;
  makeClothGrid(45, 45, 1.0f, 1.0f, Vec3::Zero(), Vec3::UnitX(), -Vec3::UnitY(), positions, indices);
  TopologyParams p;
  for (int i = 0; i < 45; i += 4) p.pinned.push_back(static_cast<uint32_t>(i));
  p.pinned.push_back(44);
  GarmentTopology t;
  std::string error;
  buildGarmentTopology(positions.data(), positions.size() / 3, indices.data(), indices.size(), p, t, error);
  return t;
}

void BM_XpbdIterations(benchmark::State& state) {
  const int substeps = static_cast<int>(state.range(0));
  XpbdSolver s(swayingGrid());
  XpbdParams params;
  params.iterations = static_cast<int>(state.range(1));
  std::string error;
  if (!s.setParams(params, error)) {
    state.SkipWithError(error.c_str());
    return;
  }
  std::vector<Vec3> targets(s.topology().pinned.size());
  int frame = 0;
  for (auto _ : state) {
    const float dx = 0.05f * static_cast<float>(frame % 60 < 30 ? frame % 30 : 30 - frame % 30) / 30.0f;
    ++frame;
    for (size_t k = 0; k < targets.size(); ++k)
      targets[k] = s.topology().rest_positions[s.topology().pinned[k]] + Vec3(dx, 0.0f, 0.0f);
    s.setPinTargets(targets.data(), targets.size(), error);
    s.step(1.0f / 30.0f, substeps);
    benchmark::DoNotOptimize(s.positions());
  }
  state.counters["particles"] = static_cast<double>(s.particleCount());
}
BENCHMARK(BM_XpbdIterations)
    ->ArgNames({"substeps", "iterations"})
    ->Args({10, 1})
    ->Args({5, 2})
    ->Args({2, 5})
    ->Args({1, 10})
    ->Args({10, 2})
    ->Args({10, 4})
    ->Args({10, 8})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace drape
