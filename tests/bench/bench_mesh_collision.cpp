// What the paper's ellipsoids replace (§3.3): cloth particles collided with the body's triangles.
// The body is the default shape (1.70 m, 65 kg) at K = 20 (1 569 vertices, 3 134 triangles) in the
// rest pose; particles are scattered within 3 cm of its surface, inside and outside (a random
// point of a random triangle, area-weighted, moved along the face normal by U(-3, 3) cm).
// Figures and the exact command: docs/body-mesh-collision.md.
//
//   BM_MeshBvhBuild             full build (median split), per call
//   BM_MeshBvhRefit             refit to a moved pose (alternating two poses), per call
//   BM_ClosestQuery/N           one closest-point query per particle, no response
//   BM_CollideMeshBvh/N         collideWithMesh through the BVH, N particles
//   BM_CollideMeshBruteForce/N  every particle against every triangle (O(n·m))
//   BM_CollideRingEllipsoids/N  for scale: the paper's response (radial projection in unit space)
//                               against one ellipsoid per ring (78), AABB-culled
//   BM_ResetParticles/N         the particle copy every collision iteration includes
//   BM_Fidelity                 measureFidelity: 78 ring ellipsoids vs the body, 256 samples each
// per_particle is seconds per particle (so "150n" = 150 ns).
#include "body/body_model.h"
#include "proxies/ellipsoid.h"
#include "proxies/fidelity.h"
#include "proxies/mesh_bvh.h"
#include "proxies/mesh_collider.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace drape {
namespace {

constexpr float kMargin = 0.005f;

struct Scene {
  BodyModel body{resolveShape(BodyShapeInput{}), BodyModelParams{}};
  std::vector<Vec3> rest_positions, moved_positions;
  TriangleBvh bvh;
  std::vector<Ellipsoid> rings;

  Scene() {
    SkeletonPose moved = restPose(body.shape(), 10.0f);
    const Mat3 turn = Eigen::AngleAxisf(0.6f, Vec3::UnitY()).toRotationMatrix();
    const Vec3 pivot = moved.position[idx(Joint::Pelvis)];
    for (auto& p : moved.position) p = pivot + turn * (p - pivot);
    body.update(moved);
    moved_positions = body.positions();
    body.update(restPose(body.shape()));
    rest_positions = body.positions();
    bvh.build(rest_positions, body.indices());
    // One ellipsoid per ring: the ring's ellipse, half-height to the farther neighbour ring.
    for (int c = 0; c < kChainCount; ++c) {
      const int first = body.chainFirstRing(static_cast<Chain>(c));
      const int n = body.chainRingCount(static_cast<Chain>(c));
      for (int j = first; j < first + n; ++j) {
        const RingPose& r = body.rings()[j];
        float h = 0.005f;
        if (j > first) h = std::max(h, (r.centre - body.rings()[j - 1].centre).norm());
        if (j + 1 < first + n) h = std::max(h, (r.centre - body.rings()[j + 1].centre).norm());
        Ellipsoid e;
        e.centre = r.centre;
        e.rotation = r.frame;
        e.radii = Vec3(std::max(r.forward_m, 0.005f), h, std::max(r.side_m, 0.005f));
        e.refresh();
        rings.push_back(e);
      }
    }
  }

  std::vector<Eigen::Vector4f> particles(size_t count, unsigned seed) const {
    const auto& P = rest_positions;
    const auto& I = body.indices();
    std::vector<float> cumulative;
    float total = 0.0f;
    for (size_t t = 0; t < I.size(); t += 3) {
      total += 0.5f * (P[I[t + 1]] - P[I[t]]).cross(P[I[t + 2]] - P[I[t]]).norm();
      cumulative.push_back(total);
    }
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f), offset(-0.03f, 0.03f);
    std::vector<Eigen::Vector4f> out;
    for (size_t i = 0; i < count; ++i) {
      const size_t t = static_cast<size_t>(
          std::lower_bound(cumulative.begin(), cumulative.end(), unit(rng) * total) - cumulative.begin());
      const size_t k = 3 * std::min(t, cumulative.size() - 1);
      const Vec3 a = P[I[k]], b = P[I[k + 1]], c = P[I[k + 2]];
      float u = unit(rng), v = unit(rng);
      if (u + v > 1.0f) {
        u = 1.0f - u;
        v = 1.0f - v;
      }
      const Vec3 p = a + u * (b - a) + v * (c - a) + offset(rng) * (b - a).cross(c - a).normalized();
      out.emplace_back(p.x(), p.y(), p.z(), 1.0f);
    }
    return out;
  }
};

const Scene& scene() {
  static const Scene s;
  return s;
}

void perParticle(benchmark::State& state, size_t n) {
  state.counters["per_particle"] = benchmark::Counter(
      static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_MeshBvhBuild(benchmark::State& state) {
  const Scene& s = scene();
  TriangleBvh bvh;
  for (auto _ : state) {
    bvh.build(s.rest_positions, s.body.indices(), /*allow_refit=*/false);
    benchmark::DoNotOptimize(bvh.nodeCount());
  }
  state.counters["triangles"] = static_cast<double>(bvh.triangleCount());
  state.counters["nodes"] = static_cast<double>(bvh.nodeCount());
  state.counters["depth"] = static_cast<double>(bvh.depth());
}
BENCHMARK(BM_MeshBvhBuild)->Unit(benchmark::kMicrosecond);

void BM_MeshBvhRefit(benchmark::State& state) {
  const Scene& s = scene();
  TriangleBvh bvh;
  bvh.build(s.rest_positions, s.body.indices());
  bool flip = false;
  for (auto _ : state) {
    bvh.refit(flip ? s.rest_positions : s.moved_positions);
    flip = !flip;
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_MeshBvhRefit)->Unit(benchmark::kMicrosecond);

// One unbounded closest-point query per particle position (no response), for the raw query cost.
void BM_ClosestQuery(benchmark::State& state) {
  const Scene& s = scene();
  const size_t n = static_cast<size_t>(state.range(0));
  const std::vector<Eigen::Vector4f> points = s.particles(n, 1);
  for (auto _ : state) {
    float sum = 0.0f;
    for (const auto& x : points) sum += s.bvh.closest(x.head<3>()).distance;
    benchmark::DoNotOptimize(sum);
  }
  perParticle(state, n);
}
BENCHMARK(BM_ClosestQuery)->Arg(2000)->Unit(benchmark::kMicrosecond);

void BM_ResetParticles(benchmark::State& state) {
  const size_t n = static_cast<size_t>(state.range(0));
  const std::vector<Eigen::Vector4f> start = scene().particles(n, 1);
  std::vector<Eigen::Vector4f> work(n);
  for (auto _ : state) {
    std::copy(start.begin(), start.end(), work.begin());
    benchmark::ClobberMemory();
  }
  perParticle(state, n);
}
BENCHMARK(BM_ResetParticles)->Arg(2000)->Arg(20000)->Unit(benchmark::kMicrosecond);

void BM_CollideMeshBvh(benchmark::State& state) {
  const Scene& s = scene();
  const size_t n = static_cast<size_t>(state.range(0));
  const std::vector<Eigen::Vector4f> start = s.particles(n, 1);
  std::vector<Eigen::Vector4f> work(n);
  MeshCollisionStats stats;
  for (auto _ : state) {
    std::copy(start.begin(), start.end(), work.begin());
    stats = collideWithMesh(s.bvh, work.data(), n, kMargin);
    benchmark::DoNotOptimize(stats);
  }
  perParticle(state, n);
  state.counters["contacts"] = stats.contacts;
  state.counters["projections"] = stats.passes;
}
BENCHMARK(BM_CollideMeshBvh)->Arg(2000)->Arg(20000)->Unit(benchmark::kMicrosecond);

void BM_CollideMeshBruteForce(benchmark::State& state) {
  const Scene& s = scene();
  const size_t n = static_cast<size_t>(state.range(0));
  const std::vector<Eigen::Vector4f> start = s.particles(n, 1);
  std::vector<Eigen::Vector4f> work(n);
  MeshCollisionStats stats;
  for (auto _ : state) {
    std::copy(start.begin(), start.end(), work.begin());
    stats = collideWithMeshBruteForce(s.bvh, work.data(), n, kMargin);
    benchmark::DoNotOptimize(stats);
  }
  perParticle(state, n);
  state.counters["contacts"] = stats.contacts;
}
BENCHMARK(BM_CollideMeshBruteForce)->Arg(2000)->Unit(benchmark::kMillisecond);

// The paper's eq. 7-10 against the ring ellipsoids, for scale only (Drape's own ellipsoid
// collider lives in proxies/collision.h).
void BM_CollideRingEllipsoids(benchmark::State& state) {
  const Scene& s = scene();
  const size_t n = static_cast<size_t>(state.range(0));
  const std::vector<Eigen::Vector4f> start = s.particles(n, 1);
  std::vector<Eigen::Vector4f> work(n);
  for (auto _ : state) {
    std::copy(start.begin(), start.end(), work.begin());
    uint32_t contacts = 0;
    for (auto& x : work) {
      Vec3 p = x.head<3>();
      for (const Ellipsoid& e : s.rings) {
        if ((p.array() < e.bounds_min.array()).any() || (p.array() > e.bounds_max.array()).any())
          continue;
        const Vec3 q = e.toUnit(p);
        const float len2 = q.squaredNorm();
        if (len2 < 1.0f && len2 > 0.0f) {
          p = e.fromUnit(q / std::sqrt(len2));
          ++contacts;
        }
      }
      x.head<3>() = p;
    }
    benchmark::DoNotOptimize(contacts);
  }
  perParticle(state, n);
  state.counters["ellipsoids"] = static_cast<double>(s.rings.size());
}
BENCHMARK(BM_CollideRingEllipsoids)->Arg(2000)->Arg(20000)->Unit(benchmark::kMicrosecond);

void BM_Fidelity(benchmark::State& state) {
  const Scene& s = scene();
  FidelityReport r;
  for (auto _ : state) {
    r = measureFidelity(s.rest_positions, s.body.indices(), s.rings.data(),
                        static_cast<int>(s.rings.size()), s.bvh, 256);
    benchmark::DoNotOptimize(r);
  }
  state.counters["ellipsoids"] = static_cast<double>(s.rings.size());
  state.counters["union_samples"] = r.union_samples;
}
BENCHMARK(BM_Fidelity)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace drape
