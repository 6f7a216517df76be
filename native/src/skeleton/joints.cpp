#include "skeleton/joints.h"

namespace drape {

const char* jointName(Joint j) {
  static const char* const kNames[kJointCount] = {
      "Pelvis", "SpineMid", "SpineShoulder", "Neck", "Head",
      "ShoulderL", "ElbowL", "WristL", "HandL",
      "ShoulderR", "ElbowR", "WristR", "HandR",
      "HipL", "KneeL", "AnkleL", "FootL",
      "HipR", "KneeR", "AnkleR", "FootR"};
  const int i = static_cast<int>(j);
  return (i >= 0 && i < kJointCount) ? kNames[i] : "?";
}

int layoutJointCount(Layout layout) {
  switch (layout) {
    case Layout::Kinect1: return 20;
    case Layout::Kinect2: return 25;
    case Layout::Azure: return 32;
  }
  return 0;
}

bool isValidLayout(int layout) { return layout >= 1 && layout <= 3; }

}  // namespace drape
