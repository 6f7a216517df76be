// Poses between a garment's rest pose and the first pose it sees (placement_path.h).
#include "cloth/placement_path.h"

#include <algorithm>
#include <cmath>

namespace drape {
namespace {

// Below this a bone or the pelvis frame's axes are degenerate (joints on top of each other).
constexpr float kDegenerateM = 1e-4f;

// The pelvis frame: columns across the hips (left to right), up the spine, and their cross
// product. False when the joints do not span one. body_shape.cpp's pelvisFrame is the same frame
// transposed, with other rounding and thresholds; calling it instead changed the figures of 17 of
// the quality matrix's 120 runs (the path's poses move by rounding), so it was left for a change
// measured on its own.
bool pelvisFrame(const SkeletonPose& p, Mat3& f) {
  Vec3 up = p.position[idx(Joint::SpineShoulder)] - p.position[idx(Joint::Pelvis)];
  Vec3 across = p.position[idx(Joint::HipR)] - p.position[idx(Joint::HipL)];
  if (!isFinite(up) || !isFinite(across) || up.norm() < kDegenerateM) return false;
  up.normalize();
  across -= up * up.dot(across);
  if (across.norm() < kDegenerateM) return false;
  across.normalize();
  f.col(0) = across;
  f.col(1) = up;
  f.col(2) = across.cross(up);
  return true;
}

// `rest` moved rigidly so its pelvis frame lies on now's (or only translated onto now's pelvis
// when either frame is degenerate).
SkeletonPose restWhereNowStands(const SkeletonPose& rest, const SkeletonPose& now) {
  Mat3 fr, fn;
  const Mat3 q = pelvisFrame(rest, fr) && pelvisFrame(now, fn) ? Mat3(fn * fr.transpose()) : Mat3::Identity();
  const Vec3 from = rest.position[idx(Joint::Pelvis)], to = now.position[idx(Joint::Pelvis)];
  SkeletonPose out = now;
  for (size_t j = 0; j < out.position.size(); ++j) out.position[j] = to + q * (rest.position[j] - from);
  return out;
}

}  // namespace

SkeletonPose poseBetween(const SkeletonPose& rest, const SkeletonPose& now, float u) {
  u = std::clamp(std::isfinite(u) ? u : 0.0f, 0.0f, 1.0f);
  const SkeletonPose start = restWhereNowStands(rest, now);
  SkeletonPose out = now;
  // Each bone's direction turns in the world frame, not relative to its parent's: turned
  // relative to the parent, more garments came off on the way (docs/garments.md).
  for (int j = 1; j < kJointCount; ++j) {  // parents come first (joints.h)
    const size_t c = static_cast<size_t>(j), p = static_cast<size_t>(kJointParent[c]);
    const Vec3 a = start.position[c] - start.position[p], b = now.position[c] - now.position[p];
    const float la = a.norm(), lb = b.norm();
    Vec3 d;
    if (la < kDegenerateM || lb < kDegenerateM) {
      d = (1.0f - u) * a + u * b;  // a bone of no length has no direction to turn
    } else {
      const Quat turn = Quat::Identity().slerp(u, rotationBetween(a, b));
      d = (turn * (a / la)) * ((1.0f - u) * la + u * lb);
    }
    out.position[c] = out.position[p] + d;
  }
  return out;
}

float largestBoneTurn(const SkeletonPose& rest, const SkeletonPose& now) {
  const SkeletonPose start = restWhereNowStands(rest, now);
  float most = 0.0f;
  for (int j = 1; j < kJointCount; ++j) {
    const size_t c = static_cast<size_t>(j), p = static_cast<size_t>(kJointParent[c]);
    const Vec3 a = start.position[c] - start.position[p], b = now.position[c] - now.position[p];
    if (a.norm() < kDegenerateM || b.norm() < kDegenerateM) continue;
    const float cosine = std::clamp(a.normalized().dot(b.normalized()), -1.0f, 1.0f);
    most = std::max(most, std::acos(cosine));
  }
  return most;
}

}  // namespace drape
