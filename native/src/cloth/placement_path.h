// The way a garment is put on the first pose it sees (docs/garments.md, "Dressed by moving into
// the first pose").
//
// A garment is dressed on its rest pose (arms 65 deg down, legs straight). Skinning it straight
// onto a pose far from that one (forearms folded in front of the belly, a knee raised) moves each
// particle with the rings near it and tears the cloth where neighbouring rings turn apart: with
// the forearms folded 1 % of the edges came out over 2.1 times their rest length and 1 % under 0.3
// of it, and the first frames of simulation pulled the sleeves off the forearms. Instead the body
// moves from the rest pose (placed where the person stands) into the pose over a few simulated
// frames and the garment is carried there by the ellipsoids, as a person moves into a pose with
// the garment on.
#pragma once

#include "body/body_model.h"
#include "proxies/ellipsoid.h"
#include "skeleton/joints.h"

#include <vector>

namespace drape {

// The pose at u in [0, 1] on the way from `rest` (the garment's rest pose, wherever it stands) to
// `now`: rest moved rigidly onto now's pelvis (origin the pelvis, axes from the spine and the
// hips), then every bone's direction turned (slerp) and its length changed (lerp) by u towards
// now's, parent before child from the pelvis. u = 0: the rest pose where the person stands;
// u = 1: now's positions (to rounding). States are now's.
SkeletonPose poseBetween(const SkeletonPose& rest, const SkeletonPose& now, float u);

// The largest angle (radians) a bone turns on that way: how far the garment has to be carried.
float largestBoneTurn(const SkeletonPose& rest, const SkeletonPose& now);

// The poses GarmentSim::placeOnBody walks before the one it places on: the body and all its
// ellipsoids (the frame's count and order) at poseBetween(rest, now, i / poses()) for i in
// [0, poses()). The context builds them on demand (capi/context_placement.cpp), so a frame on
// which no garment is placed pays nothing.
class PlacementPath {
 public:
  virtual ~PlacementPath() = default;
  // Poses before now; 0 when the pose is near enough the rest pose to skin the garment onto it.
  virtual int poses() = 0;
  // Pose i < poses(): pointers valid until the next call.
  virtual void at(int i, const BodyModel*& body, const std::vector<Ellipsoid>*& ellipsoids) = 0;
};

}  // namespace drape
