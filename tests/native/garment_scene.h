// A garment on a real recording, driven through drape::Context exactly as the C ABI drives it:
// push each frame, step by the frame's dt, measure. Shared by the garment tests.
#pragma once

#include "capi/context.h"
#include "cloth/garment_templates.h"
#include "recording/recording.h"
#include "skeleton/layouts.h"

#include <algorithm>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace drape::test {

struct SceneSummary {
  int frames = 0;
  float max_stretch = 0.0f;        // over all frames
  float p99_stretch_worst = 0.0f;  // worst per-frame P99
  float p99_stretch_median = 0.0f; // median per-frame P99
  float p99_stretch_p90 = 0.0f;    // 90th percentile of the per-frame P99s (the bad frames, but
                                   // not one chaotic frame)
  uint64_t proxy_inside = 0;       // summed over frames
  float penetration_p99_max_mm = 0.0f;  // worst per-frame P99 depth inside the body mesh
  float penetration_max_mm = 0.0f;
  float max_speed = 0.0f;
  bool finite = true;
  int nan_resets = 0, teleport_resets = 0;
  double step_ms_median = 0.0;
  uint32_t openings = 0;           // (opening, body part) pairs tracked (cloth/garment_openings.h)
  int openings_off_frames = 0;     // frames with at least one of them off its body part
};

inline drape_context_desc defaultDesc() {
  // The C ABI's defaults (drape_context_desc_init), so a field added to the desc gets its default.
  drape_context_desc d;
  drape_context_desc_init(&d);
  return d;
}

// Adds a template garment to `ctx` (dressed on the rest body).
inline GarmentSim* addTemplate(Context& ctx, GarmentKind kind, int particles, ClothSolverKind solver,
                               const GarmentSimParams& params, std::string& err,
                               float dress_time_s = 0.5f) {
  GarmentTemplateParams tp;
  tp.kind = kind;
  tp.target_particles = particles;
  auto g = GarmentSim::createTemplate(tp, TopologyParams{}, solver, params, dress_time_s, ctx.restBody(),
                                     ctx.restEllipsoids(), ctx.restEllipsoidGroups(), err);
  return g ? ctx.adoptGarment(std::move(g)) : nullptr;
}

// Reads the recording at `path` into `rec` and adds a template T-shirt of `particles` to `ctx`;
// null and err when either fails.
inline GarmentSim* readTakeAndAddTShirt(Context& ctx, const std::string& path, int particles, Recording& rec,
                                        std::string& err) {
  if (!readRecordingFile(path, 0, rec, err)) return nullptr;
  return addTemplate(ctx, GarmentKind::TShirt, particles, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
}

// Pushes frame `f` of `rec` (optionally changed by `perturb`) and steps by `dt`.
inline drape_result pushAndStep(Context& ctx, const Recording& rec, const RecordingFrame& f,
                                double time_s, float dt, std::string& err) {
  std::vector<drape_joint> joints(f.joints.size());
  for (size_t j = 0; j < joints.size(); ++j) {
    joints[j].position = {f.joints[j].position.x(), f.joints[j].position.y(), f.joints[j].position.z()};
    joints[j].tracking_state = static_cast<int32_t>(f.joints[j].state);
  }
  drape_skeleton_frame sf{};
  sf.struct_size = sizeof(sf);
  sf.layout = static_cast<int32_t>(rec.layout);
  sf.joint_count = static_cast<uint32_t>(joints.size());
  sf.timestamp_s = time_s;
  sf.joints = joints.data();
  if (drape_result r = ctx.pushFrame(sf, err)) return r;
  return ctx.step(dt, err);
}

// A Kinect v2 frame (25 joints) from a canonical pose: the tests' way to feed synthetic poses.
inline RecordingFrame kinect2FromPose(const SkeletonPose& pose, double time_s) {
  // Kinect v2 JointType order -> canonical joint.
  static const Joint kMap[25] = {
      Joint::Pelvis, Joint::SpineMid, Joint::Neck, Joint::Head, Joint::ShoulderL, Joint::ElbowL,
      Joint::WristL, Joint::HandL, Joint::ShoulderR, Joint::ElbowR, Joint::WristR, Joint::HandR,
      Joint::HipL, Joint::KneeL, Joint::AnkleL, Joint::FootL, Joint::HipR, Joint::KneeR,
      Joint::AnkleR, Joint::FootR, Joint::SpineShoulder, Joint::HandL, Joint::HandL, Joint::HandR,
      Joint::HandR};
  RecordingFrame f;
  f.time_s = time_s;
  f.joints.resize(25);
  for (int j = 0; j < 25; ++j) {
    f.joints[static_cast<size_t>(j)].position = pose.position[static_cast<size_t>(kMap[j])];
    f.joints[static_cast<size_t>(j)].state = TrackingState::Tracked;
  }
  return f;
}

// The same Kinect v2 frame with the knees only inferred. A first pose whose legs the sensor guesses
// has the context wait for the calibration to cut the garments cut for the skeleton (its
// provisional fit at the first pose asks for every limb joint tracked: capi/context.h): the way
// the tests of the calibration's recut still get one on synthetic poses, whose bones never change.
inline RecordingFrame withGuessedKnees(RecordingFrame f) {
  for (size_t k : {size_t{13}, size_t{17}})  // Kinect v2 KneeLeft, KneeRight
    if (k < f.joints.size()) f.joints[k].state = TrackingState::Inferred;
  return f;
}

// Replays the whole recording (frame dt from its timestamps, first frame 1/30 s) with `garment`
// in `ctx`, measuring after every step. `per_frame` (optional) sees each frame index.
inline SceneSummary replay(Context& ctx, GarmentSim& garment, const Recording& rec, std::string& err,
                           bool measure_body = true,
                           const std::function<void(int)>& per_frame = nullptr) {
  SceneSummary s;
  std::vector<float> p99s;
  std::vector<double> ms;
  double prev = rec.frames.empty() ? 0.0 : rec.frames.front().time_s - 1.0 / 30.0;
  for (size_t i = 0; i < rec.frames.size(); ++i) {
    const RecordingFrame& f = rec.frames[i];
    const float dt = static_cast<float>(f.time_s - prev);
    prev = f.time_s;
    if (pushAndStep(ctx, rec, f, f.time_s, dt, err) != DRAPE_OK) {
      s.finite = false;
      return s;
    }
    const GarmentAccuracy a = measure_body ? ctx.measureGarment(garment)
                                           : garment.measure(ctx.proxies().ellipsoids(), nullptr, &ctx.body());
    s.max_stretch = std::max(s.max_stretch, a.stretch.max);
    p99s.push_back(a.stretch.p99);
    s.proxy_inside += a.proxy_inside;
    s.openings = a.openings.tracked;
    s.openings_off_frames += a.openings.off > 0 ? 1 : 0;
    s.penetration_p99_max_mm = std::max(s.penetration_p99_max_mm, a.body_penetration_p99_mm);
    s.penetration_max_mm = std::max(s.penetration_max_mm, a.body_penetration_max_mm);
    s.max_speed = std::max(s.max_speed, maxSpeed(garment.velocities(), garment.particleCount()));
    for (size_t p = 0; p < garment.particleCount(); ++p) s.finite = s.finite && garment.positions()[p].allFinite();
    s.nan_resets += garment.lastStep().nan_reset ? 1 : 0;
    s.teleport_resets += garment.lastStep().teleport_reset ? 1 : 0;
    ms.push_back(garment.lastStep().total_ms);
    if (per_frame) per_frame(static_cast<int>(i));
    ++s.frames;
  }
  std::sort(p99s.begin(), p99s.end());
  std::sort(ms.begin(), ms.end());
  if (!p99s.empty()) {
    s.p99_stretch_worst = p99s.back();
    s.p99_stretch_median = p99s[p99s.size() / 2];
    s.p99_stretch_p90 = p99s[p99s.size() * 9 / 10];
    s.step_ms_median = ms[ms.size() / 2];
  }
  return s;
}

}  // namespace drape::test
