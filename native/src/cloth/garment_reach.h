// Which tracking ellipsoids a garment can reach (proxy culling, docs/adaptive.md).
//
// A garment hangs from attachments on body rings (a waistband, a collar). A particle can get no
// farther from its attachment than the length of cloth between them: the geodesic distance over
// the mesh's edges at rest, times a stretch allowance (tethers hold a particle within 1.1 x its
// rest distance; the allowance covers that and the stretch measured on the shared takes). So
// everything the garment can touch lies in spheres around the rings it is attached to, one per
// (ring, collision mask) pair, with the radius of the farthest particle of that mask plus a margin
// that covers one frame of body motion. An ellipsoid is reachable when its chain is in the mask
// and its bounding sphere meets the sphere. The spheres are computed once per garment (they depend
// on the cut, not the pose); the test runs every frame on the current rings, because a raised knee
// brings the shin within reach of a skirt that cannot reach it standing.
//
// A particle with no path to an attachment (an unattached garment, a loose piece) can go anywhere:
// it gets a sphere with ring -1 that reaches every ellipsoid of its mask.
#pragma once

#include "body/body_model.h"
#include "proxies/ellipsoid.h"
#include "proxies/proxy_builder.h"

#include <cstdint>
#include <vector>

namespace drape {

class GarmentSim;

struct ReachSphere {
  int ring = -1;         // body ring the sphere is centred on; -1: unbounded
  uint8_t groups = 0;    // collision groups (bit = Chain) its particles collide with
  float radius_m = 0.0f; // around the ring's centre
};

struct ReachParams {
  float stretch_allowance = 1.1f;   // geodesic rest distance x this bounds a particle's distance
  float margin_m = 0.1f;            // plus this (body motion in one frame, cloth thickness)
};

// The garment's reach spheres (see above). Never empty for a garment with particles.
std::vector<ReachSphere> garmentReach(const GarmentSim& garment, const ReachParams& params);

// Radius of a sphere around each ellipsoid's source ring centre that holds the ellipsoid, from
// ellipsoids built on `body` (the rest body), scaled up by `scale` and `pad_m` so it still holds
// on a tracked body whose bones are up to that much longer.
std::vector<float> ellipsoidBoundRadii(const BodyModel& body, const std::vector<Ellipsoid>& ellipsoids,
                                       const std::vector<ProxySource>& sources, float scale = 1.15f,
                                       float pad_m = 0.02f);

// Sets reach[k] = 1 for every ellipsoid k the spheres reach on the current rings (others are left
// as they are, so several garments can mark one array). rings: the body's current ring poses.
void markReachable(const std::vector<ReachSphere>& spheres, const std::vector<RingPose>& rings,
                   const std::vector<ProxySource>& sources, const std::vector<float>& bound_radii,
                   std::vector<uint8_t>& reach);

}  // namespace drape
