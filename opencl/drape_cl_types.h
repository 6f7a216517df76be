/* Structs shared by the host (C++, native/src/backends/opencl) and the kernels (OpenCL C 1.2).
 * Only 16-byte vectors (float4) and 4-byte scalars, in an order that needs no padding, so both
 * compilers lay them out identically (the host static_asserts the sizes): float3 is 16 bytes in
 * OpenCL and 12 in C++, so it never appears in a buffer. Each struct mirrors a CPU structure:
 * DrapeClShape = EllipsoidCollider's Shape + Quick (proxies/collision.h) for one collision span,
 * DrapeClGarment = one garment's slice of the batched buffers and its XpbdParams. */
#ifndef DRAPE_CL_TYPES_H
#define DRAPE_CL_TYPES_H

#ifdef __OPENCL_C_VERSION__
/* No fused multiply-adds: the CPU build (x86-64 without -mfma) rounds every product, and the
 * parity with it is closer when the device does too. */
#pragma OPENCL FP_CONTRACT OFF
typedef float4 dcl_f4;
typedef uint dcl_u32;
typedef int dcl_i32;
#else
#include <cstdint>
namespace drape {
struct alignas(16) DclF4 {
  float x, y, z, w;
};
}  // namespace drape
typedef drape::DclF4 dcl_f4;
typedef uint32_t dcl_u32;
typedef int32_t dcl_i32;
#endif

/* One ellipsoid of one collision span, inflated by the margin. Matrices are stored by column
 * (w = 0): q = to_unit * (p - centre), p = centre + from_unit * q, rot = the end rotation. */
typedef struct {
  dcl_f4 end_c, end_u0, end_u1, end_u2;        /* end centre, columns of S^-1 R^T */
  dcl_f4 end_f0, end_f1, end_f2;               /* columns of R S (end) */
  dcl_f4 start_c, start_u0, start_u1, start_u2;
  dcl_f4 start_f0, start_f1, start_f2;
  dcl_f4 rot0, rot1, rot2;                     /* end rotation columns */
  dcl_f4 radii;                                /* inflated end radii */
  dcl_f4 radii2;                               /* their squares */
  dcl_f4 swept_min, swept_max, end_min, end_max;
  float inside_tol2, graze;
  dcl_i32 smallest_axis;
  dcl_u32 group;                               /* collision-group bit(s); 0xFF without groups */
} DrapeClShape;

/* Flags of DrapeClGarment.flags. */
#define DRAPE_CL_CONTINUOUS 1u  /* swept test */
#define DRAPE_CL_EXACT 2u       /* exact closest point (else radial) */
#define DRAPE_CL_GROUPED 4u     /* per-particle masks against DrapeClShape.group */
#define DRAPE_CL_LOCAL 8u       /* particles fit in __local memory */

/* One garment in a batched launch: offsets into the shared buffers and this frame's step. */
typedef struct {
  dcl_f4 hg;                  /* h * gravity, w = 0 */
  dcl_f4 wind;                /* w = 0 */
  dcl_u32 particle_offset, particle_count;
  dcl_u32 distance_group_offset, distance_groups;  /* into the group table (constraint offsets) */
  dcl_u32 tether_group_offset, tether_groups;
  dcl_u32 pin_offset, pin_count;
  dcl_u32 shape_offset, shape_count;               /* this frame: spans x shape_count shapes */
  dcl_u32 span_offset, flags;                      /* span bounds: 2 float4 per span */
  dcl_i32 substeps, stride;
  dcl_i32 iterations;                              /* constraint passes per substep (>= 1) */
  dcl_i32 strain_passes;                           /* strain-limit passes in the last substep (0 = off) */
  float h, inv_n, h_drag, max_speed;
  float max_speed2, velocity_scale, tether_scale, static_friction;
  float kinetic_friction, max_escape;
  float strain_scale;         /* 1 + XpbdParams::strain_limit: the longest a stretch edge may end a step */
  float pad1;
  /* compliance / h^2 of this frame by constraint kind: alpha[0..2] the distance kinds in their
   * projection order (kDistanceKindOrder: shear, bend, stretch), alpha[3] the tethers. Kept out of
   * the constraints so that a new h (a Kinect's frame time varies every frame) changes 16 bytes
   * here instead of every constraint on the host and its upload. */
  float alpha[4];
  dcl_u32 kind_end[2];        /* distance group index where the first / second kind's colours end */
  dcl_u32 rim_group_offset;   /* into the group table: the rim edges' colours (GarmentTopology::rims) */
  dcl_u32 rim_groups;         /* 0: no rim edges collided (none, or CollisionParams::rims off) */
} DrapeClGarment;

/* A distance or tether constraint: a and b are particle indices within the garment; w_sum =
 * w_a + w_b (tethers: w_a, the anchor is pinned). The kernels project with inv_w = 1 / (w_sum +
 * alpha), alpha = compliance / h^2 of the constraint's kind this frame (DrapeClGarment.alpha),
 * and 0 when that sum is not positive (inert): the CPU solver's 1 / (w_a + w_b + alpha~). */
typedef struct {
  dcl_u32 a, b;
  float rest, w_sum;
} DrapeClConstraint;

/* The rigid carry of one garment in a batched drape_transform_batch launch: x -> R (x - pivot)
 * + shift, v -> vscale R v over particles [offset, offset + count) (R by columns). */
typedef struct {
  dcl_f4 r0, r1, r2, pivot, shift;
  float vscale;
  dcl_u32 offset, count, pad;
} DrapeClTransform;

/* Collision counters of one garment for the last frame (CollisionStats). */
typedef struct {
  dcl_u32 tests, contacts, swept_catches, escapes;
} DrapeClStats;

/* How dcl_project_one (kernels.cl) projects a constraint: an equality on both ends (distance),
 * the inequality |d| <= rest * scale on a only (tether: b is a pinned anchor), or the same
 * inequality on both ends (the strain limit over the stretch groups, XpbdParams::strain_limit). */
#define DCL_MODE_DISTANCE 0u
#define DCL_MODE_TETHER 1u
#define DCL_MODE_LIMIT 2u

#ifdef __OPENCL_C_VERSION__
/* Device helpers of the constraint record (xpbd_frame.cl, kernels.cl and phases.cl use them).
 * 1 / (w_a + w_b + alpha~) of a constraint for this frame's alpha~ = compliance / h^2 (0 when
 * not positive: inert), the CPU solver's inv_w (XpbdSolver, refreshed per step there) in the same
 * float operations; the program is built with -cl-fp32-correctly-rounded-divide-sqrt. */
inline float dcl_inv_w(float w_sum, float alpha) {
  const float w = w_sum + alpha;
  return w > 0.0f ? 1.0f / w : 0.0f;
}

/* A particle's velocity from where a substep leaves it (the CPU solver's update after the
 * collision): (x - prev) * velocity_scale, clamped to max_speed (w - w = 0). */
inline float4 dcl_velocity(__global const DrapeClGarment* g, float4 xi, float4 pi) {
  float4 v = (xi - pi) * g->velocity_scale;
  if (g->max_speed2 > 0.0f) {
    const float s2 = dot(v, v);
    if (s2 > g->max_speed2) v *= g->max_speed / sqrt(s2);
  }
  return v;
}

/* The alpha~ of distance colour group `group` (or of the tethers) of garment g: the distance
 * groups run kind by kind in projection order, kind_end[] where each of the first two ends. */
inline float dcl_group_alpha(__global const DrapeClGarment* g, uint group, uint tether) {
  if (tether) return g->alpha[3];
  return group < g->kind_end[0] ? g->alpha[0] : group < g->kind_end[1] ? g->alpha[1] : g->alpha[2];
}
#endif

#endif /* DRAPE_CL_TYPES_H */
