#include "body/arm_clearance.h"

#include <cmath>

namespace drape {
namespace {

// Distance from an ellipse's centre to its boundary in the in-plane unit direction (c, s) given
// in the ellipse's axes (semi-axes a along c, b along s).
float armClearanceEllipseRadius(float a, float b, float c, float s) {
  const float u = c / a, v = s / b;
  return 1.0f / std::sqrt(u * u + v * v);
}

}  // namespace

void keepArmsOutOfTorso(std::vector<RingPose>& rings, int torso_first, int torso_count, const int arm_first[2],
                        const int arm_count[2], const ArmClearance& c, Vec3 shift[2]) {
  shift[0] = shift[1] = Vec3::Zero();
  if (torso_count < 2 || !(c.weight > 0.0f)) return;
  const int torso_last = torso_first + torso_count - 1;
  for (int side = 0; side < 2; ++side) {
    // Ring 0 is the shoulder junction: it stays where the shoulder joint is, as the stitch to the
    // torso's top ring expects.
    for (int i = 1; i < arm_count[side]; ++i) {
      RingPose& arm = rings[static_cast<size_t>(arm_first[side] + i)];
      // The torso ring whose plane is nearest the arm ring's centre.
      int best = torso_first;
      float best_d = INFINITY;
      for (int r = torso_first; r <= torso_last; ++r) {
        const RingPose& t = rings[static_cast<size_t>(r)];
        const float d = std::fabs((arm.centre - t.centre).dot(t.frame.col(1)));
        if (d < best_d) best_d = d, best = r;
      }
      const RingPose& t = rings[static_cast<size_t>(best)];
      const float along = (arm.centre - t.centre).dot(t.frame.col(1));
      if ((best == torso_last && along > 0.0f) || (best == torso_first && along < 0.0f)) continue;
      // In the torso ring's plane: the arm ring's centre seen from the torso's centre.
      const Vec3 out = (arm.centre - t.centre) - along * t.frame.col(1);
      const float dist = out.norm();
      if (!(dist > 1e-4f)) continue;  // on the spine: no direction to push in
      const Vec3 dir = out / dist;
      const float torso_r =
          armClearanceEllipseRadius(t.forward_m, t.side_m, dir.dot(t.frame.col(0)), dir.dot(t.frame.col(2)));
      // The arm ring's reach towards the torso: its ellipse in the direction of -dir, as seen in
      // its own plane (an arm along the spine has no such direction: left alone).
      float ax = -dir.dot(arm.frame.col(0)), az = -dir.dot(arm.frame.col(2));
      const float in_plane = std::sqrt(ax * ax + az * az);
      if (!(in_plane > 1e-3f)) continue;
      const float arm_r = armClearanceEllipseRadius(arm.forward_m, arm.side_m, ax / in_plane, az / in_plane);
      const float overlap = torso_r + arm_r + c.clearance_m - dist;
      if (!(overlap > 0.0f) || !std::isfinite(overlap)) continue;
      const Vec3 push = (c.weight * overlap) * dir;
      arm.centre += push;
      if (i == arm_count[side] - 1) shift[side] = push;
    }
  }
}

void keepArmsOutOfTorso(const BodyModel& layout, std::vector<RingPose>& rings, const ArmClearance& c,
                        Vec3 shift[2]) {
  const int first[2] = {layout.chainFirstRing(Chain::ArmL), layout.chainFirstRing(Chain::ArmR)};
  const int count[2] = {layout.chainRingCount(Chain::ArmL), layout.chainRingCount(Chain::ArmR)};
  keepArmsOutOfTorso(rings, layout.chainFirstRing(Chain::Torso), layout.chainRingCount(Chain::Torso), first, count,
                     c, shift);
}

}  // namespace drape
