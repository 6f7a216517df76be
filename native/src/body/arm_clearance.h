// Arms kept out of the torso (docs/body-model.md, "Arms clear of the torso").
//
// The rings are centred on the bones, and a Kinect puts the shoulder joints close to the spine:
// with the arms down, the upper arm's tube then runs up to 3-5 cm inside the torso's on the
// shared takes (Ges01: in every frame; CMU's shoulders sit deeper still). Cloth between arm and
// torso can be outside neither, so the body mesh itself forced garment vertices deep into it, and
// the sleeve and the torso cloth, each colliding with its own part, were squeezed against each
// other. This moves each arm ring that would enter the torso straight out of it, in the torso
// ring's plane, until the two ellipses keep `clearance_m` between them; rings beside the neck
// (above the torso's top ring) or below the torso's bottom ring stay on their bones.
#pragma once

#include "body/body_model.h"

namespace drape {

struct ArmClearance {
  float clearance_m = kDefaultArmTorsoClearanceM;  // between an arm ring and the torso ring beside it
  float weight = 1.0f;  // the share of each push applied, [0, 1] (a pose path fades it in)
};

// rings: every ring of the body (chain order); torso / arms: first ring and count of each chain.
// shift[0], shift[1]: what the left / right arm's last ring moved (its hand apex follows it).
void keepArmsOutOfTorso(std::vector<RingPose>& rings, int torso_first, int torso_count, const int arm_first[2],
                        const int arm_count[2], const ArmClearance& c, Vec3 shift[2]);
// The same with the chains where `layout` has them (rings: that model's, or a copy of them).
void keepArmsOutOfTorso(const BodyModel& layout, std::vector<RingPose>& rings, const ArmClearance& c,
                        Vec3 shift[2]);

}  // namespace drape
