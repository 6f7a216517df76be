// Pass 0 of the collider for a batch of consecutive particles at once, chosen at run time:
// eight lanes with AVX (CollisionParams::batch8) and sixteen with AVX-512F (batch16 too). One
// body, collision_batch.inc, compiled once per width. docs/collision.md, "Eight particles at once"
// and "Sixteen particles at once".
#include "proxies/collision_internal.h"
#include "proxies/collision_lanes.h"

#include "common/cpu.h"

#include <algorithm>
#include <cstring>
#include <limits>

namespace drape {
using namespace collision_internal;

#if DRAPE_COLLISION_AVX
using collision_lanes::orCells;

#define DRAPE_BATCH_LANES collision_lanes::lanes8
#define DRAPE_BATCH_TARGET DRAPE_LANES8_TARGET
#define DRAPE_BATCH_CPU cpuHasAvx
#define DRAPE_BATCH_COLLIDE collideEights
#define DRAPE_BATCH_SETTLE settleEight
#define DRAPE_BATCH_EXACT exactContactsEight
#include "proxies/collision_batch.inc"

#if !defined(__clang__)
// GCC 12's AVX-512 intrinsics pass _mm512_undefined_ps() (a self-initialised variable) as the
// unused merge source, and -Wuninitialized reports it where they are inlined: a known false positive.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#define DRAPE_BATCH_LANES collision_lanes::lanes16
#define DRAPE_BATCH_TARGET DRAPE_LANES16_TARGET
#define DRAPE_BATCH_CPU cpuHasAvx512
#define DRAPE_BATCH_COLLIDE collideSixteens
#define DRAPE_BATCH_SETTLE settleSixteen
#define DRAPE_BATCH_EXACT exactContactsSixteen
#include "proxies/collision_batch.inc"
#if !defined(__clang__)
#pragma GCC diagnostic pop
#endif

#else
// No AVX on this target: collide() runs one particle at a time.
size_t EllipsoidCollider::collideEights(Eigen::Vector4f*, const Eigen::Vector4f*, size_t first, size_t,
                                        const CollisionParams&, bool, CollisionStats&) const {
  return first;
}
size_t EllipsoidCollider::collideSixteens(Eigen::Vector4f*, const Eigen::Vector4f*, size_t first, size_t,
                                          const CollisionParams&, bool, CollisionStats&) const {
  return first;
}
#endif

}  // namespace drape
