// Sensor joint layouts (Kinect v1, Kinect v2, Azure Kinect) <-> the canonical 21-joint skeleton.
//
// Every layout is given in the sensor SDK's own joint order (tables in docs/skeleton.md, section
// "Layouts"). Positions are metres in a right-handed camera space for every layout: Azure hosts
// convert k4abt's millimetres to metres before calling. The Azure SDK's camera has +Y pointing
// down while Kinect's points up; nothing here assumes a direction for "up" (face points and
// clavicles are built from the body's own neck->head and right->left shoulder axes), so no axis
// flip is applied or needed.
//
// Joints a layout lacks are synthesised from the ones it has (fixed geometric rules, documented in
// docs/skeleton.md) and reported as Inferred; a synthesised joint whose sources include a
// NotTracked joint is reported NotTracked. State values outside 0..2 are read as NotTracked.
#pragma once

#include "skeleton/joints.h"

#include <string>
#include <vector>

namespace drape {

// Maps one sensor frame (layout order, `count` joints) onto the canonical pose. Returns false and
// sets `err` (leaving `out` untouched) when the layout value is unknown, `count` does not match
// the layout, or `joints` is null. Positions are not checked for finiteness (the caller does
// that); NaN inputs only produce NaN outputs, never a crash.
//   Kinect v1: the canonical Neck is synthesised from ShoulderCenter and Head (Inferred).
//   Azure:     the canonical SpineShoulder is the midpoint of CLAVICLE_LEFT/RIGHT (state: the
//              lower of the two), or, when a clavicle is NotTracked but SPINE_CHEST and NECK are
//              not, the midpoint of SPINE_CHEST and NECK (Inferred).
bool mapToCanonical(Layout layout, const JointSample* joints, int count, SkeletonPose& out,
                    std::string& err);

// Converts a frame from one layout to another (for tests, and for feeding Kinect v2 recordings as
// v1/Azure data). Joints the target has but the source lacks are synthesised and marked Inferred
// (Azure clavicles / SPINE_CHEST / nose / eyes / ears, Kinect v2 hand tips / thumbs / neck, ...).
// Joints both layouts have are copied unchanged. Returns false + `err` (and leaves `out`
// untouched) on an unknown layout, a count mismatch or a null `in`.
bool convertLayout(Layout from, const JointSample* in, int inCount, Layout to,
                   std::vector<JointSample>& out, std::string& err);

// Geometry constants of the synthesis rules (measured on the Kinect v2 recordings in
// shared/data/kinect_v2_msft_labanotation where possible; see docs/skeleton.md).
namespace layout_constants {
// Neck = SpineShoulder + kNeckFraction * (Head - SpineShoulder). Measured median 0.29..0.36
// over the four Kinect v2 recordings (median perpendicular offset 3..18 mm).
constexpr float kNeckFraction = 0.34f;
// Azure SPINE_CHEST = SpineMid + kSpineChestFraction * (SpineShoulder - SpineMid).
constexpr float kSpineChestFraction = 0.5f;
// Azure clavicles = SpineShoulder +/- kClavicleFraction * (ShoulderL - ShoulderR) / 2.
constexpr float kClavicleFraction = 0.3f;
// Hand tip = Hand + kHandTipLength along Wrist->Hand (measured median Hand->HandTip 0.064..0.102 m;
// the rule lands a median 27 mm from the recorded tip).
constexpr float kHandTipLengthM = 0.08f;
// Thumb = Hand + these offsets along Wrist->Hand, toward the body's front and outward (away from
// the body's midline): the rounded median offsets in the recordings. Kinect v2 thumbs are noisy:
// the rule lands a median 29..65 mm (per recording) from the recorded thumb; the hand joint
// itself is a median 47 mm away.
constexpr float kThumbOffsetAlongM = 0.01f;
constexpr float kThumbOffsetFrontM = 0.01f;
constexpr float kThumbOffsetOutM = 0.02f;
}  // namespace layout_constants

}  // namespace drape
