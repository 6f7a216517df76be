// The adaptive pipeline's side of Context (capi/adaptive.h): proxy culling, the body mesh on
// demand, sleeping garments and the skip counters.
#include "capi/context.h"

namespace drape {

const BodyModel& Context::bodyMesh(bool normals) {
  if (!meshFresh_) {
    body_->updateMesh();
    meshFresh_ = true;
  }
  if (normals && !normalsFresh_) {
    body_->updateNormals();
    normalsFresh_ = true;
  }
  return *body_;
}

const ProxyBuilder& Context::proxies() {
  if (!proxiesComplete_ && updated_) {
    proxies_.build(*body_, tracker_.pose());
    proxiesComplete_ = true;
    builtThisUpdate_ = proxies_.ellipsoids().size();
    fresh_.assign(proxies_.ellipsoids().size(), 1);
  }
  return proxies_;
}

void Context::buildProxies(const SkeletonPose& pose) {
  reachDirty_ = false;
  const size_t total = proxies_.ellipsoids().size();
  if (!options_.cull_proxies) {
    for (auto& g : garments_) g->setReachable({});
    proxies_.build(*body_, pose);
    proxiesComplete_ = true;
    builtThisUpdate_ = total;
    fresh_.assign(total, 1);
    return;
  }
  if (proxyBounds_.size() != total && !garments_.empty()) {
    const RestSlot& rest = restSlot(contextCut());
    proxyBounds_ = ellipsoidBoundRadii(*rest.body, rest.proxies.ellipsoids(), rest.proxies.sources());
  }
  // The union of what the awake garments reach now; each garment is told its own share.
  fresh_.assign(total, 0);
  const auto& sources = proxies_.sources();
  for (auto& g : garments_) {
    if (options_.sleep && adaptive_.asleep(g.get())) continue;
    const std::vector<ReachSphere>* reach = adaptive_.reach(g.get());
    if (!reach) continue;
    garmentReach_.assign(total, 0);
    markReachable(*reach, body_->rings(), sources, proxyBounds_, garmentReach_);
    reachIndices_.clear();
    for (size_t k = 0; k < total; ++k) {
      if (!garmentReach_[k]) continue;
      reachIndices_.push_back(static_cast<int>(k));
      fresh_[k] = 1;
    }
    // A garment that reaches nothing still gets a (single) ellipsoid list of its own: an empty
    // one would mean "all" to setReachable.
    if (reachIndices_.empty() && total > 0) {
      reachIndices_.push_back(0);
      fresh_[0] = 1;
    }
    g->setReachable(reachIndices_);
  }
  proxies_.build(*body_, pose, fresh_);
  builtThisUpdate_ = proxies_.lastBuilt();
  proxiesComplete_ = builtThisUpdate_ == total;
}

void Context::finishFrameCounters() {
  // The frame before this update is final now: what was never computed for it was skipped.
  if (!updated_) return;
  const size_t total = proxies_.ellipsoids().size();
  skips_.stages_skipped += (meshFresh_ ? 0 : 1) + (normalsFresh_ ? 0 : 1) + (proxiesComplete_ ? 0 : 1);
  skips_.proxies_skipped += total - std::min(total, builtThisUpdate_);
}

SkipCounters Context::skipCounters() const {
  SkipCounters s = skips_;
  const size_t total = proxies_.ellipsoids().size();
  s.proxies_available = static_cast<uint32_t>(total);
  s.proxies_built = static_cast<uint32_t>(updated_ ? builtThisUpdate_ : 0);
  s.garments = static_cast<uint32_t>(garments_.size());
  s.garments_asleep = static_cast<uint32_t>(options_.sleep ? adaptive_.asleepCount() : 0);
  uint32_t bits = 0;
  if (updated_) {
    if (!meshFresh_) bits |= kStageBodyMesh;
    if (!normalsFresh_) bits |= kStageBodyNormals;
    if (!proxiesComplete_) bits |= kStageProxies;
    // The frame in progress counts as far as it went.
    s.stages_skipped += (meshFresh_ ? 0 : 1) + (normalsFresh_ ? 0 : 1) + (proxiesComplete_ ? 0 : 1);
    s.proxies_skipped += total - std::min(total, builtThisUpdate_);
  }
  if (clothSkippedLast_) bits |= kStageCloth;
  s.stages_skipped_last = bits;
  return s;
}

void Context::setPipelineOptions(const PipelineOptions& o) {
  const bool reachChanged = o.reach_margin_m != options_.reach_margin_m;
  options_ = o;
  if (reachChanged) {
    // The margin is part of every garment's spheres.
    ReachParams rp;
    rp.margin_m = options_.reach_margin_m;
    for (auto& g : garments_) {
      adaptive_.removeGarment(g.get());
      adaptive_.addGarment(g.get(), garmentReach(*g, rp));
    }
  }
  wakeAll();
  // A host that turns on-demand stages off expects the mesh of the current frame at once.
  if (!options_.stages_on_demand && updated_) bodyMesh(true);
}

void Context::wakeAll() {
  adaptive_.wakeAll();
  reachDirty_ = true;
}

void Context::wakeGarment(const GarmentSim* garment) {
  adaptive_.wake(garment);
  reachDirty_ = true;
}

}  // namespace drape
