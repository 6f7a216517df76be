// Each kernel of the frame run on its own, for the per-kernel tests and the benchmark's
// per-stage split: host arrays in, host arrays out, one launch. Not used by the frame step
// (ClXpbdSolver runs every stage inside one launch). docs/opencl.md.
#pragma once

#include "backends/opencl/cl_runtime.h"
#include "drape_cl_types.h"
#include "proxies/collision.h"

#include <string>
#include <vector>

namespace drape {

// Wall-clock of a stage call, split (device profiling when the queue has it).
struct ClStageTimes {
  double upload_ns = 0.0, kernel_ns = 0.0, readback_ns = 0.0;
};

// EllipsoidCollider::collide on the device: `x` corrected in place against span 0 of `shapes`
// (count shapes, bounds = 2 float4), prev = span-start positions (same count as x), masks one
// per particle or empty (no groups). Returns false with err on a device failure.
bool clCollide(ClRuntime& rt, const std::vector<DrapeClShape>& shapes, const std::vector<DclF4>& bounds,
               const CollisionParams& params, const std::vector<uint8_t>& masks, std::vector<DclF4>& x,
               const std::vector<DclF4>& prev, CollisionStats& stats, std::string& err,
               ClStageTimes* times = nullptr);

// One colour group: constraints [begin, end) of `constraints` projected on x by `mode`
// (DCL_MODE_*: 0 distance; 1 tether, one-sided |d| <= rest * scale; 2 strain limit, the same
// inequality on both ends; a bool `tether` reads as 0 / 1), each with inv_w = 1 / (w_sum + alpha),
// alpha = compliance / h^2.
bool clProjectGroup(ClRuntime& rt, const std::vector<DrapeClConstraint>& constraints, uint32_t begin, uint32_t end,
                    uint32_t mode, float scale, float alpha, std::vector<DclF4>& x, std::string& err,
                    ClStageTimes* times = nullptr);

// Area-weighted unit vertex normals of x for the triangle list `indices` (vertexNormals).
bool clVertexNormals(ClRuntime& rt, const std::vector<DclF4>& x, const std::vector<uint32_t>& indices,
                     std::vector<DclF4>& normals, std::string& err, ClStageTimes* times = nullptr);

}  // namespace drape
