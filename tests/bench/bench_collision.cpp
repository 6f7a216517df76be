// Particle–ellipsoid collision cost (native/src/proxies/collision.h): one discrete test, one
// contact response (radial, exact), and one substep's collide() for 2 000 and 20 000 particles
// against 40 ellipsoids placed like a body, with and without the broad phase.
// Run: ./build/release/tests/drape_benchmarks --benchmark_filter=Collision --benchmark_repetitions=5
#include "cloth/collider_motion.h"
#include "proxies/closest_point.h"
#include "proxies/collision.h"

#include "../native/random_draws.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <random>
#include <vector>

namespace drape {
namespace {

using Vec4 = Eigen::Vector4f;

Ellipsoid make(const Vec3& c, const Vec3& radii, const Mat3& R = Mat3::Identity()) {
  Ellipsoid e;
  e.centre = c;
  e.radii = radii;
  e.rotation = R;
  e.refresh();
  return e;
}

// A limb ellipsoid along the bone a -> b (y axis along the bone, semi-axis = half the length).
Ellipsoid limb(const Vec3& a, const Vec3& b, float radius) {
  const Vec3 y = (b - a).normalized();
  const Mat3 R = drape::rotationBetween(Vec3::UnitY(), y).toRotationMatrix();
  return make(0.5f * (a + b), Vec3(radius, 0.5f * (b - a).norm(), radius), R);
}

// 40 ellipsoids: 22 torso rings (paper §3.2: one per ring, height = ring spacing), 2 buttocks,
// neck, head, 2 shoulder junctions, upper arms, forearms, hands (A-pose), thighs, calves, feet.
// x = left, y = up, z = forward; metres.
std::vector<Ellipsoid> bodyEllipsoids(float swing) {
  std::vector<Ellipsoid> es;
  for (int i = 0; i < 22; ++i) {
    const float t = static_cast<float>(i) / 21.0f;
    const float y = 0.90f + 0.55f * t;
    const float side = 0.16f - 0.04f * std::sin(kPi * t) + 0.01f * t;   // hip, waist, chest
    const float fwd = 0.105f - 0.01f * std::sin(kPi * t) + 0.015f * t;
    es.push_back(make(Vec3(0.0f, y, 0.0f), Vec3(side, 0.028f, fwd)));
  }
  for (float s : {-1.0f, 1.0f}) es.push_back(make(Vec3(0.08f * s, 0.86f, -0.03f), Vec3(0.09f, 0.09f, 0.09f)));
  es.push_back(make(Vec3(0.0f, 1.50f, 0.0f), Vec3(0.055f, 0.05f, 0.055f)));
  es.push_back(make(Vec3(0.0f, 1.62f, 0.01f), Vec3(0.08f, 0.11f, 0.095f)));
  for (float s : {-1.0f, 1.0f}) {
    const Vec3 shoulder(0.19f * s, 1.42f, 0.0f);
    const Mat3 swing_r = Eigen::AngleAxisf(swing * s, Vec3::UnitX()).toRotationMatrix();
    const Vec3 elbow = shoulder + swing_r * Vec3(0.11f * s, -0.27f, 0.0f);
    const Vec3 wrist = elbow + swing_r * Vec3(0.08f * s, -0.25f, 0.03f);
    const Vec3 hand = wrist + swing_r * Vec3(0.02f * s, -0.16f, 0.0f);
    es.push_back(make(shoulder, Vec3::Constant(0.055f)));
    es.push_back(limb(shoulder, elbow, 0.047f));
    es.push_back(limb(elbow, wrist, 0.036f));
    Ellipsoid h = limb(wrist, hand, 0.045f);
    h.radii.z() = 0.02f;
    h.refresh();
    es.push_back(h);
  }
  for (float s : {-1.0f, 1.0f}) {
    const Vec3 hip(0.09f * s, 0.90f, 0.0f), knee(0.10f * s, 0.48f, 0.01f), ankle(0.10f * s, 0.08f, -0.01f);
    es.push_back(limb(hip, knee, 0.075f));
    es.push_back(limb(knee, ankle, 0.055f));
    es.push_back(make(Vec3(0.10f * s, 0.04f, 0.06f), Vec3(0.045f, 0.035f, 0.12f)));
  }
  return es;
}

struct BodyScene {
  std::vector<Ellipsoid> start, end;
  std::vector<Vec4> x, prev;
};

// shell = false: particles uniform in the body's bounding box (the brief's scatter).
// shell = true: particles within ±4 mm of the union of the inflated torso and arm ellipsoids,
// like a shirt resting on the body: about half of them in contact every substep.
BodyScene makeScene(int particles, bool shell) {
  BodyScene s;
  s.start = bodyEllipsoids(0.0f);
  s.end = bodyEllipsoids(0.01f);  // arms swing 0.01 rad per substep (~2.4 rad/s at 240 Hz)
  for (Ellipsoid& e : s.end) {
    e.centre += Vec3(0.001f, 0.0f, 0.002f);  // the body walks 0.5 m/s
    e.refresh();
  }
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const float margin = EllipsoidCollider::kDefaultMargin;
  while (static_cast<int>(s.x.size()) < particles) {
    Vec3 p;
    if (shell) {
      // torso (0..21) or upper arm / forearm (27, 28, 31, 32)
      const int pick = static_cast<int>(std::uniform_int_distribution<int>(0, 25)(rng));
      const int k = pick < 22 ? pick : (pick == 22 ? 27 : pick == 23 ? 28 : pick == 24 ? 31 : 32);
      const Ellipsoid& e = s.end[static_cast<size_t>(k)];
      Vec3 d = test::draw3(u, rng);
      if (d.squaredNorm() < 1e-4f) continue;
      d.normalize();
      const Vec3 surface = e.centre + e.rotation * (e.radii + Vec3::Constant(margin)).cwiseProduct(d);
      // Only points on the union's surface: not inside any other (inflated) ellipsoid.
      bool buried = false;
      for (size_t j = 0; j < s.end.size() && !buried; ++j) {
        if (static_cast<int>(j) == k) continue;
        const Ellipsoid& o = s.end[j];
        const Vec3 q = (o.radii + Vec3::Constant(margin)).cwiseInverse().asDiagonal() * (o.rotation.transpose() * (surface - o.centre));
        buried = q.squaredNorm() < 1.0f;
      }
      if (buried) continue;
      const Vec3 n = (e.rotation * d.cwiseQuotient(e.radii + Vec3::Constant(margin))).normalized();
      p = surface + n * (0.004f * u(rng));
    } else {
      const float px = 0.45f * u(rng);
      const float py = 0.875f + 0.875f * u(rng);
      const float pz = 0.2f * u(rng);
      p = Vec3(px, py, pz);
    }
    const Vec3 v = test::draw3(u, rng) * 0.002f;
    s.x.emplace_back(p.x(), p.y(), p.z(), 1.0f);
    s.prev.emplace_back(p.x() - v.x(), p.y() - v.y(), p.z() - v.z(), 1.0f);
  }
  return s;
}

// Orders each consecutive block of `block` particles along a Morton curve (5 mm cells), so that
// neighbours in memory are neighbours in space, as the vertices of a cloth mesh are.
void mortonOrder(BodyScene& s, size_t block) {
  auto code = [](const Vec4& v) {
    uint64_t c = 0;
    const uint32_t q[3] = {static_cast<uint32_t>((v.x() + 1.0f) * 200.0f), static_cast<uint32_t>((v.y() + 0.2f) * 200.0f),
                           static_cast<uint32_t>((v.z() + 1.0f) * 200.0f)};
    for (uint32_t b = 0; b < 10; ++b) {
      for (uint32_t a = 0; a < 3; ++a) c |= static_cast<uint64_t>((q[a] >> b) & 1u) << (3 * b + a);
    }
    return c;
  };
  std::vector<size_t> idx(s.x.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  for (size_t b = 0; b < idx.size(); b += block) {
    const auto first = idx.begin() + static_cast<std::ptrdiff_t>(b);
    const auto last = idx.begin() + static_cast<std::ptrdiff_t>(std::min(b + block, idx.size()));
    std::sort(first, last, [&](size_t i, size_t j) { return code(s.x[i]) < code(s.x[j]); });
  }
  std::vector<Vec4> x, prev;
  for (size_t i : idx) {
    x.push_back(s.x[i]);
    prev.push_back(s.prev[i]);
  }
  s.x.swap(x);
  s.prev.swap(prev);
}

// --- single tests ---------------------------------------------------------------------------

std::vector<Vec3> pointsAround(const Ellipsoid& e, int n, float lo, float hi) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), r(lo, hi);
  std::vector<Vec3> pts;
  while (static_cast<int>(pts.size()) < n) {
    Vec3 d = test::draw3(u, rng);
    if (d.squaredNorm() < 1e-4f) continue;
    pts.push_back(e.fromUnit(d.normalized() * r(rng)));
  }
  return pts;
}

const Ellipsoid& forearm() {
  static const Ellipsoid e = make(Vec3(0.3f, 1.0f, 0.1f), Vec3(0.04f, 0.13f, 0.04f),
                                  Eigen::AngleAxisf(0.5f, Vec3(1, 0, 1).normalized()).toRotationMatrix());
  return e;
}

// The discrete inside test alone: q = to_unit (p - c), |q|^2 < 1.
void BM_CollisionDiscreteTest(benchmark::State& state) {
  const Ellipsoid& e = forearm();
  const std::vector<Vec3> pts = pointsAround(e, 4096, 0.5f, 1.5f);
  for (auto _ : state) {
    int inside = 0;
    for (const Vec3& p : pts) inside += e.toUnit(p).squaredNorm() < 1.0f;
    benchmark::DoNotOptimize(inside);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(pts.size()));
}
BENCHMARK(BM_CollisionDiscreteTest);

// Test + radial response for points inside (within 0.9..1.0 of the surface: typical contacts).
void BM_CollisionRadialContact(benchmark::State& state) {
  const Ellipsoid& e = forearm();
  const std::vector<Vec3> pts = pointsAround(e, 4096, 0.9f, 0.999f);
  for (auto _ : state) {
    Vec3 acc = Vec3::Zero();
    for (const Vec3& p : pts) {
      const Vec3 q = e.toUnit(p);
      const float r2 = q.squaredNorm();
      if (r2 < 1.0f) acc += e.fromUnit(q / std::sqrt(r2));
    }
    benchmark::DoNotOptimize(acc);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(pts.size()));
}
BENCHMARK(BM_CollisionRadialContact);

// Test + exact response (closest point, safeguarded Halley) for the same points; state.range(0)
// = 1: the bisection reference instead.
void BM_CollisionExactContact(benchmark::State& state) {
  const Ellipsoid& e = forearm();
  const std::vector<Vec3> pts = pointsAround(e, 4096, 0.9f, 0.999f);
  const bool bisection = state.range(0) == 1;
  for (auto _ : state) {
    Vec3 acc = Vec3::Zero();
    for (const Vec3& p : pts) {
      const Vec3 q = e.toUnit(p);
      if (q.squaredNorm() < 1.0f) {
        const Vec3 local = e.rotation.transpose() * (p - e.centre);
        const Vec3 y = bisection ? closestPointOnEllipsoid(e.radii, local) : closestPointOnEllipsoidFast(e.radii, local);
        acc += e.centre + e.rotation * y;
      }
    }
    benchmark::DoNotOptimize(acc);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(pts.size()));
}
BENCHMARK(BM_CollisionExactContact)->Arg(0)->Arg(1)->ArgName("bisection");

// --- one substep ------------------------------------------------------------------------------

void BM_CollisionSetEllipsoids(benchmark::State& state) {
  const BodyScene s = makeScene(1, false);
  EllipsoidCollider col;
  for (auto _ : state) {
    col.setEllipsoids(s.start.data(), s.end.data(), static_cast<int>(s.start.size()));
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_CollisionSetEllipsoids);

// A cloth step's collider set-up as XpbdSolver::step runs it for a garment of 1 250 particles or
// more (collision every second substep): ColliderMotion::set with the step's start and end
// ellipsoids (this step's start = last step's end), then the five spans of a 10-substep step
// (interpolated ellipsoids, the collider's shapes and one grid). Arg: the body's ellipsoids
// repeated that many times (a T-shirt reaches ~110 of the ~140 of a default body).
void BM_CollisionStepSetUp(benchmark::State& state) {
  std::vector<Ellipsoid> a, b;
  for (int r = 0; r < state.range(0); ++r) {
    const std::vector<Ellipsoid> a_r = bodyEllipsoids(0.0f), b_r = bodyEllipsoids(0.01f);
    a.insert(a.end(), a_r.begin(), a_r.end());
    b.insert(b.end(), b_r.begin(), b_r.end());
  }
  EllipsoidCollider col;
  ColliderMotion motion;
  std::string error;
  bool forward = true;
  for (auto _ : state) {
    // Steps alternate a -> b and b -> a, so each starts where the last one ended.
    motion.set(&col, forward ? a.data() : b.data(), forward ? b.data() : a.data(), static_cast<int>(a.size()),
               EllipsoidCollider::kDefaultMargin, error);
    for (int s = 0; s < 10; s += 2) benchmark::DoNotOptimize(motion.beginSpan(s, s + 2, 10));
    forward = !forward;
    benchmark::ClobberMemory();
  }
  state.counters["ellipsoids"] = static_cast<double>(a.size());
}
BENCHMARK(BM_CollisionStepSetUp)->Arg(1)->Arg(3)->Unit(benchmark::kMicrosecond);

// Args: particles, broad phase (0/1), scatter (0 = box, 1 = shell), response (0 radial, 1 exact),
// lanes: pass 0 for 16 particles at once (16, the default where the CPU has AVX-512F; 8 there
// without it), 8 at once (8: CollisionParams::batch16 off) or one at a time (1: batch8 off).
// Each iteration collides a different set of particles (20 000 in all, cycled): the same 2 000
// every iteration would let the branch predictor learn them and flatter the small case. Within
// a set the particles are in Morton order, like the vertices of a cloth mesh.
void BM_CollisionSubstep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int sets = std::max(1, 20000 / n);
  BodyScene s = makeScene(n * sets, state.range(2) == 1);
  mortonOrder(s, static_cast<size_t>(n));
  EllipsoidCollider col;
  col.setEllipsoids(s.start.data(), s.end.data(), static_cast<int>(s.start.size()));
  CollisionParams p;
  p.broad_phase = state.range(1) == 1;
  p.response = static_cast<ContactResponse>(state.range(3));
  p.batch8 = state.range(4) >= 8;
  p.batch16 = state.range(4) == 16;
  std::vector<Vec4> x(static_cast<size_t>(n));
  CollisionStats st;
  uint64_t contacts = 0, tests = 0, escapes = 0;
  int set = 0;
  for (auto _ : state) {
    state.PauseTiming();
    const size_t first = static_cast<size_t>(set) * static_cast<size_t>(n);
    std::copy(s.x.begin() + static_cast<std::ptrdiff_t>(first),
              s.x.begin() + static_cast<std::ptrdiff_t>(first + static_cast<size_t>(n)), x.begin());
    state.ResumeTiming();
    st = col.collide(x.data(), s.prev.data() + first, x.size(), p);
    benchmark::DoNotOptimize(x.data());
    contacts += st.contacts;
    tests += st.tests;
    escapes += st.escapes;
    set = (set + 1) % sets;
  }
  const double iters = static_cast<double>(state.iterations());
  state.counters["contacts"] = static_cast<double>(contacts) / iters;
  state.counters["tests"] = static_cast<double>(tests) / iters;
  state.counters["escapes"] = static_cast<double>(escapes) / iters;
  state.counters["contacts/s"] = benchmark::Counter(static_cast<double>(contacts), benchmark::Counter::kIsRate);
  state.counters["ns/particle"] = benchmark::Counter(static_cast<double>(n) * iters,
                                                     benchmark::Counter::kIsRate | benchmark::Counter::kInvert,
                                                     benchmark::Counter::OneK::kIs1000);
}
BENCHMARK(BM_CollisionSubstep)
    ->ArgNames({"particles", "grid", "shell", "exact", "lanes"})
    ->ArgsProduct({{2000, 20000}, {0, 1}, {0, 1}, {0, 1}, {1, 8, 16}})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace drape
