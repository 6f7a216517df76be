// The body: elliptical feature rings placed along the skeleton's bones (paper §2.1), joined into
// one closed, consistently wound triangle mesh, with the dynamic shoulder junction (paper §2.2).
//
// Layout, chosen for the stages that follow (tracking ellipsoids, cloth, OpenCL):
//  - rings are stored flat (structure of arrays: centre, frame, semi-axes) in chain order, so the
//    ellipsoid stage reads them without walking any tree;
//  - the mesh topology (indices) is fixed when the model is built — it depends only on K and the
//    ring density — and every frame rewrites positions and normals in place, without allocating.
#pragma once

#include "body/body_shape.h"
#include "common/math.h"
#include "skeleton/joints.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace drape {

// A chain is a run of bones the rings follow without branching.
enum class Chain : int { Torso = 0, Head, ArmL, ArmR, LegL, LegR, Count };
constexpr int kChainCount = static_cast<int>(Chain::Count);
const char* chainName(Chain c);
// The joints a chain runs through: bone k of the chain is chainJoint(c, k) -> chainJoint(c, k+1).
int chainJointCount(Chain c);
Joint chainJoint(Chain c, int k);

// Where a ring sits and how big it is. `u` runs along the chain: bone k of the chain covers
// u in [k, k+1] (0 = the chain's first joint); `offset_m` slides the ring further along the
// local bone direction (for rings beyond the last joint, e.g. the top of the head).
struct RingStation {
  Chain chain = Chain::Torso;
  float u = 0.0f;
  float offset_m = 0.0f;
  float forward_m = 0.0f;  // semi-axis along the ring frame's x (body forward)
  float side_m = 0.0f;     // semi-axis along the ring frame's z (body right / limb side)
  int measure = -1;        // Measure whose girth this ring reproduces exactly, or -1
  bool junction = false;   // the dynamic shoulder ring (radius follows the next ring)
};

// The gap kept between an arm and the torso by default (BodyModelParams::arms_clear_torso): the two
// layers of cloth the arm rests on (sleeve and torso cloth, each kept 4 mm outside its part) and a
// little room.
inline constexpr float kDefaultArmTorsoClearanceM = 0.01f;

struct BodyModelParams {
  int ring_points = 20;           // K: a multiple of 4 in [8, 256]
  int rings_per_segment = 1;      // extra rings interpolated between two stations: [0, 16]
  // The paper's naive fixed shoulder connection ring (normal = the rest arm direction) instead of
  // the dynamic junction; exists only so tests can show what the dynamic junction prevents.
  bool fixed_shoulder_junction = false;
  // Arm rings that would enter the torso are moved out of it, keeping arm_torso_clearance_m
  // between the two (body/arm_clearance.h). Off here so that a bare model's rings sit on its
  // bones; the context turns it on for the tracked body and the poses a garment is carried
  // through, not for the rest bodies garments are cut on.
  bool arms_clear_torso = false;
  float arm_torso_clearance_m = kDefaultArmTorsoClearanceM;
  // For a rest body garments are cut on (arms_clear_torso off, its rings on the bones): whether
  // the tracked bodies it stands for keep their arms clear, arm_torso_clearance_m apart, so a
  // garment judges its collision groups with the arms where they will be (GarmentSim::create).
  bool tracked_arms_clear_torso = true;
};

// One ring's pose this frame. The frame is a proper rotation: x = forward, y = along the chain,
// z = x × y. (The paper writes z = body left, which makes its frame left-handed; an ellipse is
// symmetric about its x axis so the geometry is the same, and we keep det(R) = +1.)
struct RingPose {
  Vec3 centre = Vec3::Zero();
  Mat3 frame = Mat3::Identity();  // columns x, y, z
  float forward_m = 0.0f;
  float side_m = 0.0f;
};

// The point of ring `r` at the angle whose cosine and sine are c and s, from the frame's x
// (forward) towards its z: where the body mesh puts its ring vertices (angles 2 pi j / K).
// Coordinate by coordinate in the order of the Eigen expression it replaces,
// centre + c * (x * forward_m) + s * (z * side_m): the same bits, and no calls into Eigen's
// expression templates in the sanitizer build (-O1), where the body mesh's vertices were a fifth
// of a body-only test's time.
inline Vec3 ringPointAt(const RingPose& r, float c, float s) {
  const Mat3& f = r.frame;
  const float a = r.forward_m, b = r.side_m;
  return Vec3(r.centre.x() + c * (f(0, 0) * a) + s * (f(0, 2) * b), r.centre.y() + c * (f(1, 0) * a) + s * (f(1, 2) * b),
              r.centre.z() + c * (f(2, 0) * a) + s * (f(2, 2) * b));
}

class BodyModel {
 public:
  // Builds rings and the fixed topology. Params must be valid (checked by the caller).
  BodyModel(const ResolvedShape& shape, const BodyModelParams& params);

  // Replaces the shape; topology is unchanged (it does not depend on the shape).
  void setShape(const ResolvedShape& shape);

  // Places every ring on the pose and rewrites positions and normals. No allocation.
  // The same as updateRings(pose); updateMesh(); updateNormals().
  void update(const SkeletonPose& pose);
  // The stages of update(), for callers that need only part of the body this frame (the
  // adaptive pipeline, capi/adaptive.h): rings and the apex vertices (what the tracking
  // ellipsoids read); the other vertices (ring points, crotch bridge) from the rings; normals from
  // the vertices. Each stage reads only what the previous ones wrote.
  void updateRings(const SkeletonPose& pose);
  void updateMesh();
  void updateNormals();

  const std::vector<RingStation>& stations() const { return stations_; }
  const std::vector<RingPose>& rings() const { return rings_; }
  // First ring index and ring count of each chain inside rings().
  int chainFirstRing(Chain c) const { return chainFirst_[static_cast<int>(c)]; }
  int chainRingCount(Chain c) const { return chainCount_[static_cast<int>(c)]; }
  int ringPoints() const { return K_; }

  const std::vector<Vec3>& positions() const { return positions_; }
  // The tip of an open chain (Head, ArmL, ArmR, LegL, LegR): the mesh vertex beyond its last ring
  // (crown, fingertips, toes), placed with the rings (updateRings). Torso: its last ring's centre.
  Vec3 apex(Chain c) const;
  const std::vector<Vec3>& normals() const { return normals_; }
  const std::vector<uint32_t>& indices() const { return indices_; }
  // Triangles of the stitch between a shoulder's torso loop and its junction ring (for tests).
  const std::vector<uint32_t>& shoulderTriangles(bool left) const {
    return left ? shoulderTrisL_ : shoulderTrisR_;
  }
  const ResolvedShape& shape() const { return shape_; }
  const BodyModelParams& params() const { return params_; }
  // The share of the arms' push out of the torso applied from the next update on, [0, 1]
  // (BodyModelParams::arms_clear_torso; 1 by default).
  void setArmClearanceWeight(float w) { armWeight_ = std::clamp(w, 0.0f, 1.0f); }

 private:
  void buildStations();
  void buildTopology();
  void placeRings(const SkeletonPose& pose);
  void writeVertices();
  void writeApexes(const SkeletonPose& pose);
  void computeNormals();

  ResolvedShape shape_;
  BodyModelParams params_;
  int K_ = 20;
  std::vector<RingStation> stations_;  // one per ring (interpolated ones included)
  std::vector<RingPose> rings_;
  float armWeight_ = 1.0f;
  Vec3 armShift_[2] = {Vec3::Zero(), Vec3::Zero()};  // the hands' last rings' push, left / right
  int chainFirst_[kChainCount] = {};
  int chainCount_[kChainCount] = {};

  // Extra vertices after the ring points: crotch bridge, then one apex per chain end.
  int bridgeFirst_ = 0, bridgeCount_ = 0;
  int apexFirst_ = 0;  // Head, ArmL, ArmR, LegL, LegR

  std::vector<Vec3> positions_, normals_;
  std::vector<uint32_t> indices_;
  std::vector<uint32_t> shoulderTrisL_, shoulderTrisR_;
};

}  // namespace drape
