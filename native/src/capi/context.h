// The object behind a drape_context handle: one tracked person, their body, and the state the
// C ABI promises to keep intact when a call is rejected.
#pragma once

#include "body/body_model.h"
#include "body/body_shape.h"
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
  const BodyModel& body() const { return *body_; }
  const SkeletonTracker& tracker() const { return tracker_; }
  const ProxyBuilder& proxies() const { return proxies_; }
  // Fidelity of the current ellipsoids against the current body mesh (a diagnostic: ~ms).
  FidelityReport measureFidelity();
  bool hasUpdate() const { return updated_; }

  // Garments. The body in its rest pose for the current shape (what garments are fitted and
  // dressed on), built on demand and cached until the shape changes.
  const BodyModel& restBody();
  const std::vector<Ellipsoid>& restEllipsoids();
  // The chain of each ellipsoid (same order every frame).
  const std::vector<int>& restEllipsoidChains();
  // Takes ownership; the garment is dressed already (GarmentSim::create with restBody()).
  GarmentSim* adoptGarment(std::unique_ptr<GarmentSim> garment);
  // Destroys it; false when it is not this context's.
  bool removeGarment(const GarmentSim* garment);
  size_t garmentCount() const { return garments_.size(); }
  GarmentSim& garment(size_t i) { return *garments_[i]; }
  // Runs update() if a frame is queued, then advances every garment by dt (seconds, (0, 10]).
  drape_result step(float dt, std::string& err);
  // Accuracy of a garment now, against the ellipsoids and the body mesh of the last update.
  GarmentAccuracy measureGarment(const GarmentSim& garment);
  double lastStepMs() const { return stepMs_; }
  void fillStats(drape_frame_stats& out);

 private:
  drape_context_desc desc_;
  ResolvedShape shape_;
  SkeletonTracker tracker_;
  std::unique_ptr<BodyModel> body_;
  ProxyBuilder proxies_;
  TriangleBvh bvh_;  // over the body mesh, built lazily for fidelity measurements
  bool bvhBuilt_ = false;
  void refreshBvh();

  std::unique_ptr<BodyModel> restBody_;  // rest pose of the current shape, for garments
  ProxyBuilder restProxies_;
  std::vector<int> restChains_;
  std::vector<std::unique_ptr<GarmentSim>> garments_;
  std::vector<Ellipsoid> stepEllipsoids_;  // the ellipsoids at the end of the last step
  bool teleportPending_ = false;           // a teleport since the last step
  double stepMs_ = 0.0;

  SkeletonPose queued_{};
  double queuedTime_ = 0.0;
  bool hasQueued_ = false;
  std::vector<drape_quat> orientations_;  // of the last accepted frame, kept for the host
  bool hasAccepted_ = false;
  double lastAcceptedTime_ = 0.0;
  bool updated_ = false;
  bool shapeDirty_ = false;

  uint32_t pushed_ = 0, accepted_ = 0, rejected_ = 0, dropped_ = 0, updates_ = 0;
  bool teleported_ = false;
  double skeletonMs_ = 0.0, bodyMs_ = 0.0, proxiesMs_ = 0.0;
  float volumeL_ = 0.0f;
  bool volumeDirty_ = true;
};

// Validates a context desc (ranges documented in drape.h). Returns DRAPE_OK or an error + message.
drape_result validateContextDesc(const drape_context_desc& d, std::string& err);
TrackerParams trackerParamsFrom(const drape_context_desc& d);

}  // namespace drape
