// Recovery from tracking glitches: the garment's state from before a pose jump or a burst of
// sensor noise, kept relative to the pelvis ring and restored when the glitch ends
// (GarmentSim::KeptState, garment_sim.h; docs/robustness.md, "Recovery").
#include "cloth/garment_sim.h"
#include "cloth/garment_solver.h"

#include "proxies/collision.h"

#include <string>

namespace drape {
namespace {

// A glitch that ends within kKeepS is restored; after that the person has moved on.
constexpr double kKeepS = 5.0;
// Restored only when every attachment target is back within this of where it was (RMS, pelvis
// frame): the collar, shoulders and waist of a person who has not bent over or changed.
constexpr float kRestoreMatchM = 0.08f;
// The restored state is swept from the pose it was kept on to the current one in this many
// simulated 1/30 s frames (run at once): the ellipsoids move continuously, so a limb that moved
// during the glitch drags its cloth along instead of landing on it.
constexpr int kCatchUpFrames = 8;
constexpr float kCatchUpFrameS = 1.0f / 30.0f;
// Noise bursts, on the tracker's sensor-noise estimate (SkeletonTracker::noiseSigmaM): a real
// Kinect reads 0.1-3 mm, 2 cm of jitter ~18 mm, 5 cm ~45 mm (docs/skeleton.md). A burst starts
// above kBurstOnM and ends below kBurstOffM; calm states are kept every kCalmEveryS while the
// estimate is below kCalmM. The estimate lags the noise by a few frames (a 0.5 s average), so
// at a burst's start the oldest calm state (0.4-0.6 s old) is the one taken before it.
constexpr float kBurstOnM = 0.030f;
constexpr float kBurstOffM = 0.025f;
constexpr float kCalmM = 0.010f;
constexpr double kCalmEveryS = 0.2;

// Centre and rotation only: a kept ellipsoid is read back through fromFrame, which refreshes it
// (its to_unit, from_unit and bounds here are stale and never read).
Ellipsoid toFrame(const Ellipsoid& e, const Mat3& f_t, const Vec3& c) {
  Ellipsoid out = e;
  out.centre = f_t * (e.centre - c);
  out.rotation = f_t * e.rotation;
  return out;
}

Ellipsoid fromFrame(const Ellipsoid& e, const Mat3& f, const Vec3& c) {
  Ellipsoid out = e;
  out.centre = f * e.centre + c;
  out.rotation = f * e.rotation;
  out.refresh();
  return out;
}

}  // namespace

void GarmentSim::keepState(KeptState& k, const std::vector<Ellipsoid>& ellipsoids, const RingPose& pelvis,
                           const std::vector<Vec3>& pins) const {
  const Mat3 to_local = pelvis.frame.transpose();
  const Eigen::Vector4f* x = solver_->x();
  k.x.resize(particleCount());
  for (size_t i = 0; i < k.x.size(); ++i) k.x[i] = to_local * (x[i].head<3>() - pelvis.centre);
  k.pins.resize(pins.size());
  for (size_t i = 0; i < pins.size(); ++i) k.pins[i] = to_local * (pins[i] - pelvis.centre);
  k.ellipsoids.resize(ellipsoids.size());
  for (size_t i = 0; i < ellipsoids.size(); ++i) k.ellipsoids[i] = toFrame(ellipsoids[i], to_local, pelvis.centre);
  k.shoulders = shoulders_;
  k.time_s = sim_time_s_;
  k.valid = true;
}

void GarmentSim::keepBeforeJump(const std::vector<Ellipsoid>& start) {
  if (before_jump_.valid && sim_time_s_ - before_jump_.time_s < kKeepS) return;
  RingPose seen;
  seen.centre = seen_pelvis_c_;
  seen.frame = seen_pelvis_f_;
  keepState(before_jump_, start, seen, pins_);  // pins_ still holds the last step's targets
}

bool GarmentSim::restoreState(KeptState& k, const BodyModel& body, const RingPose& pelvis,
                              const std::vector<Ellipsoid>& end) {
  if (!k.valid) return false;
  if (sim_time_s_ - k.time_s >= kKeepS || k.x.size() != particleCount() ||
      k.pins.size() != mesh_.pinned.size() || k.pins.empty()) {
    k.valid = false;
    return false;
  }
  pinTargets(body, pins_);
  const Mat3 to_local = pelvis.frame.transpose();
  float sum2 = 0.0f;
  for (size_t i = 0; i < pins_.size(); ++i) sum2 += (to_local * (pins_[i] - pelvis.centre) - k.pins[i]).squaredNorm();
  if (!(sum2 <= kRestoreMatchM * kRestoreMatchM * static_cast<float>(pins_.size()))) return false;

  scratch3_.resize(k.x.size());
  for (size_t i = 0; i < scratch3_.size(); ++i) scratch3_[i] = pelvis.frame * k.x[i] + pelvis.centre;
  std::string err;
  if (!solver_->reset(scratch3_, err)) return false;
  k.valid = false;
  // The shoulders' place comes back with the state: a placement during the glitch restarted it,
  // and measured again on the glitch's or the restore's frames it lifted a dress's armhole off its
  // arm a second later (docs/robustness.md, "The same scenarios on the other garments").
  shoulders_ = k.shoulders;

  // Sweep from the kept pose to this one. The reachable set of ellipsoids may have changed since
  // (proxy culling): then the kept ellipsoids do not pair with the current ones and the garment
  // settles on the current pose instead.
  // The kept ellipsoids and attachment targets carried to the current pelvis (world), once.
  const bool sweep = k.ellipsoids.size() == end.size();
  catch_kept_.resize(sweep ? end.size() : 0);
  for (size_t i = 0; i < catch_kept_.size(); ++i) catch_kept_[i] = fromFrame(k.ellipsoids[i], pelvis.frame, pelvis.centre);
  catch_kept_pins_.resize(pins_.size());
  for (size_t i = 0; i < pins_.size(); ++i) catch_kept_pins_[i] = pelvis.frame * k.pins[i] + pelvis.centre;
  catch_a_.resize(end.size());
  catch_b_.resize(end.size());
  catch_pins_.resize(pins_.size());
  solver_->setRimGate({});  // every rim: the garment as it was, on the body
  for (int f = 0; f < kCatchUpFrames; ++f) {
    const float t0 = static_cast<float>(f) / kCatchUpFrames, t1 = static_cast<float>(f + 1) / kCatchUpFrames;
    for (size_t i = 0; i < end.size(); ++i) {
      catch_a_[i] = sweep ? interpolateEllipsoid(catch_kept_[i], end[i], t0) : end[i];
      catch_b_[i] = sweep ? interpolateEllipsoid(catch_kept_[i], end[i], t1) : end[i];
    }
    for (size_t i = 0; i < pins_.size(); ++i)
      catch_pins_[i] = catch_kept_pins_[i] + t1 * (pins_[i] - catch_kept_pins_[i]);
    runFrame(catch_a_, catch_b_, catch_pins_, kCatchUpFrameS);
  }
  last_.blend_frames = kCatchUpFrames;
  return true;
}

bool GarmentSim::noiseBurstEnded() {
  if (!in_burst_) {
    if (tracking_noise_m_ > kBurstOnM) {
      in_burst_ = true;
      const KeptState* oldest = nullptr;
      for (const KeptState& c : calm_)
        if (c.valid && (!oldest || c.time_s < oldest->time_s)) oldest = &c;
      if (oldest) before_burst_ = *oldest;
      else before_burst_.valid = false;
    }
    return false;
  }
  if (tracking_noise_m_ < kBurstOffM) {
    in_burst_ = false;
    return before_burst_.valid;
  }
  return false;
}

void GarmentSim::keepCalmState(const RingPose& pelvis) {
  if (in_burst_ || !(tracking_noise_m_ < kCalmM) || sim_time_s_ - calm_last_s_ < kCalmEveryS) return;
  if (last_.teleport_reset || last_.nan_reset || !pending_end_) return;
  keepState(calm_[calm_next_], *pending_end_, pelvis, pins_);
  calm_next_ = (calm_next_ + 1) % 3;
  calm_last_s_ = sim_time_s_;
}

}  // namespace drape
