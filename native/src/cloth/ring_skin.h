// Ring-space skinning: points bound to the body's ring segments and placed again on the same body
// in another pose or shape. A point is expressed in the section between two consecutive rings of
// a chain: x and z as fractions of the section's semi-axes (so it follows the girth), y along the
// chain in metres. Each point blends every segment nearly as near as its nearest one (weights
// exp(-(d - d_min) / blend)), so neighbours bound to different chains (armpit, crotch, neck) do
// not tear apart. Used to retarget OBJ garments onto a body (garment_obj.h) and by garments to
// place themselves on a body that jumped (first tracked frame, teleport). (A constraint keeping
// particles within a distance of where the body carries them was tried and not kept:
// docs/garments.md, "Openings".)
#pragma once

#include "body/body_model.h"
#include "common/math.h"

#include <cstdint>
#include <vector>

namespace drape {

struct RingBinding {
  int chain = 0, r0 = 0;         // segment between rings r0 and r0 + 1 of `chain`
  float t = 0.0f, dist = 0.0f;   // segment parameter; approximate distance to the body surface
  Vec3 local = Vec3::Zero();     // (x / a, y, z / b) in the section's frame
};

// The binding of p to segment (r0, r0 + 1), t clamped to the segment.
RingBinding bindToSegment(const std::vector<RingPose>& rings, int chain, int r0, const Vec3& p);
// Where a binding puts its point on `rings`.
Vec3 placeBinding(const std::vector<RingPose>& rings, const RingBinding& b);

class RingSkin {
 public:
  // Binds every point to `body` (updated with a pose). blend_m >= 0; 0 = nearest segment only.
  void bind(const BodyModel& body, const std::vector<Vec3>& points, float blend_m);
  // The same on `rings`, an earlier state of a body with `layout`'s ring layout (rings kept from
  // another shape or pose). rings.size() must be layout.rings().size().
  void bind(const BodyModel& layout, const std::vector<RingPose>& rings, const std::vector<Vec3>& points,
            float blend_m);
  // The points on `body` (same ring layout as at bind time). `out` is resized.
  void place(const BodyModel& body, std::vector<Vec3>& out) const;
  // Point i placed on `rings`.
  Vec3 place(const std::vector<RingPose>& rings, size_t i) const;
  const RingBinding& primary(size_t i) const { return primary_[i]; }
  const std::vector<RingBinding>& primaries() const { return primary_; }
  size_t size() const { return primary_.size(); }

 private:
  std::vector<RingBinding> primary_;  // nearest segment of each point
  std::vector<RingBinding> blend_;    // every blended binding, point by point
  std::vector<float> weight_;         // normalised weight of each blended binding
  std::vector<uint32_t> offset_{0};   // point i owns blend_[offset_[i] .. offset_[i + 1])
};

}  // namespace drape
