#include "capi/context.h"

#include "body/mesh_metrics.h"
#include "skeleton/layouts.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

namespace drape {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// Garments are cut and dressed on the rest pose with the arms this far below horizontal. A
// Kinect user stands mostly with the arms down (70-80 degrees on the shared takes) and raises
// them now and then; a T-shirt cut at 65 degrees stretched less on all four Kinect takes than one
// cut in the usual 35-degree A-pose (median per-frame P99 stretch 18-34 % against 30-38 %,
// docs/garments.md).
constexpr float kGarmentRestArmDownDeg = 65.0f;

// A person whose rest pose (their bones, their torso) is within this of the one the garments were
// cut on keeps the garments as they are at calibration: a refit re-dresses every garment (a visible
// change, and 29 ms at 1 802 particles, docs/garments.md) for a difference the cloth absorbs anyway.
constexpr float kRefitBelowM = 0.01f;

// Coordinates beyond this are not a person in front of a sensor; rejecting them keeps 1e30-style
// garbage from turning into Inf inside the filters.
constexpr float kMaxCoordinateM = 1000.0f;

}  // namespace

drape_result validateContextDesc(const drape_context_desc& d, std::string& err) {
  std::ostringstream s;
  // Bounds are compared as float, the type the host writes, so an edge like 0.999f is inside.
  auto range = [&](const char* name, float v, float lo, float hi) {
    if (!std::isfinite(v)) {
      s << "context desc: " << name << " is not finite";
      return DRAPE_ERROR_NONFINITE;
    }
    if (v < lo || v > hi) {
      s << "context desc: " << name << " = " << v << " is outside [" << lo << ", " << hi << "]";
      return DRAPE_ERROR_OUT_OF_RANGE;
    }
    return DRAPE_OK;
  };
  drape_result r = DRAPE_OK;
  if (d.ring_points < 8 || d.ring_points > 256 || d.ring_points % 4 != 0) {
    s << "context desc: ring_points = " << d.ring_points << " must be a multiple of 4 in [8, 256]";
    r = DRAPE_ERROR_OUT_OF_RANGE;
  } else if ((r = range("rings_per_segment", static_cast<float>(d.rings_per_segment), 0.0f, 16.0f)) != DRAPE_OK) {
  } else if ((r = range("calibration_frames", static_cast<float>(d.calibration_frames), 1.0f, 100000.0f)) != DRAPE_OK) {
  } else if (d.filter < DRAPE_FILTER_NONE || d.filter > DRAPE_FILTER_DOUBLE_EXPONENTIAL) {
    s << "context desc: filter = " << d.filter << " is not a drape_filter value (0, 1, 2)";
    r = DRAPE_ERROR_OUT_OF_RANGE;
  } else if ((r = range("filter_min_cutoff_hz", d.filter_min_cutoff_hz, 1e-3f, 1000.0f)) != DRAPE_OK) {
  } else if ((r = range("filter_beta", d.filter_beta, 0.0f, 1000.0f)) != DRAPE_OK) {
  } else if ((r = range("filter_d_cutoff_hz", d.filter_d_cutoff_hz, 1e-3f, 1000.0f)) != DRAPE_OK) {
  } else if ((r = range("smoothing", d.smoothing, 0.0f, 0.999f)) != DRAPE_OK) {
  } else if ((r = range("correction", d.correction, 0.0f, 1.0f)) != DRAPE_OK) {
  } else if ((r = range("prediction", d.prediction, 0.0f, 10.0f)) != DRAPE_OK) {
  } else if ((r = range("jitter_radius_m", d.jitter_radius_m, 0.0f, 10.0f)) != DRAPE_OK) {
  } else if ((r = range("max_deviation_m", d.max_deviation_m, 0.0f, 10.0f)) != DRAPE_OK) {
  } else if ((r = range("teleport_distance_m", d.teleport_distance_m, 1e-6f, 100.0f)) != DRAPE_OK) {
  } else if (d.garment_fit != DRAPE_GARMENT_FIT_SKELETON && d.garment_fit != DRAPE_GARMENT_FIT_SHAPE) {
    s << "context desc: garment_fit = " << d.garment_fit << " is not 0 (shape) or 1 (skeleton)";
    r = DRAPE_ERROR_OUT_OF_RANGE;
  } else if (d.proxy_rule != DRAPE_PROXY_RULE_PAPER && d.proxy_rule != DRAPE_PROXY_RULE_DRAPE) {
    s << "context desc: proxy_rule = " << d.proxy_rule << " is not 0 (paper) or 1 (drape)";
    r = DRAPE_ERROR_OUT_OF_RANGE;
  } else if (d.arms_clear_torso != 0 && d.arms_clear_torso != 1) {
    s << "context desc: arms_clear_torso = " << d.arms_clear_torso << " is not 0 or 1";
    r = DRAPE_ERROR_OUT_OF_RANGE;
  } else if ((r = range("arm_torso_clearance_m", d.arm_torso_clearance_m, 0.0f, 0.05f)) != DRAPE_OK) {
  }
  err = s.str();
  return r;
}

TrackerParams trackerParamsFrom(const drape_context_desc& d) {
  TrackerParams p;
  p.filter = static_cast<FilterKind>(d.filter);
  p.min_cutoff_hz = d.filter_min_cutoff_hz;
  p.beta = d.filter_beta;
  p.d_cutoff_hz = d.filter_d_cutoff_hz;
  p.smoothing = d.smoothing;
  p.correction = d.correction;
  p.prediction = d.prediction;
  p.jitter_radius_m = d.jitter_radius_m;
  p.max_deviation_m = d.max_deviation_m;
  p.calibration_frames = static_cast<int>(d.calibration_frames);
  p.teleport_distance_m = d.teleport_distance_m;
  return p;
}

BodyModelParams bodyParamsFrom(const drape_context_desc& d, bool own_arms_clear) {
  BodyModelParams bp;
  bp.ring_points = static_cast<int>(d.ring_points);
  bp.rings_per_segment = static_cast<int>(d.rings_per_segment);
  bp.arms_clear_torso = own_arms_clear && d.arms_clear_torso != 0;
  bp.tracked_arms_clear_torso = d.arms_clear_torso != 0;
  bp.arm_torso_clearance_m = d.arm_torso_clearance_m;
  return bp;
}

Context::Context(const drape_context_desc& desc)
    : desc_(desc),
      shape_(resolveShape(BodyShapeInput{})),
      tracker_(trackerParamsFrom(desc)),
      proxies_(static_cast<ProxyRule>(desc.proxy_rule)) {
  body_ = std::make_unique<BodyModel>(shape_, bodyParamsFrom(desc, true));
  // Size the ellipsoid arrays once (on the rest pose) so updates never allocate.
  proxies_.build(*body_, restPose(shape_));
  orientations_.reserve(32);
}

drape_result Context::setShape(const BodyShapeInput& in, std::string& err) {
  bool nonfinite = false;
  if (!validateShapeInput(in, err, &nonfinite))
    return nonfinite ? DRAPE_ERROR_NONFINITE : DRAPE_ERROR_OUT_OF_RANGE;
  const ResolvedShape before = shape_;
  auto useShape = [this](const ResolvedShape& shape) {
    shape_ = shape;
    body_->setShape(shape_);
    for (RestSlot& r : rest_) r.body.reset();  // rebuilt for the shape when next asked for
  };
  useShape(resolveShape(in));
  // Garments are refitted to the new body (GarmentSim::refitted, docs/garments.md "Body shape
  // changes"): all of them or, when one cannot be dressed on it, none and the old shape back.
  // The same measurements again (a host that sets the shape every frame) change nothing.
  // A recut still dressing (the skeleton's calibration) was for the old shape: this refit covers
  // its garments too, on the skeleton's rest body of the new shape.
  const bool recutting = before.m != shape_.m && !recuts_.empty();
  if (before.m != shape_.m) recuts_.clear();
  if (before.m != shape_.m && !refitGarments(err)) {
    useShape(before);
    if (recutting) restoreFitBefore();  // the skeleton's garments stay on the cut they have
    err += "; the previous shape is kept";
    return DRAPE_ERROR_INVALID_ARGUMENT;
  }
  shapeDirty_ = true;
  volumeDirty_ = true;
  // The body changes under sleeping garments, and the ellipsoids' bounds with the rest body.
  wakeAll();
  proxyBounds_.clear();
  return DRAPE_OK;
}

SkeletonPose Context::garmentRestPose(RestCut cut) const {
  return cut == kCutSkeleton && fit_.on ? restPoseWithBones(shape_, kGarmentRestArmDownDeg, fit_.bones, &fit_.torso)
                                          : restPose(shape_, kGarmentRestArmDownDeg);
}

bool Context::shapeFitsPerson(const std::array<float, kBoneCount>& bones) const {
  return boneScaleAgainstShape(shape_, bones) <= kTrackedBoneScale * kShapeMisfit;
}

void Context::fitGarmentsToSkeleton(bool provisional) {
  // The garments cut for the skeleton so far were cut for other proportions (the shape's standard
  // ones, or a previous calibration's): cut them again for this person, when their rest pose is
  // another. Those cut for the shape while it fits are cut for the skeleton when it does not (and
  // stay so until a shape change decides again). Should one fail to dress on that body, every
  // garment stays as it was, on the previous rest body, until the next calibration.
  const std::array<float, kBoneCount>& bones = tracker_.boneLengths();
  const bool fits = shapeFitsPerson(bones);
  if (provisional && fits && !provisionalFitsFirstPose()) return;  // the calibration cuts them
  const SkeletonPose torso = torsoAverage_.empty() ? tracker_.pose() : torsoAverage_.mean();
  if (!provisional) {
    fittedCalibration_ = tracker_.calibrationCount();
    torsoAverage_.clear();  // the next calibration (a tracker reset) averages its own window
  }
  shapeFits_ = fits;
  const SkeletonPose fitted = restPoseWithBones(shape_, kGarmentRestArmDownDeg, bones, &torso);
  const SkeletonPose current = garmentRestPose(kCutSkeleton);
  float moved = 0.0f;
  for (int j = 0; j < kJointCount; ++j)
    moved = std::max(moved, (fitted.position[static_cast<size_t>(j)] - current.position[static_cast<size_t>(j)]).norm());
  // A garment to cut again: one cut for the skeleton, when this person's proportions are not the
  // ones it was cut for; one cut for a shape that does not fit.
  auto recutsTo = [&](const GarmentCut& c) {
    return (c.cut == kCutSkeleton && moved >= kRefitBelowM) || (c.cut == kCutShape && c.shape_while_it_fits && !fits);
  };
  if (std::none_of(garmentCuts_.begin(), garmentCuts_.end(), recutsTo)) {
    if (moved >= kRefitBelowM) {  // no garment cut for the skeleton yet: those added later are
      fit_ = BoneFit{true, bones, torso};
      rest_[kCutSkeleton].body.reset();
      if (contextCut() == kCutSkeleton) proxyBounds_.clear();
    }
    return;
  }
  // An earlier calibration's recut still dressing is replaced by this one's; the garments are still
  // on the cut before it, so that is the one to go back to.
  if (recuts_.empty()) fitBeforeRecut_ = fit_;
  recuts_.clear();
  fit_ = BoneFit{true, bones, torso};
  rest_[kCutSkeleton].body.reset();
  // The replacements, made now and dressed over the next steps (advanceRecuts): all of them or,
  // when one cannot be made on the new body, none. A garment not yet stepped (not yet placed on
  // the person: the provisional fit at the first pose) is dressed now and swapped in before its
  // first step, so it is never seen in the cut that does not fit.
  std::vector<Recut> now;
  for (size_t i = 0; i < garments_.size(); ++i) {
    if (!recutsTo(garmentCuts_[i])) continue;
    Recut r;
    r.garment = garments_[i].get();
    const bool placed = r.garment->steps() > 0;
    std::string why;
    r.fresh = r.garment->refitted(restBody(kCutSkeleton), restEllipsoids(kCutSkeleton), restEllipsoidGroups(kCutSkeleton),
                                  why, /*remake_template=*/true, placed ? &r.dressing : nullptr);
    if (!r.fresh) {
      recuts_.clear();
      restoreFitBefore();
      return;
    }
    (placed ? recuts_ : now).push_back(std::move(r));
  }
  for (Recut& r : now) {
    swapIn(*r.garment, std::move(*r.fresh));
    if (GarmentCut* c = cutEntry(r.garment)) c->cut = kCutSkeleton;
  }
  // The adaptive pipeline's ellipsoid bounds come from the context's own cut's rest body.
  if (contextCut() == kCutSkeleton) proxyBounds_.clear();
}

bool Context::provisionalFitsFirstPose() const {
  // Only garments that have not been placed on the person yet: recut now, they are never seen in
  // the shape's proportions; one already worn would be recut twice (now and at the calibration),
  // each a jump. And only from a pose whose limbs the sensor sees: a guessed leg (the close-range
  // take's) gave trousers cut too short until the calibration.
  for (size_t i = 0; i < garments_.size(); ++i)
    if (garmentCuts_[i].cut == kCutSkeleton && garments_[i]->steps() > 0) return false;
  const SkeletonPose& p = tracker_.pose();
  for (Joint j : {Joint::ShoulderL, Joint::ElbowL, Joint::WristL, Joint::ShoulderR, Joint::ElbowR, Joint::WristR,
                  Joint::HipL, Joint::KneeL, Joint::AnkleL, Joint::HipR, Joint::KneeR, Joint::AnkleR})
    if (p.state[static_cast<size_t>(idx(j))] != TrackingState::Tracked) return false;
  return true;
}

void Context::restoreFitBefore() {
  fit_ = fitBeforeRecut_;
  rest_[kCutSkeleton].body.reset();
  if (contextCut() == kCutSkeleton) proxyBounds_.clear();
}

void Context::advanceRecuts() {
  if (recuts_.empty()) return;
  bool dressed = true;
  for (const Recut& r : recuts_) dressed = dressed && r.dressing.finished;
  if (!dressed) {
    for (Recut& r : recuts_) {
      std::string why;
      if (!r.fresh->dress(r.dressing, kRecutFramesPerStep, why)) {
        // Every garment stays as it was, on the previous rest body, until the next calibration.
        recuts_.clear();
        restoreFitBefore();
        return;
      }
    }
    return;
  }
  for (Recut& r : recuts_) {
    std::string unused;
    r.fresh->setParams(r.garment->params(), unused);  // the host's parameters of now (validated when set)
    swapIn(*r.garment, std::move(*r.fresh));
    if (GarmentCut* c = cutEntry(r.garment)) c->cut = kCutSkeleton;
  }
  recuts_.clear();
  reachDirty_ = true;
  wakeAll();
}

bool Context::refitGarments(std::string& err) {
  // The new shape may fit the person's fitted bones where the old one did not, or the other way:
  // the garments cut for the shape while it fits take the cut that says, made again as their
  // template on that cut's rest body; the others are carried to their cut's new rest body.
  const bool fits = !fit_.on || shapeFitsPerson(fit_.bones);
  std::vector<std::unique_ptr<GarmentSim>> refits(garments_.size());
  std::vector<RestCut> cuts(garments_.size());
  for (size_t i = 0; i < garments_.size(); ++i) {
    const GarmentCut& c = garmentCuts_[i];
    cuts[i] = c.shape_while_it_fits ? (fits ? kCutShape : kCutSkeleton) : c.cut;
    std::string why;
    refits[i] = garments_[i]->refitted(restBody(cuts[i]), restEllipsoids(cuts[i]), restEllipsoidGroups(cuts[i]), why,
                                       /*remake_template=*/cuts[i] != c.cut);
    if (!refits[i]) {
      err = "garment " + std::to_string(i) + " could not be dressed on the new body (" + why + ")";
      return false;
    }
  }
  for (size_t i = 0; i < garments_.size(); ++i) {
    swapIn(*garments_[i], std::move(*refits[i]));
    garmentCuts_[i].cut = cuts[i];
  }
  shapeFits_ = fits;
  return true;
}

void Context::swapIn(GarmentSim& garment, GarmentSim&& fresh) {
  garment.replaceWith(std::move(fresh));
  ReachParams rp;
  rp.margin_m = options_.reach_margin_m;
  adaptive_.removeGarment(&garment);
  adaptive_.addGarment(&garment, garmentReach(garment, rp));
  applyBackend(garment);
}

drape_result Context::pushFrame(const drape_skeleton_frame& f, std::string& err) {
  ++pushed_;
  auto reject = [&](drape_result r, const std::string& message) {
    ++rejected_;
    err = message;
    return r;
  };
  if (f.layout < DRAPE_LAYOUT_KINECT1 || f.layout > DRAPE_LAYOUT_AZURE)
    return reject(DRAPE_ERROR_OUT_OF_RANGE, "skeleton frame: layout " + std::to_string(f.layout) +
                                                " is not 1 (Kinect v1), 2 (Kinect v2) or 3 (Azure Kinect)");
  const Layout layout = static_cast<Layout>(f.layout);
  const int expected = layoutJointCount(layout);
  if (f.joint_count != static_cast<uint32_t>(expected))
    return reject(DRAPE_ERROR_INVALID_ARGUMENT,
                  "skeleton frame: joint_count " + std::to_string(f.joint_count) + " does not match layout " +
                      std::to_string(f.layout) + " (" + std::to_string(expected) + " joints)");
  if (!f.joints) return reject(DRAPE_ERROR_NULL_ARGUMENT, "skeleton frame: joints is NULL");
  if (f.reserved != 0) return reject(DRAPE_ERROR_INVALID_ARGUMENT, "skeleton frame: reserved must be 0");
  if (!std::isfinite(f.timestamp_s))
    return reject(DRAPE_ERROR_NONFINITE, "skeleton frame: timestamp_s is not finite");
  if (hasAccepted_ && !(f.timestamp_s > lastAcceptedTime_)) {
    std::ostringstream s;
    s.precision(17);
    s << "skeleton frame: timestamp " << f.timestamp_s << " s is not after the previous frame's "
      << lastAcceptedTime_ << " s";
    return reject(DRAPE_ERROR_TIMESTAMP, s.str());
  }
  JointSample samples[32];
  for (int j = 0; j < expected; ++j) {
    const drape_joint& in = f.joints[j];
    const float c[3] = {in.position.x, in.position.y, in.position.z};
    for (float v : c) {
      if (!std::isfinite(v))
        return reject(DRAPE_ERROR_NONFINITE, "skeleton frame: joint " + std::to_string(j) + " has a NaN or Inf coordinate");
      if (std::fabs(v) > kMaxCoordinateM)
        return reject(DRAPE_ERROR_OUT_OF_RANGE, "skeleton frame: joint " + std::to_string(j) +
                                                    " is more than 1000 m from the sensor");
    }
    if (in.tracking_state < DRAPE_TRACKING_NOT_TRACKED || in.tracking_state > DRAPE_TRACKING_TRACKED)
      return reject(DRAPE_ERROR_OUT_OF_RANGE, "skeleton frame: joint " + std::to_string(j) + " tracking_state " +
                                                  std::to_string(in.tracking_state) + " is not 0, 1 or 2");
    samples[j].position = Vec3(c[0], c[1], c[2]);
    samples[j].state = static_cast<TrackingState>(in.tracking_state);
  }
  if (f.orientations) {
    for (int j = 0; j < expected; ++j) {
      const drape_quat& q = f.orientations[j];
      const float n2 = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
      if (!std::isfinite(n2))
        return reject(DRAPE_ERROR_NONFINITE, "skeleton frame: orientation " + std::to_string(j) + " is not finite");
      if (std::fabs(n2 - 1.0f) > 0.02f)
        return reject(DRAPE_ERROR_INVALID_ARGUMENT, "skeleton frame: orientation " + std::to_string(j) +
                                                        " is not a unit quaternion");
    }
  }
  SkeletonPose pose;
  std::string mapErr;
  if (!mapToCanonical(layout, samples, expected, pose, mapErr))
    return reject(DRAPE_ERROR_INVALID_ARGUMENT, "skeleton frame: " + mapErr);

  // Accepted: commit.
  if (hasQueued_) ++dropped_;
  queued_ = pose;
  queuedTime_ = f.timestamp_s;
  hasQueued_ = true;
  hasAccepted_ = true;
  lastAcceptedTime_ = f.timestamp_s;
  orientations_.assign(f.orientations ? f.orientations : nullptr,
                       f.orientations ? f.orientations + expected : nullptr);
  ++accepted_;
  return DRAPE_OK;
}

drape_result Context::update(std::string& err) {
  if (!hasQueued_ && !updated_) {
    err = "update: no skeleton frame has been accepted yet (call drape_context_push_skeleton first)";
    return DRAPE_ERROR_CALL_ORDER;
  }
  if (hasQueued_) {
    const auto t0 = Clock::now();
    tracker_.push(queued_, queuedTime_);
    hasQueued_ = false;
    skeletonMs_ = msSince(t0);
    teleported_ = tracker_.teleportedLastPush();
    poseJumped_ = tracker_.poseJumpedLastPush();
    teleportPending_ = teleportPending_ || teleported_;
    poseJumpPending_ = poseJumpPending_ || poseJumped_;
    ++updates_;
  } else if (!shapeDirty_) {
    return DRAPE_OK;  // nothing new
  }
  const bool newPose = updates_ != skips_.updates;
  const SkeletonPose& pose = tracker_.pose();
  for (const Vec3& p : pose.position) {
    if (!isFinite(p)) {
      // Cannot happen with validated input; if it does, start the tracker afresh rather than
      // spreading NaN into the body.
      tracker_.reset();
      err = "update: the skeleton filter produced a non-finite joint; tracker reset (please report)";
      return DRAPE_ERROR_INTERNAL;
    }
  }
  // The torso over the calibration window, for the garments' cut (fitGarmentsToSkeleton).
  // Any garment may be cut for the skeleton (drape_garment_desc.cut), one added later too.
  if (newPose && !tracker_.calibrated()) torsoAverage_.add(pose);
  finishFrameCounters();
  skips_.updates = updates_;
  // A body that moved wakes the garments before anything is built for the frame.
  if (newPose) adaptive_.observePose(pose, teleported_, options_);
  const auto t1 = Clock::now();
  body_->updateRings(pose);
  meshFresh_ = normalsFresh_ = !options_.stages_on_demand;
  if (meshFresh_) {
    body_->updateMesh();
    body_->updateNormals();
  }
  bodyMs_ = msSince(t1);
  const auto t2 = Clock::now();
  buildProxies(pose);
  proxiesMs_ = msSince(t2);
  updated_ = true;
  shapeDirty_ = false;
  volumeDirty_ = true;
  return DRAPE_OK;
}

void Context::fillStats(drape_frame_stats& out) {
  if (updated_ && volumeDirty_) {
    const BodyModel& body = bodyMesh(false);
    volumeL_ = static_cast<float>(1000.0 * signedVolume(body.positions(), body.indices()));
    volumeDirty_ = false;
  }
  out.frames_pushed = pushed_;
  out.frames_accepted = accepted_;
  out.frames_rejected = rejected_;
  out.frames_dropped = dropped_;
  out.updates = updates_;
  out.teleports = tracker_.teleportCount();
  out.teleported = teleported_ ? 1 : 0;
  out.calibrated = tracker_.calibrated() ? 1 : 0;
  out.pose_jumped = poseJumped_ ? 1 : 0;
  out.reserved1 = 0;
  out.last_timestamp_s = lastAcceptedTime_;
  out.skeleton_ms = skeletonMs_;
  out.body_ms = bodyMs_;
  out.proxies_ms = proxiesMs_;
  out.body_volume_l = updated_ ? volumeL_ : 0.0f;
  out.pose_jumps = tracker_.poseJumpCount();
}

}  // namespace drape

namespace drape {

void Context::refreshBvh() {
  // The topology never changes, so after the first build a refit follows the moved vertices.
  bodyMesh(false);
  if (!bvhBuilt_) {
    bvh_.build(body_->positions(), body_->indices());
    bvhBuilt_ = true;
  } else {
    bvh_.refit(body_->positions());
  }
}

FidelityReport Context::measureFidelity() {
  refreshBvh();
  const auto& e = proxies().ellipsoids();
  return drape::measureFidelity(body_->positions(), body_->indices(), e.data(), static_cast<int>(e.size()), bvh_);
}

}  // namespace drape

namespace drape {

Context::RestCut Context::cutFor(int32_t garment_cut, bool limbs_must_fit, bool template_kind) const {
  if (garment_cut == DRAPE_GARMENT_CUT_SHAPE) return kCutShape;
  if (garment_cut == DRAPE_GARMENT_CUT_SKELETON) return kCutSkeleton;
  if (garment_cut == DRAPE_GARMENT_CUT_BY_KIND && (limbs_must_fit || (template_kind && !shapeFits_))) return kCutSkeleton;
  return contextCut();
}

Context::RestSlot& Context::restSlot(RestCut cut) {
  RestSlot& r = rest_[cut];  // kCutShape 0, kCutSkeleton 1
  if (!r.body) {
    auto b = std::make_unique<BodyModel>(shape_, bodyParamsFrom(desc_, false));
    const SkeletonPose pose = garmentRestPose(cut);
    b->update(pose);
    // The tracked body's builder, so the ellipsoids come in the same count and order as every
    // frame's (the plan of sub-rings is made on a builder's first build and depends on the
    // proportions: a fresh builder on a body with the person's bones can plan other ones).
    r.proxies = proxies_;
    r.proxies.build(*b, pose);
    r.groups.clear();
    for (const ProxySource& src : r.proxies.sources()) r.groups.push_back(collisionGroups(src));
    r.body = std::move(b);
  }
  return r;
}

const BodyModel& Context::restBody(RestCut cut) { return *restSlot(cut).body; }

const std::vector<uint8_t>& Context::restEllipsoidGroups(RestCut cut) { return restSlot(cut).groups; }

const std::vector<Ellipsoid>& Context::restEllipsoids(RestCut cut) { return restSlot(cut).proxies.ellipsoids(); }

Context::GarmentCut* Context::cutEntry(const GarmentSim* garment) {
  for (size_t i = 0; i < garments_.size(); ++i)
    if (garments_[i].get() == garment) return &garmentCuts_[i];
  return nullptr;
}

GarmentSim* Context::adoptGarment(std::unique_ptr<GarmentSim> garment, RestCut cut, bool shape_while_it_fits) {
  ReachParams rp;
  rp.margin_m = options_.reach_margin_m;
  std::vector<ReachSphere> reach = garmentReach(*garment, rp);
  garmentCuts_.reserve(garments_.size() + 1);  // first: the three lists stay the same length
  garmentLayers_.reserve(garments_.size() + 1);
  garments_.push_back(std::move(garment));
  garmentCuts_.push_back(GarmentCut{cut, shape_while_it_fits});
  garmentLayers_.emplace_back();
  adaptive_.addGarment(garments_.back().get(), std::move(reach));
  reachDirty_ = true;
  applyBackend(*garments_.back());
  return garments_.back().get();
}

bool Context::removeGarment(const GarmentSim* garment) {
  for (auto it = garments_.begin(); it != garments_.end(); ++it) {
    if (it->get() == garment) {
      // Its replacement, if a recut is dressing one, goes with it.
      recuts_.erase(std::remove_if(recuts_.begin(), recuts_.end(), [&](const Recut& r) { return r.garment == garment; }),
                    recuts_.end());
      adaptive_.removeGarment(garment);
      reachDirty_ = true;
      garmentCuts_.erase(garmentCuts_.begin() + (it - garments_.begin()));
      garmentLayers_.erase(garmentLayers_.begin() + (it - garments_.begin()));
      garments_.erase(it);
      return true;
    }
  }
  return false;
}

bool Context::setGarmentLayer(const GarmentSim* garment, int32_t layer) {
  for (size_t i = 0; i < garments_.size(); ++i) {
    if (garments_[i].get() != garment) continue;
    if (garmentLayers_[i].layer == layer) return true;
    garmentLayers_[i].layer = layer;
    // What lies under which garment changed: every garment of the context steps again.
    for (const auto& g : garments_) wakeGarment(g.get());
    return true;
  }
  return false;
}

int32_t Context::garmentLayer(const GarmentSim* garment) const {
  for (size_t i = 0; i < garments_.size(); ++i)
    if (garments_[i].get() == garment) return garmentLayers_[i].layer;
  return 0;
}

const std::vector<float>* Context::garmentLayerOffsets(const GarmentSim* garment) const {
  for (size_t i = 0; i < garments_.size(); ++i)
    if (garments_[i].get() == garment) return &garmentLayers_[i].over.offsets();
  return nullptr;
}

void Context::measureLayers(size_t count) {
  // A garment's cloth is measured when another lies over it: where its last step left it, on
  // stepEllipsoids_; a garment not yet stepped where it was dressed, on its cut's rest body (the
  // offsets are distances off the ellipsoids, the same in any pose), so that garments placed
  // together on the first frame are layered from it.
  const auto under = [&](size_t j, int32_t over) {
    const int32_t l = garmentLayers_[j].layer;
    return l >= 1 && l < over;
  };
  for (size_t j = 0; j < garments_.size(); ++j) {
    bool covered = false;
    for (size_t i = 0; i < garments_.size() && !covered; ++i) covered = i != j && under(j, garmentLayers_[i].layer);
    const GarmentSim& g = *garments_[j];
    if (!covered) {
      garmentLayers_[j].shell.forgetHosts();
    } else if (g.steps() == 0) {
      garmentLayers_[j].shell.forgetHosts();  // dressed: new positions, then the body's
      garmentLayers_[j].shell.measure(g.positions(), g.particleCount(), restEllipsoids(garmentCuts_[j].cut));
      garmentLayers_[j].shell.forgetHosts();
    } else {
      garmentLayers_[j].shell.measure(g.positions(), g.particleCount(), stepEllipsoids_);
    }
  }
  for (size_t i = 0; i < garments_.size(); ++i) {
    GarmentLayer& me = garmentLayers_[i];
    if (me.layer < 2) {  // nothing can be under it
      me.over.reset();
      continue;
    }
    me.over.beginStep(count);
    for (size_t j = 0; j < garments_.size(); ++j)
      if (j != i && under(j, me.layer)) me.over.addUnder(garmentLayers_[j].shell.offsets());
    // A garment's first step places it on the body: no motion to limit (docs/garments.md).
    me.over.endMeasure(/*limited=*/garments_[i]->steps() > 0);
  }
}

bool Context::layerOver(size_t i, const std::vector<Ellipsoid>& start, const std::vector<Ellipsoid>& end) {
  GarmentLayer& me = garmentLayers_[i];
  if (!me.over.any()) return false;
  // The step moves from the last step's offsets to this one's, as it moves the body.
  LayerOffsets::grow(start, me.over.startOffsets(), me.start);
  LayerOffsets::grow(end, me.over.offsets(), me.end);
  return true;
}

drape_result Context::step(float dt, std::string& err) {
  Context* self = this;
  return stepContexts(&self, 1, dt, err);
}

drape_result Context::checkStep(float dt, std::string& err) const {
  if (!std::isfinite(dt)) {
    err = "dt is not finite";
    return DRAPE_ERROR_NONFINITE;
  }
  if (!(dt > 0.0f) || dt > 10.0f) {
    err = "dt = " + std::to_string(dt) + " s is outside (0, 10]";
    return DRAPE_ERROR_OUT_OF_RANGE;
  }
  if (!hasQueued_ && !updated_) {
    err = "no skeleton frame has been accepted yet (call drape_context_push_skeleton first)";
    return DRAPE_ERROR_CALL_ORDER;
  }
  return DRAPE_OK;
}

drape_result Context::beginStep(float dt, std::string& err) {
  if (drape_result r = update(err)) return r;
  stepT0_ = Clock::now();
  // A recut dresses from the step after the calibration's, which makes the replacements.
  advanceRecuts();
  // (update() has given the tracker a pose by now: a step before any frame is refused.)
  if (tracker_.calibrated()) {
    provisionalFitDone_ = false;  // a tracker that starts calibrating again fits provisionally again
    if (tracker_.calibrationCount() != fittedCalibration_) fitGarmentsToSkeleton(/*provisional=*/false);
  } else if (!provisionalFitDone_) {
    provisionalFitDone_ = true;
    fitGarmentsToSkeleton(/*provisional=*/true);
  }
  // Woken or new garments, or new options, since the frame's ellipsoids were built.
  if (reachDirty_ && updated_) buildProxies(tracker_.pose());
  const std::vector<Ellipsoid>& now = proxies_.ellipsoids();
  if (stepEllipsoids_.size() != now.size()) stepEllipsoids_ = now;
  // An ellipsoid culled at the last step and built now has no start value: it starts still (it
  // was out of every garment's reach by the reach margin, so no particle is near it).
  for (size_t k = 0; k < now.size() && k < fresh_.size(); ++k)
    if (fresh_[k] && !(k < freshAtStep_.size() && freshAtStep_[k])) stepEllipsoids_[k] = now[k];
  adaptive_.advance(dt);
  size_t slept = 0;
  stepping_.clear();
  // Torso cloth meets a leg only while the sensor tracks its hip and knee (GarmentSim::
  // setLegsTrusted): an inferred leg is a guess.
  const SkeletonPose& tracked = tracker_.pose();
  const auto trusted = [&](Joint hip, Joint knee) {
    return tracked.state[idx(hip)] == TrackingState::Tracked && tracked.state[idx(knee)] == TrackingState::Tracked;
  };
  const bool left_leg = trusted(Joint::HipL, Joint::KneeL), right_leg = trusted(Joint::HipR, Joint::KneeR);
  placement_[kCutShape].aim(this, kCutShape);
  placement_[kCutSkeleton].aim(this, kCutSkeleton);
  measureLayers(now.size());
  for (size_t i = 0; i < garments_.size(); ++i) {
    const std::unique_ptr<GarmentSim>& g = garments_[i];
    g->setPlacementPath(&placement_[garmentCuts_[i].cut]);
    if (options_.sleep && adaptive_.asleep(g.get())) {
      g->markSkipped();
      ++slept;
      continue;
    }
    const std::vector<Ellipsoid>* woke = adaptive_.wakeStart(g.get(), now);
    g->setTrackingNoise(tracker_.noiseSigmaM());  // noise bursts: garment_recovery.cpp
    g->setLegsTrusted(left_leg, right_leg);
    g->setPoseJumped(poseJumpPending_);
    // A garment worn over others steps with the ellipsoids grown by the cloth under it.
    const std::vector<Ellipsoid>& start = woke ? *woke : stepEllipsoids_;
    const bool layered = layerOver(i, start, now);
    // Device frames are only staged here: the caller runs them all together (runStagedFrames).
    g->stepBegin(*body_, layered ? garmentLayers_[i].start : start, layered ? garmentLayers_[i].end : now, dt,
                 teleportPending_, true);
    stepping_.push_back(g.get());
  }
  stepDt_ = dt;
  stepSlept_ = slept;
  return DRAPE_OK;
}

void Context::endStep() {
  const float dt = stepDt_;
  const size_t slept = stepSlept_;
  const std::vector<Ellipsoid>& now = proxies_.ellipsoids();
  for (GarmentSim* g : stepping_) {
    g->stepEnd();
    adaptive_.afterStep(*g, now, dt, options_);
  }
  stepping_.clear();
  checkDeviceFailures();
  clothSkippedLast_ = slept > 0;
  if (!garments_.empty()) {
    ++skips_.steps;
    skips_.garment_steps_slept += slept;
    if (slept == garments_.size()) ++skips_.frames_slept;
    if (slept > 0) ++skips_.stages_skipped;
  }
  teleportPending_ = false;
  poseJumpPending_ = false;
  stepEllipsoids_ = now;
  freshAtStep_ = fresh_;
  stepMs_ = msSince(stepT0_);
}

drape_result Context::stepContexts(Context* const* contexts, size_t count, float dt, std::string& err) {
  // Every check first: a rejected call changes nothing.
  for (size_t i = 0; i < count; ++i)
    if (drape_result r = contexts[i]->checkStep(dt, err)) return r;
  drape_result result = DRAPE_OK;
  size_t begun = 0;
  for (; begun < count; ++begun) {
    if ((result = contexts[begun]->beginStep(dt, err)) != DRAPE_OK) break;
  }
  // The contexts that began finish their step even when a later one failed to begin.
  if (count == 1) {
    if (begun == 1) runStagedFrames(contexts[0]->stepping_);  // drape_context_step: no gathering
  } else {
    std::vector<GarmentSim*>& staged = contexts[0]->gathered_;  // scratch kept between steps
    staged.clear();
    for (size_t i = 0; i < begun; ++i)
      staged.insert(staged.end(), contexts[i]->stepping_.begin(), contexts[i]->stepping_.end());
    runStagedFrames(staged);
  }
  for (size_t i = 0; i < begun; ++i) contexts[i]->endStep();
  return result;
}

Context::RestCut Context::cutOf(const GarmentSim& garment) const {
  for (size_t i = 0; i < garments_.size(); ++i)
    if (garments_[i].get() == &garment) return garmentCuts_[i].cut;
  return contextCut();
}

GarmentAccuracy Context::measureGarment(const GarmentSim& garment) {
  if (!updated_) {
    // Before the first update: on the rest body the garment was cut on.
    const RestCut cut = cutOf(garment);
    return garment.measure(restEllipsoids(cut), nullptr, &restBody(cut));
  }
  refreshBvh();
  return garment.measure(proxies().ellipsoids(), &bvh_, &body());
}

}  // namespace drape
