// The internal (canonical) skeleton every sensor layout maps onto, and its bone hierarchy.
//
// Kinect v1 (20 joints), Kinect v2 (25) and Azure Kinect (32) all describe the same 21 body
// points we need; extra joints (hand tips, thumbs, face points, clavicles) are dropped and
// missing ones (Kinect v1 has no neck) are synthesised in layouts.cpp.
#pragma once

#include "common/math.h"

#include <array>
#include <cstdint>

namespace drape {

enum class Joint : int {
  Pelvis = 0,     // Kinect v2 SpineBase
  SpineMid,       // Kinect v2 SpineMid
  SpineShoulder,  // Kinect v2 SpineShoulder (between the shoulders, base of the neck)
  Neck,
  Head,
  ShoulderL, ElbowL, WristL, HandL,
  ShoulderR, ElbowR, WristR, HandR,
  HipL, KneeL, AnkleL, FootL,
  HipR, KneeR, AnkleR, FootR,
  Count
};
constexpr int kJointCount = static_cast<int>(Joint::Count);
constexpr int idx(Joint j) { return static_cast<int>(j); }

// Parent of each joint in the hierarchy (Pelvis is the root, parent -1). Listed so a parent
// always comes before its children: iterate 0..kJointCount-1 for a top-down pass.
constexpr std::array<int, kJointCount> kJointParent = {
    -1,                      // Pelvis
    idx(Joint::Pelvis),      // SpineMid
    idx(Joint::SpineMid),    // SpineShoulder
    idx(Joint::SpineShoulder),  // Neck
    idx(Joint::Neck),        // Head
    idx(Joint::SpineShoulder), idx(Joint::ShoulderL), idx(Joint::ElbowL), idx(Joint::WristL),
    idx(Joint::SpineShoulder), idx(Joint::ShoulderR), idx(Joint::ElbowR), idx(Joint::WristR),
    idx(Joint::Pelvis), idx(Joint::HipL), idx(Joint::KneeL), idx(Joint::AnkleL),
    idx(Joint::Pelvis), idx(Joint::HipR), idx(Joint::KneeR), idx(Joint::AnkleR),
};

// Bone b connects kJointParent[b+1] -> joint b+1 (one bone per non-root joint).
constexpr int kBoneCount = kJointCount - 1;
constexpr int boneChild(int bone) { return bone + 1; }
constexpr int boneParent(int bone) { return kJointParent[bone + 1]; }

const char* jointName(Joint j);

enum class TrackingState : uint8_t { NotTracked = 0, Inferred = 1, Tracked = 2 };
// A state read from the host outside 0..2 counts as NotTracked.
inline TrackingState sanitizeState(TrackingState s) {
  return static_cast<unsigned>(s) <= 2u ? s : TrackingState::NotTracked;
}

// Sensor layouts (values equal the C ABI's drape_layout).
enum class Layout : int { Kinect1 = 1, Kinect2 = 2, Azure = 3 };
int layoutJointCount(Layout layout);  // 20, 25, 32; 0 for an unknown value
bool isValidLayout(int layout);

// One joint as a sensor reports it, in the sensor's own joint order.
struct JointSample {
  Vec3 position = Vec3::Zero();  // metres, camera space, right-handed
  TrackingState state = TrackingState::NotTracked;
};

// A full canonical pose.
struct SkeletonPose {
  std::array<Vec3, kJointCount> position{};
  std::array<TrackingState, kJointCount> state{};
};

}  // namespace drape
