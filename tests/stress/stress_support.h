// Stress scenarios: shared machinery. A real take from ../shared/data is replayed through the C ABI
// (drape.h only) at any frame times (joints interpolated between recorded frames), with a
// perturbation applied to the joints the host pushes; every frame is stepped and (optionally)
// measured, and the figures the assertions need are kept per frame.
#pragma once

#include "capi_test_support.h"
#include "sanitizer_scale.h"
#include "test_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <initializer_list>
#include <random>
#include <cstdlib>
#include <string>
#include <vector>

namespace stress {

using Joints = std::array<drape_joint, 25>;

// Kinect v2 joint indices used by the scenarios.
enum J : int {
  SpineBase = 0, SpineMid = 1, Neck = 2, Head = 3, ShoulderL = 4, ElbowL = 5, WristL = 6, HandL = 7,
  ShoulderR = 8, ElbowR = 9, WristR = 10, HandR = 11, HipL = 12, KneeL = 13, AnkleL = 14, FootL = 15,
  HipR = 16, KneeR = 17, AnkleR = 18, FootR = 19, SpineShoulder = 20
};

// A recording as Kinect v2 joints; sample() interpolates positions linearly between frames.
struct Take {
  std::vector<Joints> frames;
  std::vector<double> times;
  double duration() const { return times.empty() ? 0.0 : times.back(); }
  Joints sample(double t) const {
    if (t <= 0.0) return frames.front();
    if (t >= times.back()) return frames.back();
    const size_t i = static_cast<size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
    const double a = (t - times[i - 1]) / (times[i] - times[i - 1]);
    Joints out = frames[i - 1];
    for (size_t j = 0; j < out.size(); ++j) {
      const drape_vec3 p = frames[i - 1][j].position, q = frames[i][j].position;
      out[j].position = drape_vec3{static_cast<float>(p.x + a * (q.x - p.x)), static_cast<float>(p.y + a * (q.y - p.y)),
                                   static_cast<float>(p.z + a * (q.z - p.z))};
      if (a > 0.5) out[j].tracking_state = frames[i][j].tracking_state;
    }
    return out;
  }
  // Ping-pong: forward then backward, for loops of any length with no jump at the ends.
  Joints sampleLooped(double t) const {
    const double d = duration();
    double u = std::fmod(t, 2.0 * d);
    if (u > d) u = 2.0 * d - u;
    return sample(u);
  }
};

inline bool loadTake(const std::string& path, Take& take, std::string& err) {
  drape_recording* r = nullptr;
  if (drape_recording_open(path.c_str(), DRAPE_LAYOUT_KINECT2, &r) != DRAPE_OK) {
    err = drape_last_error();
    return false;
  }
  drape_recording_info info;
  info.struct_size = sizeof info;
  drape_recording_get_info(r, &info);
  take.frames.resize(info.frame_count);
  take.times.resize(info.frame_count);
  for (uint32_t i = 0; i < info.frame_count; ++i)
    drape_recording_read_frame(r, i, take.frames[i].data(), 25, &take.times[i]);
  drape_recording_destroy(r);
  return true;
}

#define STRESS_REQUIRE_TAKE(var, relative)                                       \
  DRAPE_REQUIRE_SHARED(var##_path, relative);                                    \
  ::stress::Take var;                                                            \
  {                                                                              \
    std::string load_err;                                                        \
    ASSERT_TRUE(::stress::loadTake(var##_path, var, load_err)) << load_err;      \
  }

// The scenarios dress a 1 000-particle T-shirt; DRAPE_STRESS_PARTICLES=N (>= 200) dresses another
// resolution, to see how much a figure depends on it (docs/robustness.md, "Sensitivity"). Below
// about 300 a T-shirt's limbs leave their tubes on the shared takes (docs/cloth-solver.md, "Coarse
// garments come off"); StressLoop.ReplayLoopTenMinutes fails its worst-frame bound at 200 (not drift).
// Under the sanitizers (preset asan) the default is `under_sanitizers`: 200 particles for the
// scenarios that disturb the input (frame times, teleports, jitter, lost tracking, bad bones, bad
// input, an upside-down skeleton), which check how the pipeline takes the disturbance and recovers
// against the undisturbed run at the same resolution (each passes at 200 in release and under
// ASan), and 400 for those about the cloth itself (clothDressing(): compliance and mass, body
// shapes), whose stretch bounds depend on the resolution (at 200 the softest, heaviest cloth sags
// to P99 5.4 against its bound of 4.5). A replay at 400 costs about half of one at 1 000 under
// ASan, at 200 about a third less again (docs/robustness.md, "Sanitizers").
inline uint32_t defaultParticles(uint32_t under_sanitizers = 200) {
  const uint32_t fallback = drape::test::kSanitizedBuild ? under_sanitizers : 1000u;
  const char* w = std::getenv("DRAPE_STRESS_PARTICLES");
  if (w == nullptr) return fallback;
  const int n = std::atoi(w);
  return n >= 200 ? static_cast<uint32_t>(n) : fallback;
}

// The variants a scenario runs (frame rates, seeds, cases): all of `all` in a plain build; under
// the sanitizers only those at the indices `under_sanitizers`, chosen so that they still run every
// code path the scenario exists for (the others repeat those paths with other numbers, and each
// costs several seconds under ASan). Release keeps every variant and every bound.
template <typename T, size_t N>
std::vector<T> variants(const T (&all)[N], std::initializer_list<size_t> under_sanitizers) {
  if (!drape::test::kSanitizedBuild) return std::vector<T>(all, all + N);
  std::vector<T> kept;
  for (size_t i : under_sanitizers) {
    if (i < N) kept.push_back(all[i]);
    else ADD_FAILURE() << "variant " << i << " of " << N;
  }
  return kept;
}

// The scenarios dress a T-shirt; DRAPE_STRESS_GARMENT=tshirt|longsleeve|skirt|dress|trousers
// dresses another template (with the default desc: trousers and the long-sleeve cut by kind, for
// the person's skeleton once calibrated), to see whether a scenario's outcome depends on the
// garment (docs/robustness.md, "Sensitivity"). The bounds were set on the T-shirt.
inline int32_t defaultGarmentKind() {
  const char* w = std::getenv("DRAPE_STRESS_GARMENT");
  if (w == nullptr) return DRAPE_GARMENT_TSHIRT;
  const std::string k = w;
  if (k == "longsleeve") return DRAPE_GARMENT_LONG_SLEEVE;
  if (k == "skirt") return DRAPE_GARMENT_SKIRT;
  if (k == "dress") return DRAPE_GARMENT_DRESS;
  if (k == "trousers") return DRAPE_GARMENT_TROUSERS;
  if (k != "tshirt") ADD_FAILURE() << "DRAPE_STRESS_GARMENT=" << k << " is not tshirt, longsleeve, skirt, dress or trousers";
  return DRAPE_GARMENT_TSHIRT;
}

struct Dressing {
  int32_t kind = defaultGarmentKind();
  uint32_t particles = defaultParticles();
  bool set_shape = false;
  drape_body_shape shape{};
  bool set_desc = false;
  drape_garment_desc desc{};
  bool set_cloth = false;
  drape_cloth_params cloth{};
};

// The dressing of the scenarios about the cloth itself: 400 particles under the sanitizers.
inline Dressing clothDressing() {
  Dressing d;
  d.particles = defaultParticles(400);
  return d;
}

// How much of a take a scenario replays: all of it in a plain build; under the sanitizers only up
// to `checked_until`, the end of the last window the scenario checks (its recovery window, or 3 s
// after the disturbances start): the rest of the take only replays more undisturbed motion, at
// 2-3 s of ASan time per replay (docs/robustness.md, "Sanitizers").
inline double replayedSeconds(const Take& take, double checked_until) {
  return drape::test::kSanitizedBuild ? std::min(take.duration(), checked_until) : take.duration();
}

// Per-frame figures of one run.
struct Series {
  std::vector<double> t;
  std::vector<float> p99, max_stretch, vmax;  // stretch measured on measured frames only (else NaN)
  std::vector<uint32_t> inside;
  std::vector<int> openings_off;  // drape_garment_accuracy.openings_off on measured frames, else -1
  std::vector<uint8_t> teleport, blend;
  bool finite = true;
  int nan_resets = 0;
  int push_errors = 0, step_errors = 0;
  uint32_t particles = 0;
  uint64_t inside_total = 0;
  int measured = 0;

  // Median and maximum P99 stretch over measured frames with t in [t0, t1].
  float medianP99(double t0, double t1) const {
    std::vector<float> v;
    for (size_t i = 0; i < t.size(); ++i)
      if (t[i] >= t0 && t[i] <= t1 && std::isfinite(p99[i])) v.push_back(p99[i]);
    if (v.empty()) return NAN;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  }
  // Measured frames with t in [t0, t1] in which an opening was off its body part.
  int openingsOffFrames(double t0, double t1) const {
    int n = 0;
    for (size_t i = 0; i < t.size(); ++i)
      if (t[i] >= t0 && t[i] <= t1 && openings_off[i] > 0) ++n;
    return n;
  }
  float maxP99(double t0, double t1) const {
    float m = 0.0f;
    for (size_t i = 0; i < t.size(); ++i)
      if (t[i] >= t0 && t[i] <= t1 && std::isfinite(p99[i])) m = std::max(m, p99[i]);
    return m;
  }
  // Fastest particle over frames that neither blend a new pose in nor carry a teleport (those move
  // the garment with the body by design).
  float maxSpeed() const {
    float m = 0.0f;
    for (size_t i = 0; i < vmax.size(); ++i)
      if (!teleport[i] && !blend[i]) m = std::max(m, vmax[i]);
    return m;
  }
  double insideFraction() const {
    return measured == 0 ? 0.0 : static_cast<double>(inside_total) / (static_cast<double>(measured) * particles);
  }
};

// One context with one garment, stepped frame by frame through the C ABI.
class Scene {
 public:
  explicit Scene(const Dressing& s = Dressing()) {
    EXPECT_EQ(drape_context_create(nullptr, &ctx_), DRAPE_OK) << lastError();
    if (s.set_shape) {
      EXPECT_EQ(drape_context_set_body_shape(ctx_, &s.shape), DRAPE_OK) << lastError();
    }
    drape_garment_template t;
    drape_garment_template_init(&t);
    t.kind = s.kind;
    t.particles = s.particles;
    EXPECT_EQ(drape_context_add_garment_template(ctx_, s.set_desc ? &s.desc : nullptr, &t,
                                                 s.set_cloth ? &s.cloth : nullptr, &g_),
              DRAPE_OK)
        << lastError();
    series.particles = particles();
  }
  ~Scene() { drape_context_destroy(ctx_); }
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  drape_context* context() const { return ctx_; }
  drape_garment* garment() const { return g_; }
  uint32_t particles() const {
    uint32_t n = 0;
    drape_garment_get_mesh_size(g_, &n, nullptr);
    return n;
  }
  std::vector<float> positions() const {
    const float* x = nullptr;
    uint32_t n = 0;
    drape_garment_view_positions(g_, &x, &n);
    return std::vector<float>(x, x + 4 * n);
  }

  // Pushes `j` at time t, steps dt, records the frame. A refused push is counted and the step
  // still runs (the host keeps stepping with the last good pose).
  drape_result frame(const Joints& j, double t, float dt, bool measure) {
    drape_skeleton_frame f;
    std::memset(&f, 0, sizeof f);
    f.struct_size = sizeof f;
    f.layout = DRAPE_LAYOUT_KINECT2;
    f.joint_count = 25;
    f.timestamp_s = t;
    f.joints = j.data();
    const drape_result pr = drape_context_push_skeleton(ctx_, &f);
    if (pr != DRAPE_OK) ++series.push_errors;
    const std::vector<float> before = positions();
    const drape_result sr = drape_context_step(ctx_, dt);
    if (sr != DRAPE_OK) {
      ++series.step_errors;
      return sr;
    }
    record(before, t, dt, measure);
    return pr;
  }

  Series series;

 private:
  void record(const std::vector<float>& before, double t, float dt, bool measure) {
    const std::vector<float> x = positions();
    float v = 0.0f;
    for (size_t i = 0; i + 3 < x.size(); i += 4) {
      for (int k = 0; k < 3; ++k)
        if (!std::isfinite(x[i + k])) series.finite = false;
      if (!before.empty()) {
        const float dx = x[i] - before[i], dy = x[i + 1] - before[i + 1], dz = x[i + 2] - before[i + 2];
        v = std::max(v, std::sqrt(dx * dx + dy * dy + dz * dz) / dt);
      }
    }
    drape_garment_stats s;
    s.struct_size = sizeof s;
    drape_garment_get_stats(g_, &s);
    if (s.nan_reset) ++series.nan_resets;
    series.t.push_back(t);
    series.vmax.push_back(v);
    series.teleport.push_back(s.teleport_reset);
    series.blend.push_back(s.blend_frames > 0 ? 1 : 0);
    float p99 = NAN, mx = NAN;
    uint32_t inside = 0;
    int off = -1;
    if (measure) {
      drape_garment_accuracy a;
      a.struct_size = sizeof a;
      if (drape_garment_measure(g_, &a) == DRAPE_OK) {
        p99 = a.p99_stretch;
        mx = a.max_stretch;
        inside = a.proxy_inside;
        off = static_cast<int>(a.openings_off);
        if (!std::isfinite(a.p99_stretch) || !std::isfinite(a.max_stretch) || !std::isfinite(a.mean_stretch))
          series.finite = false;
        series.inside_total += a.proxy_inside;
        ++series.measured;
      }
    }
    series.p99.push_back(p99);
    series.max_stretch.push_back(mx);
    series.inside.push_back(inside);
    series.openings_off.push_back(off);
  }

  drape_context* ctx_ = nullptr;
  drape_garment* g_ = nullptr;
};

// Frame times: the take's duration sampled with dt from `nextDt` (constant or irregular).
inline std::vector<double> frameTimes(double duration, const std::function<double()>& nextDt) {
  std::vector<double> t;
  for (double u = 0.0; u <= duration; u += nextDt()) t.push_back(u);
  return t;
}
inline std::vector<double> fixedTimes(double duration, double dt) {
  return frameTimes(duration, [dt] { return dt; });
}

using Perturb = std::function<void(double t, Joints& j)>;

// Replays `take` at `times` (the first frame steps 1/30 s) with `perturb` applied to each frame,
// measuring every `measure_every` frames. Under the sanitizers half as often: the measurement (a
// signed distance to the body mesh for every particle) is 59 % of a replay's ASan time, and the
// checked figures are medians and maxima over windows that keep 15 measured frames or more.
inline Series replay(const Take& take, const std::vector<double>& times, const Perturb& perturb = nullptr,
                     const Dressing& setup = Dressing(), int measure_every = 1) {
  const size_t scale = drape::test::kSanitizedBuild ? 2 : 1;
  const size_t stride = measure_every > 0 ? scale * static_cast<size_t>(measure_every) : 0;  // 0: none
  Scene scene(setup);
  for (size_t i = 0; i < times.size(); ++i) {
    Joints j = take.sample(times[i]);
    if (perturb) perturb(times[i], j);
    const float dt = i == 0 ? 1.0f / 30.0f : static_cast<float>(times[i] - times[i - 1]);
    scene.frame(j, times[i], dt, stride > 0 && i % stride == 0);
  }
  return scene.series;
}

inline void print(const char* name, const Series& s, double t0 = 0.0, double t1 = 1e9) {
  std::printf("[ figures  ] %-34s frames %zu, P99 median %.3f worst %.3f (t %.1f-%.1f s), vmax %.1f m/s, "
              "inside %.4f %%, nan_resets %d, refused pushes %d\n",
              name, s.t.size(), s.medianP99(t0, t1), s.maxP99(t0, t1), t0, std::min(t1, s.t.empty() ? 0.0 : s.t.back()),
              s.maxSpeed(), 100.0 * s.insideFraction(), s.nan_resets, s.push_errors);
}

// The assertions every scenario makes (docs/robustness.md explains the bounds):
//  - every position and stretch figure finite, no NaN reset;
//  - particles slower than 50 m/s outside teleport and blend-in frames (limbs reach 10-15 m/s;
//    the existing real-data test measured at most 30 m/s; an explosion is far faster);
//  - under 0.5 % particle-frames inside an ellipsoid (cloth pinched between touching body parts
//    may stay inside, docs/garments.md "Escape limit").
inline void expectHealthy(const Series& s, const char* what, float speed_bound = 50.0f) {
  EXPECT_TRUE(s.finite) << what << ": a non-finite position or stretch";
  EXPECT_EQ(s.nan_resets, 0) << what << ": drape_garment_stats.nan_reset";
  EXPECT_EQ(s.step_errors, 0) << what << ": drape_context_step failed";
  EXPECT_LT(s.maxSpeed(), speed_bound) << what << ": particle speed";
  EXPECT_LT(s.insideFraction(), 0.005) << what << ": particle-frames inside an ellipsoid";
}

// Recovery: from one second after the disturbance ends, for `window` seconds, the median P99
// stretch is within `median_margin` of the undisturbed run's over the same window and the worst
// frame within `worst_margin` of the undisturbed worst, and the garment is as much on the body as
// in the undisturbed run: no more frames with an opening off its body part (a sleeve the arm left,
// docs/garments.md "Openings"). The margins are the noise between runs
// that should agree: the same undisturbed take built at -O1 (ASan) and -O2 differs by 3.4 points
// of median P99 over one window, and harmless disturbances (1 cm jitter, a lost arm) land 0-5
// points either side of the undisturbed run (docs/robustness.md).
inline void expectRecovered(const Series& s, const Series& control, double end, const char* what,
                            double window = 1.0, float median_margin = 0.06f, float worst_margin = 0.12f,
                            bool openings_back_on = true) {
  const double t0 = end + 1.0, t1 = end + 1.0 + window;
  const float m = s.medianP99(t0, t1), mc = control.medianP99(t0, t1);
  const float w = s.maxP99(t0, t1), wc = control.maxP99(t0, t1);
  const int off = s.openingsOffFrames(t0, t1), offc = control.openingsOffFrames(t0, t1);
  std::printf("[ recovery ] %-34s t %.1f-%.1f s: P99 median %.3f (undisturbed %.3f), worst %.3f (undisturbed %.3f), "
              "openings off in %d frames (undisturbed %d)\n",
              what, t0, t1, m, mc, w, wc, off, offc);
  ASSERT_TRUE(std::isfinite(m) && std::isfinite(mc)) << what << ": no measured frame in the recovery window";
  EXPECT_LE(m, mc + median_margin) << what << ": P99 stretch not back to the undisturbed run's one second after";
  EXPECT_LE(w, wc + worst_margin) << what << ": worst P99 one second after the disturbance";
  if (openings_back_on) EXPECT_LE(off, offc) << what << ": an opening off its body part one second after the disturbance";
}

}  // namespace stress
