// One setting of Drape replayed over one take through the C ABI: the per-stage times of every
// frame and, on a measuring run, the garment's vertices and the error figures of every frame.
#pragma once

#include <drape/drape.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace bench {

// A real recording, replayed at `rate_hz` (every `stride`-th frame; the 120 Hz BVH takes at 60 Hz
// so that a frame is the 1/60 s the Bullet and NvCloth figures are quoted for).
struct Take {
  std::string name;  // short name for tables (file stem)
  std::string path;
  int32_t layout = 0;
  uint32_t joint_count = 0;
  std::vector<std::vector<drape_joint>> frames;  // the frames replayed, in order
  std::vector<double> timestamps_s;
  double rate_hz = 30.0;  // replayed frames per second (median)
};

// Reads `frames` frames (0 = all) of the recording, keeping every `stride`-th. Empty error = ok.
bool loadTake(const std::string& path, uint32_t frames, uint32_t stride, Take& out, std::string& error);

// Every knob the sweeps turn. The defaults are the library's (drape_*_init) for a 2 000-particle
// T-shirt; solver/substeps defaults as drape-replay uses them.
struct Setting {
  std::string sweep;  // which sweep it belongs to
  std::string label;  // its value on that sweep's axis, e.g. "600 Hz"
  int32_t solver = DRAPE_SOLVER_XPBD;
  float substep_hz = 300.0f;
  uint32_t iterations = 1;
  uint32_t ring_points = 20;
  int32_t proxy_rule = DRAPE_PROXY_RULE_DRAPE;
  int32_t contact_response = DRAPE_CONTACT_EXACT;
  uint32_t continuous_collision = 1;
  float strain_limit = 0.1f;  // drape_cloth_params.strain_limit (0 = off); XPBD only
  uint32_t strain_limit_passes = 2;  // drape_cloth_params.strain_limit_passes, [1, 16]
  uint32_t particles = 2000;
  std::string backend = "cpu";
  bool is_default = false;

  // Identity of the simulation (sweep and label excluded), for caches.
  std::string key() const;
  // The converged reference for the same input: 16x the substep rate (capped at the library's
  // 20 000 Hz) and 4x the iterations (XPBD only: the mass-spring solver has none), on the CPU.
  // quick (drape-bench --quick, which CI runs so the benchmark never rots; its figures are not
  // quoted): XPBD 4x the substep rate and 2x the iterations (above every quick point, an eighth
  // of the work), mass-spring 2x the rate (the references were two thirds of a quick run).
  Setting reference(bool quick = false) const;
  // The model a reference converges (solver, K, proxy rule, contact response, swept test,
  // particles): settings that differ only in substeps, iterations, strain limit or backend share
  // one converged reference, convergedReference().
  std::string modelKey() const;
  // That shared reference: the model at its solver's base substep rate, one iteration and the
  // default strain limit, then reference(quick). The strain limit is left out because at the
  // reference's 16x the substeps a chain's stretch is 1/256 of the default's, so the limit hardly
  // acts there; one reference prices every limit.
  Setting convergedReference(bool quick = false) const;
};

// The mass-spring solver's substep rate when none is given (drape-replay's: 96 per 1/30 s, the
// 48 per 1/60 s the paper's method needs not to blow up; ../shared/ANCHORS.md).
constexpr float kMassSpringSubstepHz = 2880.0f;

struct FrameTimes {  // milliseconds of one replayed frame
  double frame = 0, skeleton = 0, body = 0, proxies = 0, cloth = 0, integrate = 0, collide = 0;
};

struct FrameErrors {
  uint32_t proxy_inside = 0;  // drape_garment_measure (the ellipsoids each particle collides with)
};

struct RunResult {
  uint32_t particles = 0;  // actual vertex count of the garment built
  uint32_t attached = 0;
  std::string device;                              // the OpenCL device, when that backend ran
  std::vector<FrameTimes> times;                   // steady frames only (no blend-in or teleport frame)
  std::vector<std::vector<drape_vec3>> positions;  // per frame, when kept
  std::vector<drape_vec3> rest;
  std::vector<uint32_t> indices;
  std::vector<uint8_t> pinned;  // 1 for attached vertices
  // Error figures (measuring runs only).
  double stretch_p99 = 0, stretch_max = 0;
  double penetration_p99_mm = 0, penetration_max_mm = 0, deeper_than_2mm = 0;
  double in_body = 0;      // vertex-frames inside the body mesh at any depth
  double inside_mean = 0;  // particles inside an ellipsoid, mean per frame
  uint32_t inside_max = 0;
  double openings_off = 0;  // fraction of measured frames with an opening off its body part
  uint32_t nan_resets = 0;
  // Whole-run substeps per frame (median) as the library reports them.
  double substeps_per_frame = 0;
};

struct RunOptions {
  bool measure = false;         // error figures every frame (outside the timed calls)
  bool keep_positions = false;  // garment vertices of every frame (references and deviation)
};

// Replays `take` with `s`. false + error on a library failure.
bool runDrape(const Take& take, const Setting& s, const RunOptions& o, RunResult& out, std::string& error);

// The template particle count whose T-shirt has the vertex count closest to `wanted` (templates
// land within +-15 % of their target): for the paper's Table 1 at 2 000 particles.
bool templateTargetFor(uint32_t wanted, uint32_t& target, std::string& error);

// Error text for a failed call: the result name and drape_last_error().
std::string libraryError(const char* call, drape_result r);
// For `if (drape_result r = call(...)) return failed("call", r, error);`: sets error, returns false.
// Frame i of the take as drape_context_push_skeleton takes it (joints point into take), and the
// step drape_context_step gets for it: the recording's dt (one period on the first frame),
// clamped to [1e-4, 1] s.
drape_skeleton_frame skeletonFrame(const Take& take, size_t i);
float frameDt(const Take& take, size_t i);
bool failed(const char* call, drape_result r, std::string& error);
// True when r is DRAPE_OK; else sets error and returns false.
bool ok(const char* call, drape_result r, std::string& error);

}  // namespace bench
