// Host side of the device collision: the collider's per-span shapes packed for the kernels.
// A frame's collision spans (collision every `stride` substeps and on the last, as
// XpbdSolver::step) get their start/end ellipsoids interpolated here exactly as ColliderMotion
// does on the CPU, inflated and packed as EllipsoidCollider::setEllipsoids builds its Shape, so
// the whole frame's ellipsoids go to the device in one upload. docs/opencl.md.
#pragma once

#include "drape_cl_types.h"
#include "proxies/ellipsoid.h"

#include <cstdint>
#include <vector>

namespace drape {

static_assert(sizeof(DrapeClShape) == 24 * 16, "DrapeClShape layout differs from the kernels'");
static_assert(sizeof(DrapeClGarment) == 11 * 16, "DrapeClGarment layout differs from the kernels'");
static_assert(sizeof(DrapeClConstraint) == 16, "DrapeClConstraint layout differs from the kernels'");
static_assert(sizeof(DrapeClTransform) == 6 * 16, "DrapeClTransform layout differs from the kernels'");

// The substeps (exclusive ends) at which a frame of `substeps` collides: every `stride`, and the
// last. As XpbdSolver::step.
std::vector<int> collisionSpanEnds(int substeps, int stride);

// One shape from the span's start and end ellipsoids (EllipsoidCollider::setEllipsoids).
// Returns false for a shape that can never match (non-finite boxes): it is then packed with empty
// boxes, as the CPU does.
bool packShape(const Ellipsoid& start, const Ellipsoid& end, float margin, uint32_t group, DrapeClShape& out);

// Every span of a frame: shapes[span * count + k] and bounds[2 * span] (min), [2 * span + 1]
// (max) = the union of the span's valid swept boxes. groups: one bit per ellipsoid, or empty.
void packFrameShapes(const Ellipsoid* start, const Ellipsoid* end, int count, float margin,
                     const std::vector<uint8_t>& groups, int substeps, int stride,
                     std::vector<DrapeClShape>& shapes, std::vector<DclF4>& bounds);

}  // namespace drape
