// The poses a garment placed this step is carried through, from its cut's rest pose into the
// pose now (cloth/placement_path.h, docs/garments.md "Dressed by moving into the first pose").
#include "capi/context.h"
#include "common/math.h"

#include <algorithm>
#include <cmath>

namespace drape {
namespace {
// A bone turning less than this from the rest pose: the garment is skinned onto the pose.
constexpr float kSkinBelowRad = 10.0f * kPi / 180.0f;
// Each pose turns the bones at most this much from the one before (one simulated 1/30 s frame),
// and there are at most kMostPoses (one second).
constexpr float kTurnPerPoseRad = 6.0f * kPi / 180.0f;
constexpr int kMostPoses = 30;
}  // namespace

void Context::PosePath::aim(Context* context, RestCut cut) {
  context_ = context;
  cut_ = cut;
  poses_ = -1;
  planned_ = false;
}

int Context::PosePath::poses() {
  if (poses_ >= 0) return poses_;
  rest_ = context_->garmentRestPose(cut_);
  now_ = context_->tracker_.pose();
  const float turn = largestBoneTurn(rest_, now_);
  poses_ = !(turn >= kSkinBelowRad)
               ? 0
               : std::min(kMostPoses, static_cast<int>(std::ceil(turn / kTurnPerPoseRad)));
  return poses_;
}

void Context::PosePath::at(int i, const BodyModel*& body, const std::vector<Ellipsoid>*& ellipsoids) {
  const int n = poses();
  const float u = n > 0 ? static_cast<float>(std::clamp(i, 0, n)) / static_cast<float>(n) : 1.0f;
  const SkeletonPose pose = poseBetween(rest_, now_, u);
  if (!planned_) {
    // Made afresh on the step that asks (rare): the shape may have changed since the last one.
    body_ = std::make_unique<BodyModel>(context_->shape_, bodyParamsFrom(context_->desc_, true));
    // The frame's builder, so the ellipsoids come in its count and order (Context::restSlot).
    proxies_ = context_->proxies_;
    planned_ = true;
  }
  // The arms leave the torso as the pose leaves the rest pose the garment was cut on.
  body_->setArmClearanceWeight(u);
  body_->update(pose);
  proxies_.build(*body_, pose);
  body = body_.get();
  ellipsoids = &proxies_.ellipsoids();
}

}  // namespace drape
