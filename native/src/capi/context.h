// The object behind a drape_context handle: one tracked person, their body, and the state the
// C ABI promises to keep intact when a call is rejected.
#pragma once

#include "body/body_model.h"
#include "capi/adaptive.h"
#include "body/body_shape.h"
#include "cloth/garment_layers.h"
#include "cloth/garment_sim.h"
#include "proxies/fidelity.h"
#include "proxies/mesh_bvh.h"
#include "proxies/proxy_builder.h"
#include "drape/drape.h"
#include "skeleton/tracker.h"

#include <memory>
#include <string>
#include <vector>

namespace drape {

class Context {
 public:
  // Throws only std::bad_alloc (caught at the ABI). desc must be validated already.
  explicit Context(const drape_context_desc& desc);

  const drape_context_desc& desc() const { return desc_; }

  // Each returns DRAPE_OK or an error with `err` filled; on error nothing changes except the
  // rejected-frame counter.
  drape_result setShape(const BodyShapeInput& in, std::string& err);
  drape_result pushFrame(const drape_skeleton_frame& frame, std::string& err);
  drape_result update(std::string& err);
  // A frame rejected before it reached pushFrame (NULL, bad struct_size) still counts.
  void countRejectedFrame() { ++pushed_; ++rejected_; }

  const ResolvedShape& shape() const { return shape_; }
  // The body's rings are current after every update; its mesh (positions, normals) only when
  // read through bodyMesh() (stages on demand, capi/adaptive.h).
  const BodyModel& body() const { return *body_; }
  const BodyModel& bodyMesh(bool normals);
  const SkeletonTracker& tracker() const { return tracker_; }
  // Every ellipsoid of the last update (culled ones are built now if they were skipped).
  const ProxyBuilder& proxies();
  size_t ellipsoidCount() const { return proxies_.ellipsoids().size(); }
  // Fidelity of the current ellipsoids against the current body mesh (a diagnostic: ~ms).
  FidelityReport measureFidelity();
  bool hasUpdate() const { return updated_; }

  // Garments. What proportions a garment is cut for (its RestCut): the shape's standard ones, or
  // the person's bones once the tracker has calibrated them (before that, the shape's too).
  enum RestCut : int { kCutShape = 0, kCutSkeleton = 1 };
  // A garment desc's cut (drape_garment_cut, validated) as a RestCut: CONTEXT follows garment_fit;
  // BY_KIND is the skeleton's for a garment whose limbs must fit (limbs_must_fit: trousers and
  // long-sleeve templates), else CONTEXT, except that a template (template_kind) takes the
  // skeleton's once the tracked bones say the shape does not fit the person (shapeFitsPerson):
  // only a template can be made again for another body when the shape's fit changes.
  RestCut cutFor(int32_t garment_cut, bool limbs_must_fit, bool template_kind = true) const;
  // Whether a template garment with this desc cut follows that rule through shape changes and
  // calibrations (BY_KIND, its limbs need not fit, the context cuts for the shape): adoptGarment's
  // shape_while_it_fits.
  bool cutFollowsShapeFit(int32_t garment_cut, bool limbs_must_fit) const {
    return garment_cut == DRAPE_GARMENT_CUT_BY_KIND && !limbs_must_fit && contextCut() == kCutShape;
  }
  // Whether the body shape is not too small for a person with these bone lengths
  // (SkeletonTracker::boneLengths): their size against the shape's proportions
  // (boneScaleAgainstShape, body/body_shape.h) at most kShapeMisfit times kTrackedBoneScale, what
  // trackers read on a shape that fits (their joints sit inside the body). Why: a host that sets a
  // shape for someone else (a child's left on while an adult plays) got garments cut for that
  // body; a dress cut for 1.0 m on an adult's skeleton stretched to 3x between its collar and
  // waist pins (P99 1.98; cut for the bones 0.10). A shape too large is not judged: cut for the
  // bones, a T-shirt on a 2.2 m body did better at BMI 15 and worse at BMI 45 (docs/garments.md,
  // "A shape too small for the person").
  static constexpr float kTrackedBoneScale = 0.85f;  // the shared Kinect and CMU takes on the default body: 0.82-0.94
  static constexpr float kShapeMisfit = 1.25f;
  bool shapeFitsPerson(const std::array<float, kBoneCount>& bones) const;
  // The cut a garment of this context was made for (contextCut() for one that is not).
  RestCut cutOf(const GarmentSim& garment) const;
  RestCut contextCut() const {
    return desc_.garment_fit == DRAPE_GARMENT_FIT_SKELETON ? kCutSkeleton : kCutShape;
  }
  // The body in its rest pose for a cut (what garments are fitted and dressed on), built on demand
  // and cached until the shape or the person's fitted bones change; the overloads without a cut
  // below take the context's own (drape_context_desc.garment_fit).
  const BodyModel& restBody(RestCut cut);
  const std::vector<Ellipsoid>& restEllipsoids(RestCut cut);
  // The collision groups of each ellipsoid (collisionGroups of its source; same order every frame).
  const std::vector<uint8_t>& restEllipsoidGroups(RestCut cut);
  const BodyModel& restBody() { return restBody(contextCut()); }
  const std::vector<Ellipsoid>& restEllipsoids() { return restEllipsoids(contextCut()); }
  const std::vector<uint8_t>& restEllipsoidGroups() { return restEllipsoidGroups(contextCut()); }
  // Takes ownership; the garment is dressed already (GarmentSim::create with restBody(cut)).
  // shape_while_it_fits: cutFollowsShapeFit (the garment changes cut when the shape's fit does).
  GarmentSim* adoptGarment(std::unique_ptr<GarmentSim> garment, RestCut cut, bool shape_while_it_fits = false);
  GarmentSim* adoptGarment(std::unique_ptr<GarmentSim> garment) { return adoptGarment(std::move(garment), contextCut()); }
  // Destroys it; false when it is not this context's.
  bool removeGarment(const GarmentSim* garment);
  // Layered garments (drape_garment_set_layer): a garment of layer L >= 2 is worn over this
  // context's garments of layers 1 .. L - 1; 0 (the default) is not layered. False when the
  // garment is not this context's; the layer is checked by the caller (0 .. kMaxGarmentLayer).
  static constexpr int32_t kMaxGarmentLayer = 255;
  bool setGarmentLayer(const GarmentSim* garment, int32_t layer);
  int32_t garmentLayer(const GarmentSim* garment) const;
  // The offsets a layered garment stepped with last (m, one per ellipsoid: how far the cloth under
  // it stood off each, within the step limits; empty for a garment of layer 0 or 1, zeros when
  // nothing lies under it). For tests and diagnostics; null when the garment is not this context's.
  const std::vector<float>* garmentLayerOffsets(const GarmentSim* garment) const;
  size_t garmentCount() const { return garments_.size(); }
  GarmentSim& garment(size_t i) { return *garments_[i]; }
  // Runs update() if a frame is queued, then advances every garment by dt (seconds, (0, 10]).
  drape_result step(float dt, std::string& err);
  // drape_step_contexts: step() of each, their OpenCL garments' frames run together (one batched
  // launch per device: docs/opencl.md). Every context is checked first (a rejected call changes
  // nothing); contexts must be distinct (the caller checks).
  static drape_result stepContexts(Context* const* contexts, size_t count, float dt, std::string& err);
  // Accuracy of a garment now, against the ellipsoids and the body mesh of the last update.
  GarmentAccuracy measureGarment(const GarmentSim& garment);
  double lastStepMs() const { return stepMs_; }
  // Backends (docs/opencl.md; capi/context_backend.cpp). desc validated by the caller. Moves every
  // garment to the chosen backend; OpenCL trouble falls back to the CPU with the reason kept.
  drape_result setBackend(const drape_backend_desc& desc, std::string& err);
  // The strings point into the context, valid until the next call.
  void backendInfo(drape_backend_info& out);
  void fillStats(drape_frame_stats& out);

  // The adaptive pipeline (capi/adaptive.h, docs/adaptive.md). Options must be valid.
  void setPipelineOptions(const PipelineOptions& o);
  const PipelineOptions& pipelineOptions() const { return options_; }
  SkipCounters skipCounters() const;
  // Wakes every sleeping garment / one garment (new cloth parameters); the next step runs it.
  void wakeAll();
  void wakeGarment(const GarmentSim* garment);
  bool garmentAsleep(const GarmentSim* garment) const { return adaptive_.asleep(garment); }
  // The skeleton's calibration recuts garments over several steps (Recut, private): this many
  // dressing frames a step. recutPending(): one is being dressed now.
  static constexpr int kRecutFramesPerStep = 2;
  bool recutPending() const { return !recuts_.empty(); }

 private:
  drape_context_desc desc_;
  ResolvedShape shape_;
  SkeletonTracker tracker_;
  std::unique_ptr<BodyModel> body_;
  ProxyBuilder proxies_;
  TriangleBvh bvh_;  // over the body mesh, built lazily for fidelity measurements
  bool bvhBuilt_ = false;
  void refreshBvh();

  // The rest body of each cut, its ellipsoids (from the tracked body's builder, so in the same
  // count and order as every frame's) and their collision groups; `body` null until asked for.
  struct RestSlot {
    std::unique_ptr<BodyModel> body;
    ProxyBuilder proxies;
    std::vector<uint8_t> groups;
  };
  RestSlot rest_[2];
  RestSlot& restSlot(RestCut cut);
  // Garments cut for the skeleton are cut on the rest pose with the person's bones once the
  // tracker has calibrated them (before that, the shape's standard proportions). fit_ says
  // which pose the skeleton cut's rest body takes (garmentRestPose): from the bone lengths and
  // averaged torso of the calibration fitted last.
  struct BoneFit {
    bool on = false;  // false: the shape's standard proportions
    std::array<float, kBoneCount> bones{};
    SkeletonPose torso{};
  };
  BoneFit fit_;
  TorsoAverage torsoAverage_;  // the torso over the calibration window
  uint32_t fittedCalibration_ = 0;  // the tracker's calibrationCount() last seen
  SkeletonPose garmentRestPose(RestCut cut) const;
  // The skeleton's calibration (or, provisional, the bones of the first step's pose while the
  // tracker is calibrating): garments cut for the skeleton are cut again for these bones, and those cut for
  // the shape while it fits are cut for the skeleton when it does not. The calibration cuts them
  // again for its own bones when those move the rest pose by kRefitBelowM or more. A provisional
  // fit acts on a shape that does not fit (garments cut for a body of another size would spend the
  // calibration window stretched or hanging off), or when provisionalFitsFirstPose(): then the
  // trousers and long sleeves are on the person from the first frame instead of hanging past the
  // feet and hands for a second and jumping at the calibration's recut (docs/garments.md, "Cut
  // for the first pose").
  void fitGarmentsToSkeleton(bool provisional);
  bool provisionalFitsFirstPose() const;
  bool provisionalFitDone_ = false;  // since the tracker last started calibrating
  bool shapeFits_ = true;         // shapeFitsPerson(bones) of the bones fitted last
  // A recut in progress (the skeleton's calibration): each garment cut for the skeleton has its
  // replacement, made on the new rest body, dressed kRecutFramesPerStep frames a step beside it
  // (GarmentSim::Dressing) instead of all in the calibration's step; the step after the last one
  // is dressed swaps them all in (each placed into that step's pose, as a new garment is). Why:
  // dressing all at once held that one step up for the whole dressing (378 ms of 612 at 31 517
  // particles; docs/garments.md, "Cut by kind"). The bones fitted before are kept to go back to
  // should a replacement fail to dress (every garment then stays as it was, as refitGarments does).
  struct Recut {
    GarmentSim* garment = nullptr;
    std::unique_ptr<GarmentSim> fresh;
    GarmentSim::Dressing dressing;  // the replacement is cut for the skeleton
  };
  std::vector<Recut> recuts_;
  BoneFit fitBeforeRecut_;
  // Dresses the recuts' next frames, or swaps them in once all are dressed (beginStep).
  void advanceRecuts();
  void restoreFitBefore();
  // Refits every garment to its cut's rest body at once, each carried there by ring skinning
  // (after a shape change; the calibration's recut is spread over steps: Recut): all of them or,
  // when one cannot be dressed on the new body, none (err says which and why).
  bool refitGarments(std::string& err);
  // A garment takes over its new cut (GarmentSim::replaceWith), with its reach and backend.
  void swapIn(GarmentSim& garment, GarmentSim&& fresh);
  std::vector<std::unique_ptr<GarmentSim>> garments_;
  // garments_[i]'s cut, and whether it is the shape's only while the shape fits the person.
  struct GarmentCut {
    RestCut cut = kCutShape;
    bool shape_while_it_fits = false;
  };
  std::vector<GarmentCut> garmentCuts_;
  GarmentCut* cutEntry(const GarmentSim* garment);
  // garments_[i]'s layer (drape_garment_set_layer; 0 = not layered) and, for a garment worn over
  // others, how far their cloth stands off each ellipsoid and the ellipsoids grown by that, which
  // its step reads until endStep (cloth/garment_layers.h). Parallel to garments_, as garmentCuts_.
  struct GarmentLayer {
    int32_t layer = 0;
    ClothShell shell;     // its own cloth, measured while a garment lies over it
    LayerOffsets over;    // what it steps with, over the shells under it
    std::vector<Ellipsoid> start, end;
  };
  std::vector<GarmentLayer> garmentLayers_;
  // Measures, for every layered garment, how far the cloth under it stands off each of the
  // `count` ellipsoids (before any garment steps: every garment is where its last step left it,
  // on stepEllipsoids_).
  void measureLayers(size_t count);
  // The ellipsoids garments_[i] steps with: the body's, or (a garment over others) grown by
  // the cloth under it (false: the body's; true: garmentLayers_[i].start / end).
  bool layerOver(size_t i, const std::vector<Ellipsoid>& start, const std::vector<Ellipsoid>& end);
  std::vector<Ellipsoid> stepEllipsoids_;  // the ellipsoids at the end of the last step
  // The way from each cut's rest pose into the pose now, for the garments placed this step
  // (cloth/placement_path.h; built only when one asks: capi/context_placement.cpp).
  class PosePath final : public PlacementPath {
   public:
    // This step's: the path's ends and what its poses are built with. Forgets the last step's.
    void aim(Context* context, RestCut cut);
    int poses() override;
    void at(int i, const BodyModel*& body, const std::vector<Ellipsoid>*& ellipsoids) override;

   private:
    Context* context_ = nullptr;
    RestCut cut_ = kCutShape;
    int poses_ = -1;  // not yet worked out this step
    SkeletonPose rest_{}, now_{};
    std::unique_ptr<BodyModel> body_;
    ProxyBuilder proxies_;
    bool planned_ = false;  // proxies_ copied from the context's builder this step
  };
  PosePath placement_[2];
  bool teleportPending_ = false;           // a teleport since the last step
  bool poseJumpPending_ = false;           // a pose jump (tracker.h) since the last step
  double stepMs_ = 0.0;

  SkeletonPose queued_{};
  double queuedTime_ = 0.0;
  bool hasQueued_ = false;
  std::vector<drape_quat> orientations_;  // of the last accepted frame, kept for the host
  bool hasAccepted_ = false;
  double lastAcceptedTime_ = 0.0;
  bool updated_ = false;
  bool shapeDirty_ = false;

  // Backends: the requested choice and its OpenCL runtime (shared with contexts choosing the same
  // device). applyBackend puts one garment where the choice says; checkDeviceFailures moves
  // garments whose device failed back to the CPU.
  struct Backend;
  std::shared_ptr<Backend> backend_;
  std::string infoDevice_, infoPlatform_, infoReason_;  // backendInfo() strings
  void applyBackend(GarmentSim& garment);
  void checkDeviceFailures();
  // step() in parts (stepContexts): the checks, the garments' host halves (device frames staged),
  // then after every staged frame ran (runStagedFrames, context_backend.cpp), the other halves.
  drape_result checkStep(float dt, std::string& err) const;
  drape_result beginStep(float dt, std::string& err);
  void endStep();
  static void runStagedFrames(const std::vector<GarmentSim*>& garments);
  std::vector<GarmentSim*> stepping_;  // begun, not yet ended
  std::vector<GarmentSim*> gathered_;  // stepContexts: the staged garments of every context
  float stepDt_ = 0.0f;
  size_t stepSlept_ = 0;
  std::chrono::steady_clock::time_point stepT0_{};

  uint32_t pushed_ = 0, accepted_ = 0, rejected_ = 0, dropped_ = 0, updates_ = 0;
  bool teleported_ = false;
  bool poseJumped_ = false;  // the last update's frame was a pose jump (tracker.h)
  double skeletonMs_ = 0.0, bodyMs_ = 0.0, proxiesMs_ = 0.0;
  float volumeL_ = 0.0f;
  bool volumeDirty_ = true;

  // Adaptive pipeline state (context_adaptive.cpp).
  PipelineOptions options_;
  AdaptiveState adaptive_;
  bool meshFresh_ = true, normalsFresh_ = true;  // body mesh / normals are of the last update
  bool proxiesComplete_ = true;                  // every ellipsoid is of the last update
  bool reachDirty_ = false;                      // garments, sleep or options changed since the build
  std::vector<uint8_t> fresh_, freshAtStep_;     // per ellipsoid: built for the last update / step
  std::vector<uint8_t> garmentReach_;            // scratch: one garment's reachable ellipsoids
  std::vector<int> reachIndices_;                // scratch
  std::vector<float> proxyBounds_;               // ellipsoidBoundRadii of the rest proxies
  SkipCounters skips_;                           // finalised counters (frames before the last)
  size_t builtThisUpdate_ = 0;
  bool clothSkippedLast_ = false;
  void buildProxies(const SkeletonPose& pose);
  void finishFrameCounters();
};

// Validates a context desc (ranges documented in drape.h). Returns DRAPE_OK or an error + message.
drape_result validateContextDesc(const drape_context_desc& d, std::string& err);
TrackerParams trackerParamsFrom(const drape_context_desc& d);
// The body model of a context with desc d: ring layout and arm clearance. own_arms_clear: whether
// this model moves its own arm rings (the tracked body and the pose path's) or only carries the
// setting for the garments cut on it (a rest body: BodyModelParams::tracked_arms_clear_torso).
BodyModelParams bodyParamsFrom(const drape_context_desc& d, bool own_arms_clear);

}  // namespace drape
