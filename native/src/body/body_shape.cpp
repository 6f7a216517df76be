#include "body/body_shape.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace drape {

bool validateShapeInput(const BodyShapeInput& in, std::string& err, bool* nonfinite) {
  if (nonfinite) *nonfinite = false;
  auto bad = [&](const char* what, float v, const char* range) {
    std::ostringstream s;
    s << "body shape: " << what << " = " << v << " is outside " << range;
    err = s.str();
    return false;
  };
  if (!std::isfinite(in.height_m) || !std::isfinite(in.weight_kg)) {
    if (nonfinite) *nonfinite = true;
    err = std::string("body shape: ") + (std::isfinite(in.height_m) ? "weight_kg" : "height_m") +
          " is not a finite number";
    return false;
  }
  if (in.height_m < 0.8f || in.height_m > 2.5f) return bad("height_m", in.height_m, "[0.8, 2.5]");
  if (in.weight_kg < 15.0f || in.weight_kg > 300.0f) return bad("weight_kg", in.weight_kg, "[15, 300]");
  for (int i = 0; i < kGirthCount; ++i) {
    const float g = in.girth_mm[i];
    if (!std::isfinite(g)) {
      if (nonfinite) *nonfinite = true;
      err = std::string("body shape: ") + measureName(static_cast<Measure>(i)) + "_mm is not finite";
      return false;
    }
    if (g != 0.0f && (g < 50.0f || g > 3000.0f)) {
      const std::string name = std::string(measureName(static_cast<Measure>(i))) + "_mm";
      return bad(name.c_str(), g, "0 (predict) or [50, 3000]");
    }
  }
  const int sex = static_cast<int>(in.sex);
  if (sex < 0 || sex > 2) {
    err = "body shape: sex must be 0 (unspecified), 1 (female) or 2 (male)";
    return false;
  }
  return true;
}

ResolvedShape resolveShape(const BodyShapeInput& in) {
  ResolvedShape r;
  r.input = in;
  for (int i = 0; i < static_cast<int>(Measure::Count); ++i) {
    r.m[i] = 0.001f * predictMeasureMm(static_cast<Measure>(i), in.height_m, in.weight_kg);
  }
  // Girths the host gave replace predictions; the breadths/depths that describe the same cross
  // section scale with them so the ellipse keeps its predicted proportions.
  auto scalePair = [&](Measure girth, Measure a, Measure b) {
    const int g = static_cast<int>(girth);
    if (in.girth_mm[g] <= 0.0f) return;
    const float factor = 0.001f * in.girth_mm[g] / r.m[g];
    r.m[static_cast<int>(a)] *= factor;
    r.m[static_cast<int>(b)] *= factor;
  };
  scalePair(Measure::Chest, Measure::ChestDepth, Measure::ChestBreadth);
  scalePair(Measure::Waist, Measure::WaistDepth, Measure::WaistBreadth);
  scalePair(Measure::Hip, Measure::ButtockDepth, Measure::HipBreadth);
  for (int i = 0; i < kGirthCount; ++i) {
    r.girth_given[i] = in.girth_mm[i] > 0.0f;
    if (r.girth_given[i]) r.m[i] = 0.001f * in.girth_mm[i];
  }
  return r;
}

SkeletonPose restPose(const ResolvedShape& shape, float arm_down_deg) {
  constexpr float kRestDepth = 2.5f;  // metres in front of the sensor
  // Heights as fractions of stature (Winter fig. 4.1 / Drillis & Contini), placed where the
  // Kinect v2 tracker puts its joints (joint centres, not surface landmarks).
  const float H = shape.input.height_m;
  SkeletonPose p;
  auto at = [&](Joint j, float x, float y_frac) {
    p.position[idx(j)] = Vec3(x, y_frac * H, kRestDepth);
    p.state[idx(j)] = TrackingState::Tracked;
  };
  // Facing -Z (towards a sensor at the origin looking along +Z): the subject's right is +X.
  const float pelvisY = 0.530f;
  at(Joint::Pelvis, 0.0f, pelvisY);
  at(Joint::SpineMid, 0.0f, 0.650f);
  at(Joint::SpineShoulder, 0.0f, 0.818f);
  at(Joint::Neck, 0.0f, 0.870f);
  at(Joint::Head, 0.0f, 0.935f);
  const float shoulderHalf = 0.100f;  // shoulder joint centres sit ~0.10 H from the midline
  const float hipHalf = 0.052f;       // hip joint centres ~0.052 H from the midline
  at(Joint::HipL, -hipHalf * H, pelvisY - 0.01f);
  at(Joint::HipR, +hipHalf * H, pelvisY - 0.01f);
  at(Joint::KneeL, -hipHalf * H, 0.285f);
  at(Joint::KneeR, +hipHalf * H, 0.285f);
  at(Joint::AnkleL, -hipHalf * H, 0.039f);
  at(Joint::AnkleR, +hipHalf * H, 0.039f);
  at(Joint::FootL, -hipHalf * H, 0.015f);
  at(Joint::FootR, +hipHalf * H, 0.015f);
  p.position[idx(Joint::FootL)].z() = kRestDepth - 0.10f * H;  // toes point forward (-Z)
  p.position[idx(Joint::FootR)].z() = kRestDepth - 0.10f * H;
  at(Joint::ShoulderL, -shoulderHalf * H, 0.808f);
  at(Joint::ShoulderR, +shoulderHalf * H, 0.808f);
  // Arm segment lengths: upper arm 0.186 H, forearm 0.146 H, wrist to hand centre 0.06 H.
  const float a = arm_down_deg * kPi / 180.0f;
  const float lengths[3] = {0.186f * H, 0.146f * H, 0.060f * H};
  for (int side = 0; side < 2; ++side) {
    const float sx = side == 0 ? -1.0f : 1.0f;
    const Vec3 dir(sx * std::cos(a), -std::sin(a), 0.0f);
    const Joint chain[4] = {side == 0 ? Joint::ShoulderL : Joint::ShoulderR,
                            side == 0 ? Joint::ElbowL : Joint::ElbowR,
                            side == 0 ? Joint::WristL : Joint::WristR,
                            side == 0 ? Joint::HandL : Joint::HandR};
    for (int k = 1; k < 4; ++k) {
      p.position[idx(chain[k])] = p.position[idx(chain[k - 1])] + dir * lengths[k - 1];
      p.state[idx(chain[k])] = TrackingState::Tracked;
    }
  }
  return p;
}

namespace {

bool isTorsoJoint(int j) {
  return j <= idx(Joint::Head) || j == idx(Joint::ShoulderL) || j == idx(Joint::ShoulderR) || j == idx(Joint::HipL) ||
         j == idx(Joint::HipR);
}

// World -> rest-pose axes for a pose's pelvis: up along pelvis -> spine-shoulder, right along
// hip L -> hip R (the rest pose faces -Z). False for a collapsed torso.
bool pelvisFrame(const SkeletonPose& p, Mat3& to_rest) {
  const auto& q = p.position;
  const Vec3 up = q[idx(Joint::SpineShoulder)] - q[idx(Joint::Pelvis)];
  Vec3 right = q[idx(Joint::HipR)] - q[idx(Joint::HipL)];
  right -= right.dot(up) / std::max(up.squaredNorm(), 1e-12f) * up;
  if (!(up.norm() > 0.05f) || !(right.norm() > 0.02f)) return false;
  Mat3 f;  // columns: right, up, back
  f.col(0) = right.normalized();
  f.col(1) = up.normalized();
  f.col(2) = f.col(0).cross(f.col(1));
  to_rest = f.transpose();
  return to_rest.allFinite();
}

}  // namespace

SkeletonPose restPoseWithBones(const ResolvedShape& shape, float arm_down_deg,
                               const std::array<float, kBoneCount>& lengths, const SkeletonPose* torso) {
  const SkeletonPose rest = restPose(shape, arm_down_deg);
  SkeletonPose p = rest;
  // The torso's own geometry (spine, hip and shoulder joints) from `torso`, in its pelvis' frame.
  Mat3 toRest = Mat3::Identity();
  const bool useTorso = torso != nullptr && pelvisFrame(*torso, toRest);
  for (int b = 0; b < kBoneCount; ++b) {  // parents come first (kJointParent's order)
    const int c = boneChild(b), pa = boneParent(b);
    Vec3 bone = rest.position[static_cast<size_t>(c)] - rest.position[static_cast<size_t>(pa)];
    if (useTorso && isTorsoJoint(c)) {
      // A torso bone more than 45 degrees off the standard pose's is not a build but bad data (a
      // joint lost or flipped): the standard direction then.
      const Vec3 d = toRest * (torso->position[static_cast<size_t>(c)] - torso->position[static_cast<size_t>(pa)]);
      if (d.norm() > 1e-3f && d.normalized().dot(bone.normalized()) > std::cos(0.25f * kPi))
        bone = d.normalized() * bone.norm();
    }
    const float canonical = bone.norm();
    const float l = lengths[static_cast<size_t>(b)];
    const float use = std::isfinite(l) && l >= 0.01f ? std::clamp(l, 0.25f * canonical, 4.0f * canonical) : canonical;
    p.position[static_cast<size_t>(c)] =
        p.position[static_cast<size_t>(pa)] + (canonical > 0.0f ? Vec3(bone * (use / canonical)) : bone);
  }
  return p;
}

void TorsoAverage::clear() {
  sum_.fill(Vec3::Zero());
  count_ = 0;
}

void TorsoAverage::add(const SkeletonPose& pose) {
  Mat3 toRest;
  if (!pelvisFrame(pose, toRest)) return;
  for (int j = 1; j < kJointCount; ++j) {
    if (!isTorsoJoint(j)) continue;
    const Vec3 d = toRest * (pose.position[static_cast<size_t>(j)] - pose.position[static_cast<size_t>(kJointParent[static_cast<size_t>(j)])]);
    if (d.norm() > 1e-4f && d.allFinite()) sum_[static_cast<size_t>(j)] += d.normalized();
  }
  ++count_;
}

SkeletonPose TorsoAverage::mean() const {
  // Rest-pose axes already: the pelvis frame of this pose is the identity (up to the spine's and
  // hips' own average directions).
  SkeletonPose p;
  p.position.fill(Vec3::Zero());
  p.state.fill(TrackingState::Tracked);
  for (int j = 1; j < kJointCount; ++j) {
    const Vec3 d = sum_[static_cast<size_t>(j)];
    p.position[static_cast<size_t>(j)] =
        p.position[static_cast<size_t>(kJointParent[static_cast<size_t>(j)])] + (d.norm() > 1e-6f ? Vec3(d.normalized()) : Vec3::Zero());
  }
  return p;
}

float boneScaleAgainstShape(const ResolvedShape& shape, const std::array<float, kBoneCount>& lengths) {
  const SkeletonPose rest = restPose(shape);
  std::array<float, kBoneCount> ratio{};
  int n = 0;
  for (int b = 0; b < kBoneCount; ++b) {
    const float l = lengths[static_cast<size_t>(b)];
    const float r = (rest.position[static_cast<size_t>(boneChild(b))] - rest.position[static_cast<size_t>(boneParent(b))]).norm();
    if (!(l >= 0.01f) || !std::isfinite(l) || !(r >= 0.01f)) continue;
    ratio[static_cast<size_t>(n++)] = l / r;
  }
  if (n == 0) return 1.0f;
  std::nth_element(ratio.begin(), ratio.begin() + n / 2, ratio.begin() + n);
  return ratio[static_cast<size_t>(n / 2)];
}

}  // namespace drape
