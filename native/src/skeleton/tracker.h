// Per-frame skeleton conditioning: smoothing, steady bone lengths, lost-joint reconstruction and
// teleport detection. Design and measured defaults: docs/skeleton.md, section "Tracker".
#pragma once

#include "skeleton/joints.h"

#include <array>
#include <cstdint>
#include <vector>

namespace drape {

enum class FilterKind : int { None = 0, OneEuro = 1, DoubleExponential = 2 };  // values become ABI-visible

struct TrackerParams {
  FilterKind filter = FilterKind::OneEuro;
  // One-Euro (Casiez et al., CHI 2012): cutoff = min_cutoff_hz + beta * speed (m/s). Defaults
  // chosen by measurement on the Kinect v2 recordings (docs/skeleton.md, "Choosing the defaults").
  float min_cutoff_hz = 0.5f, beta = 6.0f, d_cutoff_hz = 1.0f;
  // Kinect SDK Holt double exponential (NUI_TRANSFORM_SMOOTH_PARAMETERS semantics; `prediction`
  // in 30 Hz frames; the per-frame constants are re-scaled for the actual dt).
  float smoothing = 0.5f, correction = 0.5f, prediction = 0.5f, jitter_radius_m = 0.05f,
        max_deviation_m = 0.04f;
  int calibration_frames = 30;       // bone lengths = median over the first N pushes (see docs)
  float teleport_distance_m = 0.5f;  // raw pelvis jump beyond this + kTeleportMaxSpeedMps * dt
  float max_not_tracked_hold_s = 1.0f;  // a lost joint is reported Inferred this long, then NotTracked
};

// Fastest plausible whole-body (pelvis) speed: a jump between two pelvis observations dt apart
// counts as a teleport only beyond teleport_distance_m + kTeleportMaxSpeedMps * min(dt, kMaxFilterGapS).
constexpr float kTeleportMaxSpeedMps = 5.0f;
// A gap between pushes longer than this restarts the smoothing filters (stale velocity/trend).
constexpr float kMaxFilterGapS = 0.5f;
// A joint coming back after being NotTracked moves from its held direction to the live one over
// this long (linear in time), so it never jumps.
constexpr float kRecoverBlendS = 0.2f;
// Inferred joints are smoothed harder (their jumps are the sensor's guesses, not motion): the
// One-Euro min cutoff is multiplied by kInferredCutoffScale and beta by kInferredBetaScale ...
constexpr float kInferredCutoffScale = 0.5f;
constexpr float kInferredBetaScale = 0.1f;
// ... and the double exponential jitter radius / max deviation are multiplied by this (as the
// Kinect SDK's own sample filter does).
constexpr float kInferredRadiusScale = 2.0f;
// Sensor noise: estimated from the torso joints (which never accelerate much, so what their
// positions do beyond a straight line is noise) over kNoiseTimeConstantS. The One-Euro beta is
// divided by 1 + (noise / kNoiseReferenceM)^2: on a noisy sensor the filter stops chasing what its
// derivative estimate calls speed but is noise (docs/skeleton.md, "Sensor noise").
constexpr float kNoiseTimeConstantS = 0.5f;
// A raw torso (pelvis, spine-shoulder, hips, shoulders) turning beyond kPoseJumpRad +
// kMaxTurnRadPerS * dt between two pushes is a pose jump: no person turns that fast (a pirouette
// is ~2 turns a second); 90 degrees on top keeps 5 cm of sensor noise from looking like one.
// The same for a limb bone (upper arm, forearm, thigh, shin) whose two joints the sensor tracks:
// its direction in the raw torso frame turning beyond that between two pushes (a thigh reported
// pointing up, knees above the hips, from one frame to the next). Inferred joints are left out:
// the close-range take's guessed legs turn 81-137 degrees from one frame to the next six times
// (docs/skeleton.md, "Pose jumps"); tracked ones on the shared takes never beyond 57. So is a
// noisy sensor (noise estimate above kNoiseReferenceM: heavy jitter turns a forearm that far).
constexpr float kPoseJumpRad = 1.5708f;
constexpr float kMaxTurnRadPerS = 12.566f;
constexpr float kNoiseReferenceM = 0.015f;

class SkeletonTracker {
 public:
  explicit SkeletonTracker(const TrackerParams& p = {});
  void reset();  // forget everything (calibration included)
  // Push one canonical pose (already validated: all positions finite) at time t (strictly
  // increasing; the caller checks - a non-increasing t is treated as a tiny positive dt).
  void push(const SkeletonPose& raw, double time_s);
  const SkeletonPose& pose() const;  // filtered pose with held bone lengths; states as reported (after reconstruction: Inferred)
  bool hasPose() const;              // false until the first push
  bool calibrated() const;           // bone lengths frozen
  // Calibrations completed since construction (reset() starts a new one; the count goes on), so a
  // caller can tell a new set of frozen lengths from the one it has seen.
  uint32_t calibrationCount() const { return calibrations_; }
  const std::array<float, kBoneCount>& boneLengths() const;  // current (calibrating: running estimate) lengths
  bool teleportedLastPush() const;
  // The last push's raw torso, or a tracked limb bone in the torso's frame, turned farther than a
  // person can in its dt (filters restarted).
  bool poseJumpedLastPush() const;
  uint32_t poseJumpCount() const;
  // Estimated sensor noise (standard deviation per coordinate, metres) and the One-Euro beta in
  // use because of it.
  float noiseSigmaM() const;
  float effectiveBeta() const;
  uint32_t teleportCount() const;
  const TrackerParams& params() const;  // as used: out-of-range values replaced (docs/skeleton.md)

 private:
  struct JointFilter {
    Vec3 x = Vec3::Zero();      // filtered position (One-Euro) / filtered, un-predicted (Holt)
    Vec3 dx = Vec3::Zero();     // One-Euro: filtered velocity (m/s); Holt: trend (m per 30 Hz frame)
    Vec3 raw = Vec3::Zero();    // previous raw sample
    int frames = 0;             // samples since the filter (re)started; 0 = uninitialised
  };

  Vec3 filterJoint(int j, const Vec3& x, bool inferred, float dt);
  void collectCalibration(const SkeletonPose& raw);
  // Frame of the raw torso (columns: right, up, forward-ish); false when a joint is not tracked.
  bool rawTorsoFrame(const SkeletonPose& raw, const std::array<TrackingState, kJointCount>& st, Mat3& out) const;
  void estimateNoise(const SkeletonPose& raw, const std::array<TrackingState, kJointCount>& st, float dt);
  void updateLengths(const SkeletonPose& raw);
  float medianOf(const float* v, int n);

  TrackerParams p_;
  float holt_k_ = 1.0f, holt_s_ = 0.5f, holt_c_ = 0.5f;  // per-push Holt constants for this dt
  int calib_cap_ = 0;     // stored samples per bone per class
  int calib_stride_ = 1;  // keep one push in `stride` when calibration_frames > capacity
  std::vector<float> calib_tracked_, calib_inferred_, scratch_;  // allocated once (constructor)
  std::array<int, kBoneCount> n_tracked_{}, n_inferred_{};
  std::array<bool, kBoneCount> frozen_{};
  int pushes_ = 0;
  bool calibrated_ = false;
  uint32_t calibrations_ = 0;

  std::array<JointFilter, kJointCount> filt_{};
  std::array<Vec3, kJointCount> est_{};       // filtered positions in raw space (lost: virtual)
  std::array<Vec3, kBoneCount> dir_{};        // output bone directions (unit)
  std::array<float, kBoneCount> len_{};
  std::array<bool, kJointCount> lost_{};
  std::array<int, kJointCount> collapsed_run_{};  // pushes in a row with the joint's bone collapsed
  std::array<double, kJointCount> lost_since_{};
  std::array<double, kJointCount> blend_end_{};  // recovery blend ends at this time (<= now: none)
  Vec3 root_held_ = Vec3::Zero();

  SkeletonPose pose_{};
  bool has_pose_ = false;
  double last_t_ = 0.0;
  bool have_pelvis_ = false;        // a non-NotTracked raw pelvis has been seen
  Vec3 last_pelvis_ = Vec3::Zero();  // last such raw pelvis and its time
  double last_pelvis_t_ = 0.0;
  bool teleported_ = false;
  uint32_t teleports_ = 0;

  // Sensor noise estimate (estimateNoise): the torso joints' last two raw samples.
  static constexpr int kNoiseJoints = 7;
  std::array<Vec3, kNoiseJoints> noise_x1_{}, noise_x2_{};
  std::array<int, kNoiseJoints> noise_seen_{};  // consecutive tracked samples, capped at 2
  float noise_dt1_ = 0.0f;                      // dt between noise_x2_ and noise_x1_
  float noise_var_ = 0.0f;                      // per-coordinate variance, m^2

  // Pose jumps: the raw torso frame of the last push that had one.
  bool have_torso_ = false;
  Mat3 last_torso_ = Mat3::Identity();
  double last_torso_t_ = 0.0;
  std::array<Vec3, kBoneCount> limb_dir_{};  // the last push's tracked limb bones, torso frame (0: none)
  bool pose_jumped_ = false;
  uint32_t pose_jumps_ = 0;
};

}  // namespace drape
