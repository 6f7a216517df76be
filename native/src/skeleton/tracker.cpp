#include "skeleton/tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace drape {
namespace {

constexpr float kNominalDt = 1.0f / 30.0f;   // the Kinect frame period the Holt constants are for
constexpr float kMinFilterDt = 1e-4f;        // smaller dt is treated as this inside the filters
constexpr float kDegenerateM = 1e-4f;        // bones shorter than this have no usable direction
constexpr float kMinLengthSampleM = 1e-3f;   // calibration ignores (near) zero-length samples
constexpr float kCollapsedBoneFraction = 0.25f;  // calibrated: a shorter raw bone's far joint is not tracked
constexpr int kCollapsedBonePushes = 2;          // ... from the second push in a row that reads it so
constexpr int kMaxCalibSamples = 256;        // stored samples per bone and class
constexpr int kMaxFrameCount = 1 << 20;      // saturating per-filter sample counter

float finiteOr(float v, float fallback) { return std::isfinite(v) ? v : fallback; }

TrackerParams sanitize(const TrackerParams& in) {
  const TrackerParams d;
  TrackerParams p = in;
  const int f = static_cast<int>(in.filter);
  if (f < 0 || f > 2) p.filter = d.filter;
  p.min_cutoff_hz = finiteOr(in.min_cutoff_hz, d.min_cutoff_hz);
  if (!(p.min_cutoff_hz > 0.0f)) p.min_cutoff_hz = d.min_cutoff_hz;
  p.min_cutoff_hz = std::min(p.min_cutoff_hz, 1000.0f);
  p.beta = std::clamp(finiteOr(in.beta, d.beta), 0.0f, 1000.0f);
  p.d_cutoff_hz = finiteOr(in.d_cutoff_hz, d.d_cutoff_hz);
  if (!(p.d_cutoff_hz > 0.0f)) p.d_cutoff_hz = d.d_cutoff_hz;
  p.d_cutoff_hz = std::min(p.d_cutoff_hz, 1000.0f);
  p.smoothing = std::clamp(finiteOr(in.smoothing, d.smoothing), 0.0f, 0.999f);
  p.correction = std::clamp(finiteOr(in.correction, d.correction), 0.0f, 1.0f);
  p.prediction = std::clamp(finiteOr(in.prediction, d.prediction), 0.0f, 10.0f);
  p.jitter_radius_m = std::clamp(finiteOr(in.jitter_radius_m, d.jitter_radius_m), 0.0f, 10.0f);
  p.max_deviation_m = std::clamp(finiteOr(in.max_deviation_m, d.max_deviation_m), 0.0f, 10.0f);
  p.calibration_frames = std::max(in.calibration_frames, 0);
  p.teleport_distance_m = finiteOr(in.teleport_distance_m, d.teleport_distance_m);
  if (!(p.teleport_distance_m > 0.0f)) p.teleport_distance_m = d.teleport_distance_m;
  p.max_not_tracked_hold_s =
      std::clamp(finiteOr(in.max_not_tracked_hold_s, d.max_not_tracked_hold_s), 0.0f, 1e6f);
  return p;
}

// One-Euro smoothing factor for a first-order low-pass at `cutoff_hz` sampled every dt.
float alphaFor(float cutoff_hz, float dt) {
  const float r = 2.0f * kPi * cutoff_hz * dt;
  return r / (1.0f + r);
}

// Rotates `a` toward `b` (unit vectors) by fraction w of the angle between them.
Vec3 slerpDir(const Vec3& a, const Vec3& b, float w) {
  if (w >= 1.0f) return b;
  const Quat q = rotationBetween(a, b);
  const Vec3 r = Quat::Identity().slerp(w, q) * a;
  const float n = r.norm();
  return (n > 1e-6f && std::isfinite(n)) ? Vec3(r / n) : b;
}

}  // namespace

SkeletonTracker::SkeletonTracker(const TrackerParams& p) : p_(sanitize(p)) {
  const int n = p_.calibration_frames;
  calib_cap_ = std::max(1, std::min(n, kMaxCalibSamples));
  calib_stride_ = n > calib_cap_ ? (n + calib_cap_ - 1) / calib_cap_ : 1;
  const size_t total = static_cast<size_t>(kBoneCount) * static_cast<size_t>(calib_cap_);
  calib_tracked_.assign(total, 0.0f);
  calib_inferred_.assign(total, 0.0f);
  scratch_.assign(static_cast<size_t>(calib_cap_), 0.0f);
  reset();
}

void SkeletonTracker::reset() {
  n_tracked_.fill(0);
  n_inferred_.fill(0);
  frozen_.fill(false);
  pushes_ = 0;
  calibrated_ = false;
  filt_.fill(JointFilter{});
  est_.fill(Vec3::Zero());
  dir_.fill(Vec3::UnitY());
  len_.fill(0.0f);
  lost_.fill(false);
  collapsed_run_.fill(0);
  lost_since_.fill(0.0);
  blend_end_.fill(-std::numeric_limits<double>::infinity());
  pose_ = SkeletonPose{};
  pose_.position.fill(Vec3::Zero());
  pose_.state.fill(TrackingState::NotTracked);
  has_pose_ = false;
  last_t_ = 0.0;
  have_pelvis_ = false;
  last_pelvis_ = Vec3::Zero();
  last_pelvis_t_ = 0.0;
  noise_seen_.fill(0);
  noise_dt1_ = 0.0f;
  noise_var_ = 0.0f;
  have_torso_ = false;
  limb_dir_.fill(Vec3::Zero());
  pose_jumped_ = false;
  pose_jumps_ = 0;
  teleported_ = false;
  teleports_ = 0;
}

const SkeletonPose& SkeletonTracker::pose() const { return pose_; }
bool SkeletonTracker::hasPose() const { return has_pose_; }
bool SkeletonTracker::calibrated() const { return calibrated_; }
const std::array<float, kBoneCount>& SkeletonTracker::boneLengths() const { return len_; }
bool SkeletonTracker::teleportedLastPush() const { return teleported_; }
uint32_t SkeletonTracker::teleportCount() const { return teleports_; }
const TrackerParams& SkeletonTracker::params() const { return p_; }

float SkeletonTracker::medianOf(const float* v, int n) {
  float* s = scratch_.data();
  std::copy(v, v + n, s);
  const int mid = n / 2;
  std::nth_element(s, s + mid, s + n);
  const float upper = s[mid];
  if (n % 2 == 1) return upper;
  const float lower = *std::max_element(s, s + mid);
  return 0.5f * (lower + upper);
}

Vec3 SkeletonTracker::filterJoint(int j, const Vec3& x, bool inferred, float dt) {
  JointFilter& f = filt_[j];
  const bool first = f.frames == 0;
  f.frames = std::min(f.frames + 1, kMaxFrameCount);
  if (p_.filter == FilterKind::None || first) {
    f.x = x;
    f.dx = Vec3::Zero();
    f.raw = x;
    return x;
  }
  const float h = std::max(dt, kMinFilterDt);
  if (p_.filter == FilterKind::OneEuro) {
    const float cutoffScale = inferred ? kInferredCutoffScale : 1.0f;
    const float betaScale = inferred ? kInferredBetaScale : 1.0f;
    const Vec3 v = (x - f.raw) / h;
    f.dx += alphaFor(p_.d_cutoff_hz, h) * (v - f.dx);
    const float cutoff = cutoffScale * p_.min_cutoff_hz + betaScale * effectiveBeta() * f.dx.norm();
    f.x += alphaFor(cutoff, h) * (x - f.x);
    f.raw = x;
    return f.x;
  }
  // Kinect SDK double exponential (Holt) filter. The SDK runs once per 30 Hz frame; for another dt
  // the per-frame constants are re-scaled so that they act over the same time: k = dt / (1/30),
  // smoothing^k, 1 - (1 - correction)^k, and the trend is kept in metres per 30 Hz frame.
  const float k = holt_k_, s = holt_s_, c = holt_c_;
  const float radiusScale = inferred ? kInferredRadiusScale : 1.0f;
  const float jitter = p_.jitter_radius_m * radiusScale;
  const float maxDev = p_.max_deviation_m * radiusScale;
  const Vec3 prevFiltered = f.x;
  Vec3 filtered;
  if (f.frames == 2) {
    filtered = 0.5f * (x + f.raw);
  } else {
    // Jitter: a move inside the radius is scaled down by its own size.
    const float d = (x - prevFiltered).norm();
    const Vec3 dejittered = (d <= jitter && jitter > 0.0f) ? Vec3(prevFiltered + (x - prevFiltered) * (d / jitter)) : x;
    filtered = (1.0f - s) * dejittered + s * (prevFiltered + f.dx * k);
  }
  f.dx = c * (filtered - prevFiltered) / k + (1.0f - c) * f.dx;
  f.x = filtered;
  f.raw = x;
  Vec3 predicted = filtered + f.dx * p_.prediction;
  const float dev = (predicted - x).norm();
  if (dev > maxDev) predicted = x + (predicted - x) * (maxDev / dev);
  return predicted;
}

float SkeletonTracker::noiseSigmaM() const { return std::sqrt(noise_var_); }

float SkeletonTracker::effectiveBeta() const {
  return p_.beta / (1.0f + noise_var_ / (kNoiseReferenceM * kNoiseReferenceM));
}

bool SkeletonTracker::poseJumpedLastPush() const { return pose_jumped_; }
uint32_t SkeletonTracker::poseJumpCount() const { return pose_jumps_; }

bool SkeletonTracker::rawTorsoFrame(const SkeletonPose& raw, const std::array<TrackingState, kJointCount>& st,
                                    Mat3& out) const {
  const int pelvis = idx(Joint::Pelvis), chest = idx(Joint::SpineShoulder);
  const int hl = idx(Joint::HipL), hr = idx(Joint::HipR);
  const int sl = idx(Joint::ShoulderL), sr = idx(Joint::ShoulderR);
  for (int j : {pelvis, chest, hl, hr, sl, sr})
    if (st[j] != TrackingState::Tracked) return false;
  // Hips and shoulders together: a baseline of ~0.6 m, so centimetres of sensor noise turn it by
  // a few degrees only.
  const Vec3 up = raw.position[chest] - raw.position[pelvis];
  const Vec3 side = raw.position[hr] - raw.position[hl] + raw.position[sr] - raw.position[sl];
  if (!(up.norm() > 0.05f) || !(side.norm() > 0.02f)) return false;
  const Vec3 y = up.normalized();
  const Vec3 z = side.cross(y);
  if (!(z.norm() > 1e-3f * side.norm())) return false;  // hips along the spine: no frame
  out.col(1) = y;
  out.col(2) = z.normalized();
  out.col(0) = y.cross(out.col(2));
  return out.allFinite();
}

namespace {
constexpr float kNoiseJumpFactor = 4.0f;
constexpr float kNoiseFloorM = 0.03f;
}  // namespace

void SkeletonTracker::estimateNoise(const SkeletonPose& raw, const std::array<TrackingState, kJointCount>& st,
                                    float dt) {
  static constexpr std::array<Joint, kNoiseJoints> kTorso = {Joint::Pelvis, Joint::SpineMid, Joint::SpineShoulder,
                                                            Joint::ShoulderL, Joint::ShoulderR, Joint::HipL,
                                                            Joint::HipR};
  // Each joint's deviation from the straight line through its two previous samples,
  // e = x - x1 - (x1 - x2) r with r = dt / dt1. For white noise of variance s^2 per coordinate,
  // E|e|^2 = 3 s^2 (1 + (1 + r)^2 + r^2). The median over the torso joints is one sample; an
  // exponential average over kNoiseTimeConstantS smooths them.
  std::array<float, kNoiseJoints> v{};
  int n = 0;
  const float r = noise_dt1_ > 0.0f ? std::clamp(dt / noise_dt1_, 0.1f, 10.0f) : 1.0f;
  for (int k = 0; k < kNoiseJoints; ++k) {
    const int j = idx(kTorso[static_cast<size_t>(k)]);
    if (st[j] != TrackingState::Tracked) {
      noise_seen_[static_cast<size_t>(k)] = 0;
      continue;
    }
    const Vec3& x = raw.position[j];
    const size_t kk = static_cast<size_t>(k);
    if (noise_seen_[kk] >= 2) {
      const Vec3 e = x - noise_x1_[kk] - (noise_x1_[kk] - noise_x2_[kk]) * r;
      v[static_cast<size_t>(n++)] = e.squaredNorm() / (3.0f * (1.0f + (1.0f + r) * (1.0f + r) + r * r));
    }
    noise_x2_[kk] = noise_x1_[kk];
    noise_x1_[kk] = x;
    noise_seen_[kk] = std::min(noise_seen_[kk] + 1, 2);
  }
  noise_dt1_ = dt;
  if (n == 0) return;
  std::nth_element(v.begin(), v.begin() + n / 2, v.begin() + n);
  // A jump (a skeleton flipped for a frame, a joint snapping to another place) is no noise: one
  // sample may raise the estimate only so far (kNoiseJumpFactor times it, or (kNoiseFloorM)^2).
  const float cap = std::max(kNoiseJumpFactor * noise_var_, kNoiseFloorM * kNoiseFloorM);
  const float sample = std::min(v[static_cast<size_t>(n / 2)], cap);
  if (!std::isfinite(sample)) return;
  const float a = 1.0f - std::exp(-std::max(dt, kMinFilterDt) / kNoiseTimeConstantS);
  noise_var_ += a * (sample - noise_var_);
}

void SkeletonTracker::collectCalibration(const SkeletonPose& raw) {
  const int window = p_.calibration_frames;
  const bool inWindow = pushes_ < window;
  const bool sampleThisPush = !inWindow || (pushes_ % calib_stride_) == 0;
  if (!sampleThisPush) return;
  for (int b = 0; b < kBoneCount; ++b) {
    if (frozen_[b]) continue;
    const int c = boneChild(b), pa = boneParent(b);
    const TrackingState sc = sanitizeState(raw.state[c]), sp = sanitizeState(raw.state[pa]);
    const float l = (raw.position[c] - raw.position[pa]).norm();
    if (!(l >= kMinLengthSampleM) || !std::isfinite(l)) continue;
    const size_t base = static_cast<size_t>(b) * static_cast<size_t>(calib_cap_);
    if (sc == TrackingState::Tracked && sp == TrackingState::Tracked) {
      if (n_tracked_[b] < calib_cap_) calib_tracked_[base + static_cast<size_t>(n_tracked_[b]++)] = l;
    } else if (sc != TrackingState::NotTracked && sp != TrackingState::NotTracked) {
      if (n_inferred_[b] < calib_cap_) calib_inferred_[base + static_cast<size_t>(n_inferred_[b]++)] = l;
    }
  }
}

void SkeletonTracker::updateLengths(const SkeletonPose& raw) {
  const bool windowDone = pushes_ >= p_.calibration_frames;  // pushes_ already counts this push
  if (windowDone && !calibrated_) {
    calibrated_ = true;
    ++calibrations_;
  }
  const int lateTarget = std::max(1, std::min(p_.calibration_frames, calib_cap_));
  for (int b = 0; b < kBoneCount; ++b) {
    if (frozen_[b]) continue;
    const int nt = n_tracked_[b], ni = n_inferred_[b];
    // Bones seen during the window freeze with it; a bone never seen (both ends at least
    // Inferred) by then keeps learning and freezes once it has its own window of samples.
    const bool freeze = windowDone && (nt + ni > 0) &&
                        (pushes_ == std::max(p_.calibration_frames, 1) || nt + ni >= lateTarget);
    const size_t base = static_cast<size_t>(b) * static_cast<size_t>(calib_cap_);
    // The running median is refreshed every push while small, then every 8th sample (cost).
    const int n = nt > 0 ? nt : ni;
    const bool refresh = freeze || n <= 32 || n % 8 == 0;
    if (nt > 0) {
      if (refresh) len_[b] = medianOf(&calib_tracked_[base], nt);
    } else if (ni > 0) {
      if (refresh) len_[b] = medianOf(&calib_inferred_[base], ni);
    } else {
      const float l = (raw.position[boneChild(b)] - raw.position[boneParent(b)]).norm();
      len_[b] = std::isfinite(l) ? l : 0.0f;
    }
    if (freeze) frozen_[b] = true;
  }
}

void SkeletonTracker::push(const SkeletonPose& raw, double time_s) {
  teleported_ = false;
  double dtd = has_pose_ ? time_s - last_t_ : static_cast<double>(kNominalDt);
  if (!(dtd > 1e-6)) dtd = 1e-6;  // non-increasing or NaN time: a tiny step, never a division by 0
  const double t = has_pose_ ? last_t_ + dtd : (std::isfinite(time_s) ? time_s : 0.0);
  const float dt = static_cast<float>(std::min(dtd, 1e6));
  if (p_.filter == FilterKind::DoubleExponential) {
    holt_k_ = std::clamp(std::max(dt, kMinFilterDt) / kNominalDt, 0.01f, 30.0f);
    holt_s_ = std::pow(p_.smoothing, holt_k_);
    holt_c_ = 1.0f - std::pow(1.0f - p_.correction, holt_k_);
  }
  bool restart = has_pose_ && dtd > static_cast<double>(kMaxFilterGapS);

  std::array<TrackingState, kJointCount> st;
  for (int j = 0; j < kJointCount; ++j) st[j] = sanitizeState(raw.state[j]);
  // Once the bone lengths are calibrated, a reported bone shorter than a quarter of its length is
  // no reading of a person (a sensor collapsing joints onto each other): its far joint counts as
  // not tracked, held like a lost joint instead of folding the body. From the second push in a row:
  // 2 cm of jitter shortens a 5-9 cm bone (hand, neck, hip) that much on a frame now and then, and
  // a joint coming back restarts its filter unsmoothed (StressJitter under the sanitizers failed
  // when it acted at once). Holding only the long bones at once, or a collapsed joint at its last
  // estimate for one push, both failed StressBones (a half-held or a re-folded skeleton).
  for (int j = 1; j < kJointCount; ++j) {
    const float l = len_[static_cast<size_t>(j - 1)];
    const bool collapsed = calibrated_ && st[j] != TrackingState::NotTracked && l > 0.0f &&
                           (raw.position[j] - raw.position[kJointParent[j]]).norm() < kCollapsedBoneFraction * l;
    int& run = collapsed_run_[static_cast<size_t>(j)];
    run = collapsed ? run + 1 : 0;
    if (run >= kCollapsedBonePushes) st[j] = TrackingState::NotTracked;
  }

  // Teleport: the raw pelvis moved further than the person plausibly could since it was last seen.
  if (st[0] != TrackingState::NotTracked) {
    const Vec3& pelvis = raw.position[0];
    if (have_pelvis_) {
      const double gap = std::clamp(t - last_pelvis_t_, 0.0, static_cast<double>(kMaxFilterGapS));
      const float allowed = p_.teleport_distance_m + kTeleportMaxSpeedMps * static_cast<float>(gap);
      if ((pelvis - last_pelvis_).norm() > allowed) {
        teleported_ = true;
        ++teleports_;
        restart = true;
        blend_end_[0] = -std::numeric_limits<double>::infinity();  // land at the new place now
      }
    }
    have_pelvis_ = true;
    last_pelvis_ = pelvis;
    last_pelvis_t_ = t;
  }
  // Pose jump: the raw torso turned farther since the last push than a person turns in dt (a
  // skeleton flipped upside down, front and back swapped). Like a teleport, the filters restart
  // so the output lands on the new pose at once instead of sweeping through the poses between.
  pose_jumped_ = false;
  Mat3 torso;
  if (rawTorsoFrame(raw, st, torso)) {
    const float gap =
        have_torso_ ? static_cast<float>(std::clamp(t - last_torso_t_, 0.0, static_cast<double>(kMaxFilterGapS))) : 0.0f;
    if (have_torso_) {
      const Mat3 R = torso * last_torso_.transpose();
      const float c = std::clamp(0.5f * (R.trace() - 1.0f), -1.0f, 1.0f);
      if (std::acos(c) > kPoseJumpRad + kMaxTurnRadPerS * gap) {
        pose_jumped_ = true;
        ++pose_jumps_;
        restart = true;
      }
    }
    // Limb bones: their directions in the torso's frame (which takes the body's own turning out).
    // Not on a noisy sensor (the estimate of the frames so far above kNoiseReferenceM): 5 cm of
    // jitter at both ends of a 25 cm forearm turns it that far now and then.
    const bool quiet = noise_var_ < kNoiseReferenceM * kNoiseReferenceM;
    bool limb_jumped = false;
    for (const Joint child : {Joint::ElbowL, Joint::WristL, Joint::ElbowR, Joint::WristR, Joint::KneeL, Joint::AnkleL,
                              Joint::KneeR, Joint::AnkleR}) {
      const int b = idx(child) - 1;  // the bone ending at `child`
      const int pa = boneParent(b);
      const Vec3 d = torso.transpose() * (raw.position[idx(child)] - raw.position[pa]);
      Vec3& last = limb_dir_[static_cast<size_t>(b)];
      if (st[pa] != TrackingState::Tracked || st[idx(child)] != TrackingState::Tracked || !(d.norm() > 1e-3f)) {
        last = Vec3::Zero();  // not compared across an untracked frame
        continue;
      }
      const Vec3 u = d.normalized();
      if (quiet && have_torso_ && last.squaredNorm() > 0.5f &&
          std::acos(std::clamp(u.dot(last), -1.0f, 1.0f)) > kPoseJumpRad + kMaxTurnRadPerS * gap)
        limb_jumped = true;
      last = u;
    }
    if (limb_jumped && !pose_jumped_) {
      pose_jumped_ = true;
      ++pose_jumps_;
      restart = true;
    }
    have_torso_ = true;
    last_torso_ = torso;
    last_torso_t_ = t;
  }
  if (restart) {
    for (JointFilter& f : filt_) f.frames = 0;
    noise_seen_.fill(0);  // the noise estimate skips the jump (no straight line spans it)
  }
  estimateNoise(raw, st, dt);

  collectCalibration(raw);
  if (pushes_ < std::numeric_limits<int>::max()) ++pushes_;
  updateLengths(raw);

  const std::array<Vec3, kBoneCount> prevDir = dir_;
  const float hold = p_.max_not_tracked_hold_s;

  // Root.
  if (st[0] != TrackingState::NotTracked) {
    if (lost_[0]) {
      lost_[0] = false;
      filt_[0].frames = 0;
      if (has_pose_ && !teleported_) blend_end_[0] = t + static_cast<double>(kRecoverBlendS);
    }
    const Vec3 f = filterJoint(0, raw.position[0], st[0] == TrackingState::Inferred, dt);
    if (has_pose_ && t < blend_end_[0]) {
      const float a = static_cast<float>(dtd / (blend_end_[0] - t + dtd));
      est_[0] = pose_.position[0] + (f - pose_.position[0]) * a;
    } else {
      est_[0] = f;
    }
    pose_.state[0] = st[0];
  } else {
    if (!lost_[0]) {
      lost_[0] = true;
      lost_since_[0] = has_pose_ ? t : -std::numeric_limits<double>::infinity();
    }
    if (!has_pose_) est_[0] = raw.position[0];  // nothing better known; otherwise held
    pose_.state[0] = (t - lost_since_[0] <= static_cast<double>(hold)) ? TrackingState::Inferred
                                                                        : TrackingState::NotTracked;
  }
  pose_.position[0] = est_[0];

  // Bones, top-down: direction from the filtered estimates, length from calibration.
  for (int j = 1; j < kJointCount; ++j) {
    const int b = j - 1;
    const int pa = kJointParent[j];
    const int pb = pa - 1;  // parent's bone (-1 for the pelvis)
    // Direction to use when there is none: the previous one, else the parent bone's.
    const Vec3 fallback = has_pose_ ? prevDir[b] : (pb >= 0 ? dir_[pb] : Vec3::UnitY());
    Vec3 d;
    if (st[j] != TrackingState::NotTracked) {
      if (lost_[j]) {
        lost_[j] = false;
        filt_[j].frames = 0;
        if (has_pose_) blend_end_[j] = t + static_cast<double>(kRecoverBlendS);
      }
      est_[j] = filterJoint(j, raw.position[j], st[j] == TrackingState::Inferred, dt);
      // A degenerate raw bone (child at parent) carries no direction: keep the previous one
      // (checked on the raw sample too, so a filter overshooting through the parent cannot flip it).
      const Vec3 live = est_[j] - est_[pa];
      const float ln = live.norm();
      const float rawLen = (raw.position[j] - raw.position[pa]).norm();
      const bool degenerate = !(ln > kDegenerateM && std::isfinite(ln)) ||
                              (st[pa] != TrackingState::NotTracked && !(rawLen > kDegenerateM));
      const Vec3 liveDir = degenerate ? fallback : Vec3(live / ln);
      if (has_pose_ && t < blend_end_[j]) {
        // Recovering: move the remaining angle between the held and the live direction linearly
        // in time, reaching the live direction at blend_end_.
        const Vec3 held = pb >= 0 ? Vec3(rotationBetween(prevDir[pb], dir_[pb]) * prevDir[b])
                                  : prevDir[b];
        const float a = static_cast<float>(dtd / (blend_end_[j] - t + dtd));
        d = slerpDir(held, liveDir, a);
      } else {
        d = liveDir;
      }
      pose_.state[j] = st[j];
    } else {
      if (!lost_[j]) {
        lost_[j] = true;
        lost_since_[j] = has_pose_ ? t : -std::numeric_limits<double>::infinity();
      }
      if (has_pose_) {
        // Hold the angle to the parent bone: turn the previous direction with the parent's swing.
        d = pb >= 0 ? Vec3(rotationBetween(prevDir[pb], dir_[pb]) * prevDir[b]) : prevDir[b];
        const float n = d.norm();
        d = (n > 1e-6f && std::isfinite(n)) ? Vec3(d / n) : fallback;
      } else {
        const Vec3 r = raw.position[j] - raw.position[pa];
        const float n = r.norm();
        d = (n > kDegenerateM && std::isfinite(n)) ? Vec3(r / n) : fallback;
      }
      est_[j] = est_[pa] + d * len_[b];  // virtual estimate for the children's directions
      pose_.state[j] = (t - lost_since_[j] <= static_cast<double>(hold)) ? TrackingState::Inferred
                                                                          : TrackingState::NotTracked;
    }
    dir_[b] = d;
    pose_.position[j] = pose_.position[pa] + d * len_[b];
  }

  has_pose_ = true;
  last_t_ = t;
}

}  // namespace drape
