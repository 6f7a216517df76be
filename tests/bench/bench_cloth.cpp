// Cloth solver cost (native/src/cloth/): one 1/30 s frame of substepped XPBD (default substeps,
// no collision) on a hanging cloth grid of about 2 000, 8 000 and 32 000 particles, and the
// paper's mass-spring baseline for 2 000 particles at the same substep count and at 96 substeps
// per 1/30 s (the 48 per 1/60 s it needs to stay stable).
// Run: ./build/cloth/tests/drape_benchmarks --benchmark_filter=Cloth --benchmark_repetitions=5
#include "cloth/garment_topology.h"
#include "cloth/mass_spring_solver.h"
#include "cloth/xpbd_solver.h"

#include <benchmark/benchmark.h>

#include <string>
#include <vector>

namespace drape {
namespace {

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

}  // namespace
}  // namespace drape
