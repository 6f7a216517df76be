// Cloth particles against the body's triangle mesh — the collision the paper's ellipsoids replace
// (§3.3: testing every particle against every body triangle is O(n·m)). Drape's cloth collides
// with ellipsoids; this exists only so that choice can be measured (docs/body-mesh-collision.md).
//
// Response: a movable particle (w > 0) whose signed distance to the mesh is below margin_m is
// moved to c + n·margin_m, with c its closest point on the mesh and n the angle-weighted
// pseudo-normal of the feature c lies on (proxies/mesh_bvh.h), i.e. to the offset surface, inside
// particles included. At a concave feature (armpit, crotch, the stitch between two rings that
// meet at an angle) one such step can land closer than margin_m to a neighbouring face, so the
// step is repeated, at most kMeshCollisionPasses times per particle, each checked by a new query,
// until the particle is at least margin_m outside. Where two parts of the body are closer than
// 2·margin_m no position between them satisfies both: the projections alternate between the two
// walls (and can overshoot through a gap narrower than margin_m into the opposite wall), so the
// particle ends at the best position seen (largest signed distance, the start included).
// Where the mesh intersects itself (body: shoulder stitch, crotch bridge) the closest point can lie
// on surface buried inside another part, and the projection cannot get the particle out; see
// docs/body-mesh-collision.md for how often either happens.
// Particles with w <= 0 (pinned) or a non-finite position are left alone.
#pragma once

#include "proxies/mesh_bvh.h"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>

namespace drape {

constexpr int kMeshCollisionPasses = 4;

struct MeshCollisionStats {
  uint32_t contacts = 0;  // particles found closer than the margin (or inside)
  uint32_t passes = 0;    // projections computed, summed over particles (>= contacts)
};

// Closest-point queries through the BVH: O(n log m) in practice.
MeshCollisionStats collideWithMesh(const TriangleBvh& mesh, Eigen::Vector4f* positions,
                                   size_t count, float margin_m);

// The same response, every particle tested against every triangle (the BVH's corner copies and
// pseudo-normals, no tree): the O(n·m) baseline.
MeshCollisionStats collideWithMeshBruteForce(const TriangleBvh& mesh, Eigen::Vector4f* positions,
                                             size_t count, float margin_m);

}  // namespace drape
