// A garment's openings (the loops of its boundary: hem, collar, sleeve cuffs, trouser legs) and
// the body parts each goes round, so a measurement can tell when one no longer does: a sleeve the
// arm has left, a collar off the neck. Stretch and penetration do not see that failure (a sleeve
// lying empty on the shoulder is neither stretched nor inside the body), pictures do.
//
// A body part is the polyline through a chain's ring centres (body/body_model.h); the spine runs
// through the torso's and then the head's rings, and on below the pelvis ring (kSpineExtensionM,
// away from the waist ring) so that a hem below the hips still goes round it; legs start inside
// the pelvis (kLegExtensionM); arms start at the shoulder, not extended (a sleeve that slides off
// the shoulder end is off). Every part ends at its tip, the body mesh's apex beyond the last ring
// (crown, fingertips, toes): a cuff round the wrist or the hand, the fingers through it, is on; one
// past the fingertips is off. How much an opening goes round a polyline is their Gauss linking
// integral: +-1 for a loop round a line that runs far on both sides, whatever the loop's shape (a
// crumpled trouser hem round an ankle too), +-1/2 when the loop's centre is at the polyline's
// end, 0 for a loop beside it. At bind time (the dressed garment on the rest body) every opening
// records the body part it goes round most (|linking| >= kBindLinking; a T-shirt's hem goes round
// the spine and both legs, the spine most); count() says how many openings are off theirs now:
// linking of the same sign below kOffLinking, i.e. the loop has slid past the polyline's end or
// the body part has left it through the cloth. Openings no polyline goes through at rest are not
// tracked (a cut that never went round anything cannot come off it).
#pragma once

#include "body/body_model.h"
#include "common/math.h"

#include <cstdint>
#include <vector>

namespace drape {

// Gauss linking integral of the closed loop (last vertex joined to the first) and the open
// polyline: the change of the loop's solid angle along the polyline, over 4 pi (computed over a
// fan spanning the loop: garment_openings.cpp).
float loopLinking(const std::vector<Vec3>& loop, const std::vector<Vec3>& polyline);

struct OpeningCount {
  uint32_t tracked = 0;  // openings round a body part at rest
  uint32_t off = 0;      // of those, the ones off it now
};

class GarmentOpenings {
 public:
  // Below the pelvis ring, the spine goes on this far (metres) for hems below the hips.
  static constexpr float kSpineExtensionM = 0.5f;
  // An opening goes round a body part at rest from this much linking, and is off it below
  // kOffLinking (same sign): its centre past the polyline's end, or the part out through the cloth.
  static constexpr float kBindLinking = 0.75f;
  static constexpr float kOffLinking = 0.5f;
  // A leg starts this far above its thigh ring, in the pelvis: a hem round both legs at the hips
  // (a T-shirt's, a skirt's) stays round them when the thigh ring moves past it.
  static constexpr float kLegExtensionM = 0.15f;

  // The openings of `triangles` (boundaryLoops, cloth/garment_topology.h) and the body part each
  // goes round with the garment at `positions` on `body_rest` (a BodyModel updated with its rest
  // pose).
  void bind(const std::vector<uint32_t>& triangles, const std::vector<Vec3>& positions, const BodyModel& body_rest);
  // The same count for positions now (xyz of x[0 .. n)) on `body` (the same ring layout).
  OpeningCount count(const Eigen::Vector4f* x, size_t n, const BodyModel& body) const;

  // on[i] = 1 for the particles of the openings round a limb (an arm or a leg) that go round it now
  // (as count(): linking of the same sign at least kOffLinking), 0 for the rest (openings off, the
  // spine's openings, loops not tracked, interior particles). The rim gate (GarmentSim): a rim keeps
  // a limb in, not out; only a limb is thin enough to slip between two rim particles, and the
  // spine's hem and collar are the largest loops to test (docs/collision.md, "Rim edges").
  void markOn(const Eigen::Vector4f* x, size_t n, const BodyModel& body, std::vector<uint8_t>& on) const;

  // The body-part polylines (spine, arms, legs) of `body`: see the file comment.
  static std::vector<std::vector<Vec3>> bodyPolylines(const BodyModel& body);
  // The same into `out`, reusing its vectors' storage.
  static void bodyPolylines(const BodyModel& body, std::vector<std::vector<Vec3>>& out);

 private:
  struct Opening {
    std::vector<uint32_t> loop;  // particle indices round the loop
    uint32_t part;               // index into bodyPolylines()
    int sign;                    // of the linking at rest
  };
  std::vector<Opening> openings_;  // the tracked ones only
  mutable std::vector<std::vector<Vec3>> parts_scratch_;  // count's and markOn's, kept between calls
  mutable std::vector<Vec3> loop_scratch_;
  // f(opening, on) for every tracked opening (limbs_only: those round an arm or a leg), on = round
  // its body part (parts[opening.part]) now (count's test).
  template <class F>
  void forEachOn(const Eigen::Vector4f* x, size_t n, const std::vector<std::vector<Vec3>>& parts, F&& f,
                 bool limbs_only = false) const;
};

}  // namespace drape
