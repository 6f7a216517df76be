/* One garment's whole frame (every substep) in one work-group: the port of XpbdSolver::step
 * (native/src/cloth/xpbd_solver.cpp). Included twice by the host-assembled program, with
 * DCL_XS = __local (particles copied into local memory: they fit) and DCL_XS = __global
 * (in place in the batched particle buffer), defining DCL_FRAME_BODY under two names.
 * Work-item i handles particles i, i + size, ...: prediction, collision and the velocity update
 * touch only their own particle, so barriers are needed only around the constraint colour groups
 * (whose constraints share no particle) and the pin moves. */

void DCL_FRAME_BODY(__global const DrapeClGarment* g, DCL_XS float4* x, __global float4* prev,
                    __global float4* vel, __global float4* span_start, __global float4* pin_start,
                    __global const uint* pin_index, __global const float4* pin_target,
                    __global const DrapeClConstraint* constraints, __global const uint* groups,
                    __global const uchar* masks, __global const DrapeClShape* shapes,
                    __global const float4* span_bounds, __global DrapeClStats* stats_out) {
  const uint lid = get_local_id(0), lsize = get_local_size(0);
  const uint n = g->particle_count;
  const int substeps = g->substeps, stride = g->stride;
  const float h = g->h;
  const float4 hg = g->hg, wind = g->wind;
  const float max_speed2 = g->max_speed2;
  CollideCounters st = {0u, 0u, 0u, 0u};
  CollideSpan sp;
  sp.count = g->shape_count;
  sp.flags = g->flags;
  sp.static_friction = g->static_friction;
  sp.kinetic_friction = g->kinetic_friction;
  sp.max_escape = g->max_escape;

  for (uint k = lid; k < g->pin_count; k += lsize) pin_start[k] = x[pin_index[k]];
  barrier(CLK_LOCAL_MEM_FENCE | CLK_GLOBAL_MEM_FENCE);

  int span0 = 0, span = 0;
  for (int s = 0; s < substeps; ++s) {
    const bool collide = (s + 1 - span0) >= stride || s + 1 == substeps;
    const bool keep_span_start = stride > 1 && s == span0;
    /* 1. Predict (and remember where the collision span starts). */
    for (uint i = lid; i < n; i += lsize) {
      const float4 xi = x[i];
      if (keep_span_start) span_start[i] = xi;
      prev[i] = xi;
      if (xi.w == 0.0f) continue;
      float4 v = vel[i];
      v += hg + g->h_drag * (wind - v);
      if (max_speed2 > 0.0f) {
        const float s2 = dot(v, v);
        if (s2 > max_speed2) v *= g->max_speed / sqrt(s2);
      }
      vel[i] = v;
      x[i] = xi + h * v;
    }
    barrier(CLK_LOCAL_MEM_FENCE | CLK_GLOBAL_MEM_FENCE);
    /* Pinned particles follow their targets linearly across the step. */
    const float pin_t = s + 1 == substeps ? 1.0f : (float)(s + 1) * g->inv_n;
    for (uint k = lid; k < g->pin_count; k += lsize) {
      const float4 a = pin_start[k];
      const float4 b = pin_target[k];
      const uint p = pin_index[k];
      x[p] = (float4)(a.xyz + pin_t * (b.xyz - a.xyz), x[p].w);
    }
    barrier(CLK_LOCAL_MEM_FENCE | CLK_GLOBAL_MEM_FENCE);
    /* 2. Constraint passes: distance colour groups, then tethers (one-sided). In the frame's last
     * substep, before collision, the strain limit's passes follow (XpbdParams::strain_limit):
     * strain_passes passes over the stretch groups only (the last distance kind, from
     * kind_end[1]), each edge longer than rest * strain_scale pulled back to it, both ends moving,
     * and no tethers. `limit` is the same for the whole work-group. */
    const int passes = g->iterations + (s + 1 == substeps ? g->strain_passes : 0);
    for (int it = 0; it < passes; ++it) {
      const bool limit = it >= g->iterations;
      for (uint c = limit ? g->kind_end[1] : 0u; c < g->distance_groups; ++c) {
        const uint begin = groups[g->distance_group_offset + c];
        const uint end = groups[g->distance_group_offset + c + 1];
        const float alpha = dcl_group_alpha(g, c, 0u);
        for (uint k = begin + lid; k < end; k += lsize) {
          const DrapeClConstraint cst = constraints[k];
          float4 pa = x[cst.a], pb = x[cst.b];
          const float3 d = pa.xyz - pb.xyz;
          const float len2 = dot(d, d);
          if (!(len2 > 1e-18f)) continue;
          const float y = rsqrt(len2);
          const float inv_w = dcl_inv_w(cst.w_sum, alpha);
          const float sc = limit ? fmax(len2 * y - cst.rest * g->strain_scale, 0.0f) * y * inv_w
                                 : (1.0f - cst.rest * y) * inv_w;
          pa.xyz -= (pa.w * sc) * d;
          pb.xyz += (pb.w * sc) * d;
          x[cst.a] = pa;
          x[cst.b] = pb;
        }
        barrier(CLK_LOCAL_MEM_FENCE | CLK_GLOBAL_MEM_FENCE);
      }
      for (uint c = 0; !limit && c < g->tether_groups; ++c) {
        const uint begin = groups[g->tether_group_offset + c];
        const uint end = groups[g->tether_group_offset + c + 1];
        const float alpha = g->alpha[3];
        for (uint k = begin + lid; k < end; k += lsize) {
          const DrapeClConstraint cst = constraints[k];
          float4 pa = x[cst.a];
          const float3 d = pa.xyz - x[cst.b].xyz;
          const float len2 = dot(d, d);
          if (!(len2 > 1e-18f)) continue;
          const float y = rsqrt(len2);
          const float c_len = fmax(len2 * y - cst.rest * g->tether_scale, 0.0f);
          pa.xyz -= (pa.w * c_len * y * dcl_inv_w(cst.w_sum, alpha)) * d;
          x[cst.a] = pa;
        }
        barrier(CLK_LOCAL_MEM_FENCE | CLK_GLOBAL_MEM_FENCE);
      }
    }
    /* 3. Collision (this span's ellipsoids), 4. velocities from positions, damping, clamp. */
    if (collide) {
      sp.shapes = shapes + g->shape_offset + (uint)span * g->shape_count;
      sp.bound_min = span_bounds[2 * (g->span_offset + (uint)span)].xyz;
      sp.bound_max = span_bounds[2 * (g->span_offset + (uint)span) + 1].xyz;
    }
    for (uint i = lid; i < n; i += lsize) {
      float4 xi = x[i];
      const float4 pi = prev[i];
      if (collide && sp.count > 0u) {
        const float4 from = stride > 1 ? span_start[i] : pi;
        const uint mask = (g->flags & DRAPE_CL_GROUPED) ? (uint)masks[g->particle_offset + i] : 0xFFu;
        const float4 y = collide_particle(&sp, mask, xi, from, &st);
        if (any(y.xyz != xi.xyz)) {
          xi = y;
          x[i] = xi;
        }
      }
      float4 v = (xi - pi) * g->velocity_scale;
      if (max_speed2 > 0.0f) {
        const float s2 = dot(v, v);
        if (s2 > max_speed2) v *= g->max_speed / sqrt(s2);
      }
      vel[i] = v;
    }
    /* 3b. The rim edges (collideRims) after every particle's collision, colour by colour; the
     * particles they move get their velocity from where they end, as the CPU's update after them. */
    if (collide && sp.count > 0u && g->rim_groups > 0u) {
      barrier(CLK_LOCAL_MEM_FENCE | CLK_GLOBAL_MEM_FENCE);
      const bool grouped = (g->flags & DRAPE_CL_GROUPED) != 0u;
      for (uint c = 0; c < g->rim_groups; ++c) {
        const uint begin = groups[g->rim_group_offset + c], end = groups[g->rim_group_offset + c + 1u];
        for (uint k = begin + lid; k < end; k += lsize) {
          const DrapeClConstraint r = constraints[k];
          if (!(r.w_sum > 0.0f)) continue;  /* gated off (ClXpbdSolver::setRimGate) or both ends pinned */
          float4 pa = x[r.a], pb = x[r.b];
          const uint ma = grouped ? (uint)masks[g->particle_offset + r.a] : 0xFFu;
          const uint mb = grouped ? (uint)masks[g->particle_offset + r.b] : 0xFFu;
          if (!collide_rim(&sp, ma, mb, &pa, &pb, &st)) continue;
          x[r.a] = pa;
          x[r.b] = pb;
          vel[r.a] = dcl_velocity(g, pa, prev[r.a]);
          vel[r.b] = dcl_velocity(g, pb, prev[r.b]);
        }
        barrier(CLK_LOCAL_MEM_FENCE | CLK_GLOBAL_MEM_FENCE);
      }
    }
    if (collide) {
      span0 = s + 1;
      ++span;
    }
    barrier(CLK_LOCAL_MEM_FENCE | CLK_GLOBAL_MEM_FENCE);
  }
  if (st.tests) atomic_add(&stats_out->tests, st.tests);
  if (st.contacts) atomic_add(&stats_out->contacts, st.contacts);
  if (st.swept_catches) atomic_add(&stats_out->swept_catches, st.swept_catches);
  if (st.escapes) atomic_add(&stats_out->escapes, st.escapes);
}
