// The adaptive pipeline: what a context skips when the scene does not need it (docs/adaptive.md).
//  - Proxy culling: only the tracking ellipsoids some awake garment can reach are built
//    (cloth/garment_reach.h); each garment's collider gets only its own.
//  - Stages on demand: the body mesh and its normals are computed when something reads them (the
//    host, a fidelity or accuracy measurement, the volume statistic), not on every update.
//  - Sleeping: once the body has stayed within sleep_distance_m of where it was and a garment's
//    particles have all moved slower than sleep_speed_m_s from step to step (displacement over
//    the step's dt: the solver's own velocities carry each substep's contact corrections, ~1 m/s
//    on cloth resting on a still body) for sleep_delay_s, the garment's step is
//    skipped; the body leaving that distance, a teleport, a new body shape, new cloth parameters
//    or the host wake it before anything is built for the frame, and it continues from the state
//    it slept in (the body's motion while it slept is swept across its first step: no pop).
// The options and counters mirror drape_pipeline_options / drape_skip_stats.
#pragma once

#include "cloth/garment_reach.h"
#include "common/math.h"
#include "proxies/ellipsoid.h"
#include "skeleton/joints.h"

#include <cstdint>
#include <string>
#include <vector>

namespace drape {

class GarmentSim;

struct PipelineOptions {
  bool cull_proxies = true;
  bool stages_on_demand = true;
  bool sleep = true;
  float sleep_delay_s = 0.5f;      // stillness needed before a garment sleeps, [0, 60]
  float sleep_distance_m = 0.005f; // joints within this of where they were count as still, [0, 1]
  float sleep_speed_m_s = 0.02f;   // every particle slower than this counts as still, [0, 10]
  float reach_margin_m = 0.1f;     // added to each garment's reach (body motion in a frame), [0, 2]
};
// Empty when valid, else what is wrong. `nonfinite` is set when a value is NaN or Inf.
std::string validate(const PipelineOptions& o, bool* nonfinite = nullptr);

// Stage bits of SkipCounters::stages_skipped_last (= drape_pipeline_stage).
enum PipelineStage : uint32_t {
  kStageBodyMesh = 1u,     // body vertex positions
  kStageBodyNormals = 2u,  // body vertex normals
  kStageProxies = 4u,      // some tracking ellipsoids (culled)
  kStageCloth = 8u,        // some garment's step (asleep)
};

struct SkipCounters {
  uint32_t proxies_available = 0;   // ellipsoids the body has
  uint32_t proxies_built = 0;       // built by the last update
  uint32_t stages_skipped_last = 0; // PipelineStage bits for the last update / step
  uint32_t garments = 0;
  uint32_t garments_asleep = 0;
  uint64_t updates = 0;             // updates that built the body for a new frame
  uint64_t stages_skipped = 0;      // stage runs skipped so far (each bit of each frame)
  uint64_t proxies_skipped = 0;     // ellipsoid builds skipped so far
  uint64_t steps = 0;               // context steps with at least one garment
  uint64_t frames_slept = 0;        // of those, steps in which every garment slept
  uint64_t garment_steps_slept = 0; // garment steps skipped
};

// Per-garment sleep and reach state, owned by the context.
class AdaptiveState {
 public:
  void addGarment(const GarmentSim* g, std::vector<ReachSphere> reach);
  void removeGarment(const GarmentSim* g);
  const std::vector<ReachSphere>* reach(const GarmentSim* g) const;

  // A new pose was consumed (update): the body leaving sleep_distance_m of the still anchor (or a
  // teleport) wakes every garment and restarts the stillness clock.
  void observePose(const SkeletonPose& pose, bool teleported, const PipelineOptions& o);
  void wakeAll();
  void wake(const GarmentSim* g);
  bool asleep(const GarmentSim* g) const;
  size_t asleepCount() const;
  // Advances the clock by a step of dt (before the garments step).
  void advance(float dt) { clock_s_ += dt; }
  // For a garment that slept and is about to step: the ellipsoids to start its step from (its
  // reachable ones as they were when it fell asleep, the others `now`), else nullptr.
  const std::vector<Ellipsoid>* wakeStart(const GarmentSim* g, const std::vector<Ellipsoid>& now);
  // After g stepped by dt: its particles' displacement feeds its calm clock; it falls asleep when
  // both clocks reach sleep_delay_s. `now`: the ellipsoids the step ended on.
  void afterStep(const GarmentSim& g, const std::vector<Ellipsoid>& now, float dt, const PipelineOptions& o);

 private:
  struct Garment {
    const GarmentSim* g = nullptr;
    std::vector<ReachSphere> reach;
    bool calm = false, asleep = false, woke = false;
    double calm_since_s = 0.0;
    std::vector<int> slept_reach;           // reachable indices when it fell asleep
    std::vector<Ellipsoid> slept_ellipsoids; // their values then
    std::vector<Ellipsoid> start;            // wakeStart() scratch
    std::vector<Eigen::Vector4f> last_x;     // positions after its previous step
  };
  Garment* find(const GarmentSim* g);
  const Garment* find(const GarmentSim* g) const;
  std::vector<Garment> garments_;
  Vec3 anchor_[kJointCount];
  bool has_anchor_ = false;
  double still_since_s_ = 0.0, clock_s_ = 0.0;
};

}  // namespace drape
