// Shoulder seams that follow the shoulders. A template top hangs from pins on its collar (the
// neck's ring) and on the tops of its shoulder seams, which follow the torso's top ring. A tracked
// shoulder joint moves against that ring: it rises when the arm goes up (on Ges01_wavehand the
// waving arm's by 10 cm). With the seam pins left where the torso ring puts them, the arm's root
// came up through the armhole, the sleeve slid down the raised arm past the shoulder, and when the
// arm came down it was outside the sleeve for the rest of the take (docs/garments.md, "Shoulder
// seams follow the shoulders"). So each seam pin also moves by how far its shoulder (the centre of
// the arm's junction ring, in the top ring's frame) has moved from where it sat while that arm
// hung: its mean over the first second of hanging-arm frames after the garment was placed.
//
// A dress too, though its waist pins keep the bodice from riding up (its P99 stretch on Ges01 8.6
// -> 13.9 %): over 24 runs its frames with a sleeve off fell in 15 and rose in none.
#pragma once

#include "body/body_model.h"
#include "common/math.h"

#include <cstdint>
#include <vector>

namespace drape {

class ShoulderSeams {
 public:
  // How long an arm must have hung (seconds) before its shoulder's place is known, and what
  // hanging means: the upper arm within this cosine of straight down along the torso.
  static constexpr float kBaselineS = 1.0f;
  static constexpr float kHangingCos = 0.866f;  // 30 degrees

  // pinned / pin_ring: the garment's attachments. The pins on the torso's top ring follow the
  // nearer arm's shoulder on `body_rest` (skirts and trousers have none there).
  void bind(const BodyModel& body_rest, const std::vector<Vec3>& positions, const std::vector<uint32_t>& pinned,
            const std::vector<int>& pin_ring);
  // The garment was placed on the body anew: where the shoulders sit is measured again.
  void restart();
  // A step of dt seconds on `body`: while an arm hangs, its shoulder's place is averaged in.
  void observe(const BodyModel& body, float dt);
  // Adds each following pin's shoulder motion to its target (one target per pin, as bound).
  void shift(const BodyModel& body, std::vector<Vec3>& targets) const;

  bool active() const { return !pin_side_.empty(); }

 private:
  struct Side {
    int junction = -1;  // the arm's first ring (at the shoulder joint)
    int upper = -1;     // a ring down the upper arm: with the junction, the arm's direction
    Vec3 sum = Vec3::Zero();  // dt-weighted sum of the shoulder's place (top ring frame)
    float seconds = 0.0f;
  };
  Vec3 shoulderIn(const BodyModel& body, const Side& s) const;
  bool hangs(const BodyModel& body, const Side& s) const;

  int top_ = -1;                // the torso's top ring
  Side side_[2];                // left arm, right arm
  std::vector<int8_t> pin_side_;  // per pin: 0 or 1 (side_), -1 for pins that do not follow
};

}  // namespace drape
