/* Large garments: the frame of drape_xpbd_frame as one launch per phase over global memory,
 * one work-item per particle (or pin, or constraint), so every compute unit takes part. Every
 * kernel takes the garment table, so one launch runs the phase for every per-phase garment of
 * a batch (one garment alone is a table of one: the same kernels, the same bits).
 *
 * `work` holds rows of count + 1 entries, each the exclusive prefix of per-garment item counts
 * (the host builds it, ClPhasePlan): row 0 particles, row 1 pins, then one row per distance
 * colour group index, then one per tether group index. Work-item i of a launch over row r
 * belongs to the last garment g with start[g] <= i (garments with nothing in the row have an
 * empty range and are never picked). Garments differ in substeps, iterations, collision stride
 * and colour-group counts: the host launches up to the largest, and a garment past its own
 * substeps or iterations returns at once.
 *
 * Per substep s: drape_phase_predict, drape_phase_pins, per iteration one drape_phase_project
 * per distance group index then per tether group index; after a substep that is some garment's
 * last, the strain limit's passes (one launch per stretch group index, each garment taking part
 * only in its own last substep); drape_phase_collide_velocity. The
 * arithmetic per particle is the frame kernel's (xpbd_frame.cl), in the same order. */

#define DCL_ROW_PARTICLES 0u
#define DCL_ROW_PINS 1u

/* The garment owning item i of a row (i < start[count]). */
uint dcl_owner(__global const uint* start, uint count, uint i) {
  uint lo = 0u, hi = count;
  while (hi - lo > 1u) {
    const uint mid = (lo + hi) / 2u;
    if (start[mid] <= i)
      lo = mid;
    else
      hi = mid;
  }
  return lo;
}

/* This work-item's item of row `row` of `work`: its garment `*gi` and its index `*j` among that
 * garment's items. False for the work-items past the row's last item (launches are rounded up). */
bool dcl_item(__global const uint* work, uint count, uint row, uint* gi, uint* j) {
  const uint i = get_global_id(0);
  __global const uint* start = work + row * (count + 1u);
  if (i >= start[count]) return false;
  *gi = dcl_owner(start, count, i);
  *j = i - start[*gi];
  return true;
}

/* The first substep of the collision span holding substep s (spans of `stride` substeps, the
 * last one ending with the frame), as the frame kernel's span0 / span counters. */
int dcl_span_of(int s, int stride) { return s / (stride > 0 ? stride : 1); }

/* Garment g's collision span `span` (its shapes, bounds and contact parameters). */
CollideSpan dcl_collide_span(__global const DrapeClGarment* g, int span, __global const DrapeClShape* shapes,
                             __global const float4* span_bounds) {
  CollideSpan sp;
  sp.shapes = shapes + g->shape_offset + (uint)span * g->shape_count;
  sp.count = g->shape_count;
  sp.flags = g->flags;
  sp.bound_min = span_bounds[2 * (g->span_offset + (uint)span)].xyz;
  sp.bound_max = span_bounds[2 * (g->span_offset + (uint)span) + 1].xyz;
  sp.static_friction = g->static_friction;
  sp.kinetic_friction = g->kinetic_friction;
  sp.max_escape = g->max_escape;
  return sp;
}

/* The per-phase garments' counters (the others' belong to the frame kernel of the batch). */
__kernel void drape_phase_clear_stats(__global DrapeClStats* stats, uint count,
                                      __global const uint* work) {
  const uint g = get_global_id(0);
  if (g >= count || work[DCL_ROW_PARTICLES * (count + 1u) + g + 1u] ==
                        work[DCL_ROW_PARTICLES * (count + 1u) + g])
    return;
  stats[g].tests = 0u;
  stats[g].contacts = 0u;
  stats[g].swept_catches = 0u;
  stats[g].escapes = 0u;
}

/* Where each pinned particle starts the frame (the pins move linearly from there). */
__kernel void drape_phase_pin_start(__global const DrapeClGarment* table, uint count,
                                    __global const uint* work, __global const float4* x,
                                    __global float4* pin_start, __global const uint* pin_index) {
  uint gi, j;
  if (!dcl_item(work, count, DCL_ROW_PINS, &gi, &j)) return;
  __global const DrapeClGarment* g = table + gi;
  const uint k = g->pin_offset + j;
  pin_start[k] = x[g->particle_offset + pin_index[k]];
}

__kernel void drape_phase_predict(__global const DrapeClGarment* table, uint count,
                                  __global const uint* work, __global float4* x,
                                  __global float4* prev, __global float4* vel,
                                  __global float4* span_start, int substep) {
  uint gi, j;
  if (!dcl_item(work, count, DCL_ROW_PARTICLES, &gi, &j)) return;
  __global const DrapeClGarment* g = table + gi;
  if (substep >= g->substeps) return;
  const int stride = g->stride;
  const bool keep_span_start = stride > 1 && substep == dcl_span_of(substep, stride) * stride;
  const uint p = g->particle_offset + j;
  const float4 xi = x[p];
  if (keep_span_start) span_start[p] = xi;
  prev[p] = xi;
  if (xi.w == 0.0f) return;
  float4 v = vel[p];
  v += g->hg + g->h_drag * (g->wind - v);
  if (g->max_speed2 > 0.0f) {
    const float s2 = dot(v, v);
    if (s2 > g->max_speed2) v *= g->max_speed / sqrt(s2);
  }
  vel[p] = v;
  x[p] = xi + g->h * v;
}

/* Pinned particles at substep `substep` (pin_start taken by drape_phase_pin_start). */
__kernel void drape_phase_pins(__global const DrapeClGarment* table, uint count,
                               __global const uint* work, __global float4* x,
                               __global const float4* pin_start, __global const uint* pin_index,
                               __global const float4* pin_target, int substep) {
  uint gi, j;
  if (!dcl_item(work, count, DCL_ROW_PINS, &gi, &j)) return;
  __global const DrapeClGarment* g = table + gi;
  if (substep >= g->substeps) return;
  const uint k = g->pin_offset + j;
  const float pin_t = substep + 1 == g->substeps ? 1.0f : (float)(substep + 1) * g->inv_n;
  const float4 a = pin_start[k];
  const float4 b = pin_target[k];
  const uint p = g->particle_offset + pin_index[k];
  x[p] = (float4)(a.xyz + pin_t * (b.xyz - a.xyz), x[p].w);
}

/* Whether garment g projects distance group `group` (or its tether group, `tether`) in pass
 * `pass` of substep `substep`: the regular passes (limit = 0) in each of its substeps up to its
 * iterations; the strain limit's (limit = 1) only in its own last substep, up to its
 * strain_passes (0 when off), and only over its stretch groups (from kind_end[1]). */
bool dcl_projects(__global const DrapeClGarment* g, uint group, uint tether, uint limit, int substep,
                  int pass) {
  if (limit) return substep + 1 == g->substeps && pass < g->strain_passes && !tether && group >= g->kind_end[1];
  return substep < g->substeps && pass < g->iterations;
}

/* Colour group `group` of every garment that has one, in pass `iteration` of substep `substep`;
 * `row` = its row of `work`; `mode` (DCL_MODE_*) a distance group, a tether group, or a distance
 * group in the strain limit's passes (dcl_projects picks the garments). */
__kernel void drape_phase_project(__global const DrapeClGarment* table, uint count,
                                  __global const uint* work, __global float4* x,
                                  __global const DrapeClConstraint* constraints,
                                  __global const uint* groups, uint row, uint group, uint mode,
                                  int substep, int iteration) {
  uint gi, j;
  if (!dcl_item(work, count, row, &gi, &j)) return;
  __global const DrapeClGarment* g = table + gi;
  const uint tether = mode == DCL_MODE_TETHER ? 1u : 0u;
  if (!dcl_projects(g, group, tether, mode == DCL_MODE_LIMIT ? 1u : 0u, substep, iteration)) return;
  const uint first = groups[(tether ? g->tether_group_offset : g->distance_group_offset) + group];
  dcl_project_one(x + g->particle_offset, constraints[first + j], mode,
                  mode == DCL_MODE_LIMIT ? g->strain_scale : g->tether_scale, dcl_group_alpha(g, group, tether));
}

/* Consecutive colour groups (rows first_row .. first_row + rows - 1) small enough for one
 * work-group - at most DRAPE_CL_WORK_GROUP items per garment each (the host's choice; the loop
 * below takes any count) - in one launch of one work-group: row after row with a barrier between
 * them, so each row sees the last one's writes as separate launches would, and each constraint
 * runs the same arithmetic in the same order (the same bits). Garments whose colouring has many
 * small groups (a vertex of many edges needs as many colours: the templates' underarm fan, up to
 * 36 edges at 32 000 particles until it was removed, gave ~35 colours per kind) would otherwise
 * pay a launch for each of them. `limit`: the strain limit's pass (distance rows only). */
__kernel __attribute__((reqd_work_group_size(DRAPE_CL_WORK_GROUP, 1, 1)))
void drape_phase_project_rows(__global const DrapeClGarment* table, uint count, __global const uint* work,
                              __global float4* x, __global const DrapeClConstraint* constraints,
                              __global const uint* groups, uint first_row, uint rows, uint distance_rows,
                              int substep, int iteration, uint limit) {
  const uint lid = get_local_id(0);
  for (uint r = first_row; r < first_row + rows; ++r) {
    __global const uint* start = work + r * (count + 1u);
    const uint c = r - 2u;
    const uint tether = c >= distance_rows ? 1u : 0u;
    const uint group = tether ? c - distance_rows : c;
    const uint mode = limit ? DCL_MODE_LIMIT : tether ? DCL_MODE_TETHER : DCL_MODE_DISTANCE;
    for (uint i = lid; i < start[count]; i += DRAPE_CL_WORK_GROUP) {
      const uint gi = dcl_owner(start, count, i);
      __global const DrapeClGarment* g = table + gi;
      if (!dcl_projects(g, group, tether, limit, substep, iteration)) continue;
      const uint first = groups[(tether ? g->tether_group_offset : g->distance_group_offset) + group];
      dcl_project_one(x + g->particle_offset, constraints[first + i - start[gi]], mode,
                      limit ? g->strain_scale : g->tether_scale, dcl_group_alpha(g, group, tether));
    }
    barrier(CLK_GLOBAL_MEM_FENCE);
  }
}

/* Collision against the substep's span when the span ends here, then the velocity update.
 * Counters: one atomic per work-item that found something, into its garment's entry. */
__kernel void drape_phase_collide_velocity(__global const DrapeClGarment* table, uint count,
                                           __global const uint* work, __global float4* x,
                                           __global const float4* prev, __global float4* vel,
                                           __global const float4* span_start,
                                           __global const uchar* masks,
                                           __global const DrapeClShape* shapes,
                                           __global const float4* span_bounds,
                                           __global DrapeClStats* stats, int substep) {
  uint gi, j;
  if (!dcl_item(work, count, DCL_ROW_PARTICLES, &gi, &j)) return;
  __global const DrapeClGarment* g = table + gi;
  if (substep >= g->substeps) return;
  const int stride = g->stride;
  const int span = dcl_span_of(substep, stride);
  const bool collide = (substep + 1 - span * stride) >= stride || substep + 1 == g->substeps;
  const uint p = g->particle_offset + j;
  float4 xi = x[p];
  const float4 pi = prev[p];
  CollideCounters st = {0u, 0u, 0u, 0u};
  if (collide && g->shape_count > 0u) {
    const CollideSpan sp = dcl_collide_span(g, span, shapes, span_bounds);
    const float4 from = stride > 1 ? span_start[p] : pi;
    const uint mask = (g->flags & DRAPE_CL_GROUPED) ? (uint)masks[p] : 0xFFu;
    const float4 y = collide_particle(&sp, mask, xi, from, &st);
    if (any(y.xyz != xi.xyz)) {
      xi = y;
      x[p] = xi;
    }
  }
  float4 v = (xi - pi) * g->velocity_scale;
  if (g->max_speed2 > 0.0f) {
    const float s2 = dot(v, v);
    if (s2 > g->max_speed2) v *= g->max_speed / sqrt(s2);
  }
  vel[p] = v;
  __global DrapeClStats* out = stats + gi;
  if (st.tests) atomic_add(&out->tests, st.tests);
  if (st.contacts) atomic_add(&out->contacts, st.contacts);
  if (st.swept_catches) atomic_add(&out->swept_catches, st.swept_catches);
  if (st.escapes) atomic_add(&out->escapes, st.escapes);
}

/* The rim edges (collideRims) of the per-phase garments whose substep `substep` collides, after
 * drape_phase_collide_velocity: one work-group, garment after garment, colour after colour with a
 * barrier between (rims are short: about 150 edges on a 2 000-particle T-shirt). The particles an
 * edge moves get their velocity from where they end, as in the frame kernel. */
__kernel __attribute__((reqd_work_group_size(DRAPE_CL_WORK_GROUP, 1, 1)))
void drape_phase_rims(__global const DrapeClGarment* table, uint count, __global const uint* work,
                      __global float4* x, __global const float4* prev, __global float4* vel,
                      __global const uchar* masks, __global const DrapeClShape* shapes,
                      __global const float4* span_bounds, __global const DrapeClConstraint* constraints,
                      __global const uint* groups, __global DrapeClStats* stats, int substep) {
  const uint lid = get_local_id(0);
  for (uint gi = 0; gi < count; ++gi) {
    __global const DrapeClGarment* g = table + gi;
    /* The same for every work-item of the group: the barriers below are reached by all or none. */
    if (work[DCL_ROW_PARTICLES * (count + 1u) + gi + 1u] == work[DCL_ROW_PARTICLES * (count + 1u) + gi]) continue;
    if (substep >= g->substeps || g->rim_groups == 0u || g->shape_count == 0u) continue;
    const int stride = g->stride;
    const int span = dcl_span_of(substep, stride);
    if (!((substep + 1 - span * stride) >= stride || substep + 1 == g->substeps)) continue;
    const CollideSpan sp = dcl_collide_span(g, span, shapes, span_bounds);
    const bool grouped = (g->flags & DRAPE_CL_GROUPED) != 0u;
    const uint o = g->particle_offset;
    CollideCounters st = {0u, 0u, 0u, 0u};
    for (uint c = 0; c < g->rim_groups; ++c) {
      const uint begin = groups[g->rim_group_offset + c], end = groups[g->rim_group_offset + c + 1u];
      for (uint k = begin + lid; k < end; k += DRAPE_CL_WORK_GROUP) {
        const DrapeClConstraint r = constraints[k];
        if (!(r.w_sum > 0.0f)) continue;  /* gated off (ClXpbdSolver::setRimGate) or both ends pinned */
        float4 pa = x[o + r.a], pb = x[o + r.b];
        const uint ma = grouped ? (uint)masks[o + r.a] : 0xFFu;
        const uint mb = grouped ? (uint)masks[o + r.b] : 0xFFu;
        if (!collide_rim(&sp, ma, mb, &pa, &pb, &st)) continue;
        x[o + r.a] = pa;
        x[o + r.b] = pb;
        vel[o + r.a] = dcl_velocity(g, pa, prev[o + r.a]);
        vel[o + r.b] = dcl_velocity(g, pb, prev[o + r.b]);
      }
      barrier(CLK_GLOBAL_MEM_FENCE);
    }
    __global DrapeClStats* out = stats + gi;
    if (st.tests) atomic_add(&out->tests, st.tests);
    if (st.contacts) atomic_add(&out->contacts, st.contacts);
    if (st.swept_catches) atomic_add(&out->swept_catches, st.swept_catches);
    if (st.escapes) atomic_add(&out->escapes, st.escapes);
  }
}
