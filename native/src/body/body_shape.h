// Body shape: what the host tells us about the person (height, weight, optional girths) resolved
// into every measurement the ring template needs, with the missing ones predicted from the ANSUR II
// regression (girth_regression.h).
#pragma once

#include "body/girth_regression.h"
#include "skeleton/joints.h"

#include <array>
#include <string>

namespace drape {

enum class Sex : int { Unspecified = 0, Female = 1, Male = 2 };

// Input: as the C ABI's drape_body_shape (girths in mm, 0 = predict).
struct BodyShapeInput {
  Sex sex = Sex::Unspecified;
  float height_m = 1.70f;
  float weight_kg = 65.0f;
  std::array<float, kGirthCount> girth_mm{};  // Measure order: neck, chest, waist, hip, thigh, calf, upper_arm, forearm
};

// Every measurement resolved, in metres.
struct ResolvedShape {
  BodyShapeInput input;                           // as given (girths 0 where predicted)
  std::array<float, static_cast<int>(Measure::Count)> m{};  // metres, indexed by Measure
  std::array<bool, kGirthCount> girth_given{};

  float operator[](Measure which) const { return m[static_cast<int>(which)]; }
};

// Validates ranges (height 0.8..2.5 m, weight 15..300 kg, girths 0 or 50..3000 mm, finite).
// `nonfinite` (optional) tells a NaN/Inf apart from an out-of-range value.
bool validateShapeInput(const BodyShapeInput& in, std::string& err, bool* nonfinite = nullptr);

// Fills every measurement: given girths as given, the rest predicted. Predicted breadths/depths
// are rescaled so the depth:breadth ratio follows the girth actually used.
ResolvedShape resolveShape(const BodyShapeInput& in);

// A standing rest pose (arms 35 degrees below horizontal, facing -Z in a Kinect-style camera
// space with +Y up, feet at y = 0, 2.5 m in front of the sensor) with segment lengths from standard anthropometric
// proportions of stature (Winter, "Biomechanics and Motor Control of Human Movement", fig. 4.1).
// Used to fix the mesh topology's seam alignment and for synthetic tests.
SkeletonPose restPose(const ResolvedShape& shape, float arm_down_deg = 35.0f);

// The same standing pose with the person's own bone lengths (SkeletonTracker::boneLengths()
// once calibrated): every bone keeps the rest pose's direction and takes the measured length,
// top-down from the pelvis, so the rings, ellipsoids and the garments cut on this pose have the
// tracked skeleton's proportions. A length that is not finite or under 1 cm (a bone the sensor
// never saw) keeps the rest pose's; the others are held within [0.25, 4] times it.
SkeletonPose restPoseWithBones(const ResolvedShape& shape, float arm_down_deg,
                               const std::array<float, kBoneCount>& lengths, const SkeletonPose* torso = nullptr);

// How the person's bones compare in size with the shape's standard proportions: the median over
// the bones of (measured length / the length in restPose(shape)), leaving out lengths that are not
// finite or under 1 cm (bones the sensor has not seen); 1 when no bone is usable. 0.82-0.94 for
// the shared Kinect and CMU takes on the default 1.70 m body (trackers read bones short), 1.0 for
// a synthetic pose of the standard proportions; 1.40 for an adult Kinect take on a 1.0 m body and
// 0.63 on a 2.2 m one (a shape the host set for someone else).
float boneScaleAgainstShape(const ResolvedShape& shape, const std::array<float, kBoneCount>& lengths);

// The person's torso geometry averaged over many poses (the tracker's calibration window): the
// direction of each torso bone (spine, neck, head, hip and shoulder joints) in the frame of the
// pelvis, so one bent or noisy frame does not shape the garments. mean() is a pose with those
// directions (unit bones from the origin) for restPoseWithBones; empty() until a pose was added.
class TorsoAverage {
 public:
  TorsoAverage() { clear(); }  // (an Eigen vector is not zeroed by {})
  void clear();
  void add(const SkeletonPose& pose);  // poses without a usable pelvis frame are skipped
  bool empty() const { return count_ == 0; }
  SkeletonPose mean() const;

 private:
  std::array<Vec3, kJointCount> sum_;
  int count_ = 0;
};

}  // namespace drape
