/* Entry points. The host assembles the program as: drape_cl_types.h, closest_point.cl,
 * collide.cl, xpbd_frame.cl twice (local / global particles), this file, phases.cl (the
 * per-phase kernels of large garments); with -D
 * DRAPE_CL_MAX_LOCAL_PARTICLES (the __local capacity the host sized) and
 * DRAPE_CL_WORK_GROUP (the work-group size the kernels are launched with). */

#ifndef DRAPE_CL_MAX_LOCAL_PARTICLES
#error "the host defines DRAPE_CL_MAX_LOCAL_PARTICLES"
#endif

/* A frame of every garment in the batch: work-group g runs garment g's substeps. */
__kernel __attribute__((reqd_work_group_size(DRAPE_CL_WORK_GROUP, 1, 1)))
void drape_xpbd_frame(__global const DrapeClGarment* garments, __global float4* x,
                      __global float4* prev, __global float4* vel, __global float4* span_start,
                      __global float4* pin_start, __global const uint* pin_index,
                      __global const float4* pin_target,
                      __global const DrapeClConstraint* constraints, __global const uint* groups,
                      __global const uchar* masks, __global const DrapeClShape* shapes,
                      __global const float4* span_bounds, __global DrapeClStats* stats) {
  __local float4 local_x[DRAPE_CL_MAX_LOCAL_PARTICLES];
  const uint gid = get_group_id(0);
  __global const DrapeClGarment* g = garments + gid;
  const uint o = g->particle_offset, n = g->particle_count;
  const uint lid = get_local_id(0), lsize = get_local_size(0);
  __global DrapeClStats* st = stats + gid;
  if (lid == 0) {
    st->tests = 0u;
    st->contacts = 0u;
    st->swept_catches = 0u;
    st->escapes = 0u;
  }
  barrier(CLK_GLOBAL_MEM_FENCE);
  if (g->flags & DRAPE_CL_LOCAL) {
    for (uint i = lid; i < n; i += lsize) local_x[i] = x[o + i];
    barrier(CLK_LOCAL_MEM_FENCE);
    drape_frame_local(g, local_x, prev + o, vel + o, span_start + o, pin_start + g->pin_offset,
                      pin_index + g->pin_offset, pin_target + g->pin_offset, constraints, groups,
                      masks, shapes, span_bounds, st);
    barrier(CLK_LOCAL_MEM_FENCE);
    for (uint i = lid; i < n; i += lsize) x[o + i] = local_x[i];
  } else {
    drape_frame_global(g, x + o, prev + o, vel + o, span_start + o, pin_start + g->pin_offset,
                       pin_index + g->pin_offset, pin_target + g->pin_offset, constraints, groups,
                       masks, shapes, span_bounds, st);
  }
}

/* Collision alone (tests and the benchmark's per-stage split): particle i of `count` against
 * the shapes of span 0 of garment 0; prev = span start positions. */
__kernel void drape_collide(__global const DrapeClGarment* g, __global float4* x,
                            __global const float4* prev, __global const uchar* masks,
                            __global const DrapeClShape* shapes, __global const float4* span_bounds,
                            uint count, __global DrapeClStats* stats) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  CollideSpan sp;
  sp.shapes = shapes + g->shape_offset;
  sp.count = g->shape_count;
  sp.flags = g->flags;
  sp.bound_min = span_bounds[2 * g->span_offset].xyz;
  sp.bound_max = span_bounds[2 * g->span_offset + 1].xyz;
  sp.static_friction = g->static_friction;
  sp.kinetic_friction = g->kinetic_friction;
  sp.max_escape = g->max_escape;
  CollideCounters st = {0u, 0u, 0u, 0u};
  const uint mask = (g->flags & DRAPE_CL_GROUPED) ? (uint)masks[i] : 0xFFu;
  x[i] = collide_particle(&sp, mask, x[i], prev[i], &st);
  if (st.tests) atomic_add(&stats->tests, st.tests);
  if (st.contacts) atomic_add(&stats->contacts, st.contacts);
  if (st.swept_catches) atomic_add(&stats->swept_catches, st.swept_catches);
  if (st.escapes) atomic_add(&stats->escapes, st.escapes);
}

/* One constraint projected in place in x, by `mode` (DCL_MODE_*, drape_cl_types.h): a distance
 * constraint (both ends move), a tether (one-sided: only a moves, and only when stretched past
 * rest * scale) or the strain limit (the tether's inequality, both ends moving). The Gauss-Seidel
 * step of the per-phase path (drape_phase_project, phases.cl) and of the per-kernel stage below. */
inline void dcl_project_one(__global float4* x, const DrapeClConstraint c, uint mode, float scale,
                            float alpha) {
  float4 pa = x[c.a], pb = x[c.b];
  const float3 d = pa.xyz - pb.xyz;
  const float len2 = dot(d, d);
  if (!(len2 > 1e-18f)) return;
  const float y = rsqrt(len2);
  const float inv_w = dcl_inv_w(c.w_sum, alpha);
  if (mode == DCL_MODE_TETHER) {
    const float c_len = fmax(len2 * y - c.rest * scale, 0.0f);
    pa.xyz -= (pa.w * c_len * y * inv_w) * d;
    x[c.a] = pa;
    return;
  }
  const float s = mode == DCL_MODE_LIMIT ? fmax(len2 * y - c.rest * scale, 0.0f) * y * inv_w
                                         : (1.0f - c.rest * y) * inv_w;
  pa.xyz -= (pa.w * s) * d;
  pb.xyz += (pb.w * s) * d;
  x[c.a] = pa;
  x[c.b] = pb;
}

/* One constraint colour group (tests): constraints [begin, end), one work-item each, projected
 * by `mode` (DCL_MODE_*) with `scale` (tether / strain limit), alpha~ as dcl_inv_w takes it. */
__kernel void drape_project_group(__global float4* x, __global const DrapeClConstraint* constraints,
                                  uint begin, uint end, uint mode, float scale, float alpha) {
  const uint k = begin + get_global_id(0);
  if (k >= end) return;
  dcl_project_one(x, constraints[k], mode, scale, alpha);
}

/* Area-weighted unit vertex normals (vertexNormals in body/mesh_metrics.cpp) without atomics:
 * vertex i sums the face normals of the triangles listed in vertex_faces[face_offsets[i] ..
 * face_offsets[i + 1]) (ascending, as the CPU's accumulation order), into normals[out_offset +
 * i]. The frame passes its particle buffer as both x and normals (positions in [0, count),
 * normals in [count, 2 count): disjoint), so one readback brings both back. */
__kernel void drape_vertex_normals(__global const float4* x, __global const uint* indices,
                                   __global const uint* face_offsets,
                                   __global const uint* vertex_faces, uint count,
                                   __global float4* normals, uint out_offset) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  float3 n = (float3)(0.0f);
  for (uint k = face_offsets[i]; k < face_offsets[i + 1]; ++k) {
    const uint t = vertex_faces[k];
    const float3 a = x[indices[3 * t]].xyz, b = x[indices[3 * t + 1]].xyz,
                 c = x[indices[3 * t + 2]].xyz;
    n += cross(b - a, c - a);
  }
  const float len = length(n);
  normals[out_offset + i] =
      len > 1e-20f ? (float4)(n / len, 0.0f) : (float4)(0.0f, 1.0f, 0.0f, 0.0f);
}

/* XpbdSolver::transform on the device state: x -> R (x - pivot) + shift, v -> vscale R v
 * (R by columns), so carrying a garment with the body costs a launch and no transfer. */
__kernel void drape_transform(__global float4* x, __global float4* v, uint count, float4 r0,
                              float4 r1, float4 r2, float4 pivot, float4 shift, float vscale) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  const float4 p = x[i];
  const float3 d = p.xyz - pivot.xyz;
  x[i] = (float4)(r0.xyz * d.x + r1.xyz * d.y + r2.xyz * d.z + shift.xyz, p.w);
  const float3 u = v[i].xyz;
  v[i] = (float4)(vscale * (r0.xyz * u.x + r1.xyz * u.y + r2.xyz * u.z), 0.0f);
}

/* drape_transform for every garment of a batch (work-group g = table entry g), the same
 * arithmetic per particle, so batched and lone garments move the same bits. */
__kernel void drape_transform_batch(__global float4* x, __global float4* v,
                                    __global const DrapeClTransform* table) {
  __global const DrapeClTransform* m = table + get_group_id(0);
  const float4 r0 = m->r0, r1 = m->r1, r2 = m->r2, pivot = m->pivot, shift = m->shift;
  const float vscale = m->vscale;
  for (uint k = get_local_id(0); k < m->count; k += get_local_size(0)) {
    const uint i = m->offset + k;
    const float4 p = x[i];
    const float3 d = p.xyz - pivot.xyz;
    x[i] = (float4)(r0.xyz * d.x + r1.xyz * d.y + r2.xyz * d.z + shift.xyz, p.w);
    const float3 u = v[i].xyz;
    v[i] = (float4)(vscale * (r0.xyz * u.x + r1.xyz * u.y + r2.xyz * u.z), 0.0f);
  }
}
