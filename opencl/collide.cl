/* Particle-ellipsoid collision of one particle against one collision span's ellipsoids: the port
 * of EllipsoidCollider::collide (native/src/proxies/collision.cpp), same passes, same order of
 * ellipsoids, same tests. Broad phase: the span's bounding box (union of the swept boxes) rejects
 * a particle outright, then each ellipsoid's collision group and swept/end box before any
 * narrow-phase arithmetic (the CPU grid only skips ellipsoids that box test rejects, so results
 * do not depend on it). Particles are independent: one work-item per particle. */

#define DCL_DEEP_CONTACT_COS 0.70710678f
#define DCL_MAX_ESCAPE_CANDIDATES 8

typedef struct {
  uint tests, contacts, swept_catches, escapes;
} CollideCounters;

/* Everything collide() needs besides the particle: the span's shapes and the contact params. */
typedef struct {
  __global const DrapeClShape* shapes;
  uint count;
  uint flags;
  float3 bound_min, bound_max;
  float static_friction, kinetic_friction, max_escape;
} CollideSpan;

inline float3 f3(float4 v) { return v.xyz; }
/* m (by columns c0..c2) times v */
inline float3 mul_cols(float4 c0, float4 c1, float4 c2, float3 v) {
  return c0.xyz * v.x + c1.xyz * v.y + c2.xyz * v.z;
}
/* m^T v */
inline float3 mul_cols_t(float4 c0, float4 c1, float4 c2, float3 v) {
  return (float3)(dot(c0.xyz, v), dot(c1.xyz, v), dot(c2.xyz, v));
}
inline float3 to_unit_end(__global const DrapeClShape* s, float3 p) {
  return mul_cols(s->end_u0, s->end_u1, s->end_u2, p - s->end_c.xyz);
}
inline float sq(float3 v) { return dot(v, v); }
inline bool box_contains(float3 mn, float3 mx, float3 p) {
  return all(p >= mn) && all(p <= mx);
}
inline bool box_overlaps(float3 lo, float3 hi, float3 mn, float3 mx) {
  return all(lo <= mx) && all(hi >= mn);
}
inline bool shape_allowed(__global const DrapeClShape* s, uint flags, uint mask) {
  return !(flags & DRAPE_CL_GROUPED) || (s->group & mask) != 0u;
}

/* closestInsideFloat: Newton on the closest-point root for points inside (|q|^2 >= 0.25),
   the first step the one exact for a sphere (native/src/proxies/collision.cpp). */
inline bool closest_inside_float(float3 b, float3 q, float r2, float3* local_pt, float3* qc) {
  if (!(r2 >= 0.25f)) return false;
  const float3 e = sqrt(b);
  const float3 y = e * q;
  const float3 a = y * e;
  float lo = -fmin(fmin(b.x, b.y), b.z), hi = 0.0f, t = 0.0f;
  float F = r2 - 1.0f;
  const float3 qq = q * q / b;
  float dF = -2.0f * (qq.x + qq.y + qq.z);
  for (int it = 0; it < 8; ++it) {
    if (F < 0.0f) hi = t; else lo = t;
    float tn = dF < 0.0f ? (it == 0 ? 2.0f * r2 * (1.0f - sqrt(r2)) / dF : t - F / dF) : lo;
    if (!(tn > lo && tn < hi)) tn = 0.5f * (lo + hi);
    t = tn;
    const float3 r = 1.0f / (b + t);
    const float3 u = a * r;
    const float3 uu = u * u;
    F = uu.x + uu.y + uu.z - 1.0f;
    if (fabs(F) < 1e-5f) {
      const float out = F < 0.0f ? 1.0f - F : 1.0f; /* just inside: out to just outside */
      *local_pt = b * y * r * out;
      *qc = y * r * e * out;
      return true;
    }
    const float3 uur = uu * r;
    dF = -2.0f * (uur.x + uur.y + uur.z);
  }
  return false;
}

inline float3 unit_axis(int a) {
  return a == 0 ? (float3)(1, 0, 0) : a == 1 ? (float3)(0, 1, 0) : (float3)(0, 0, 1);
}

/* respond(): the point the particle moves to, and the contact's unit-space coordinate. */
inline float3 respond(__global const DrapeClShape* s, float3 x, float3 q, float r2, bool exact,
                      float3* qc) {
  if (!exact) {
    *qc = r2 > 1e-30f ? q / sqrt(r2) : unit_axis(s->smallest_axis);
    return s->end_c.xyz + mul_cols(s->end_f0, s->end_f1, s->end_f2, *qc);
  }
  float3 y;
  if (!closest_inside_float(s->radii2.xyz, q, r2, &y, qc)) {
    const float3 local_pt = mul_cols_t(s->rot0, s->rot1, s->rot2, x - s->end_c.xyz);
    y = closest_point_on_ellipsoid(s->radii.xyz, local_pt);
    *qc = y / s->radii.xyz;
  }
  return s->end_c.xyz + mul_cols(s->rot0, s->rot1, s->rot2, y);
}

inline float3 entry_point(float3 q0, float q0sq, float3 q1) {
  const float3 d = q1 - q0;
  const float a = sq(d), b = dot(q0, d), c0 = q0sq - 1.0f;
  float t = 0.0f;
  if (c0 > 0.0f && a > 0.0f) {
    const float den = -b + sqrt(fmax(b * b - a * c0, 0.0f));
    t = den > 0.0f ? fmin(c0 / den, 1.0f) : 0.0f;
  }
  const float3 qe = q0 + t * d;
  const float len = length(qe);
  return len > 0.0f ? qe / len : q0;
}

inline float3 slide_from_entry(__global const DrapeClShape* s, float3 qe, float3 q1, float3* qc) {
  const float3 xe = s->end_c.xyz + mul_cols(s->end_f0, s->end_f1, s->end_f2, qe);
  float3 n = mul_cols_t(s->end_u0, s->end_u1, s->end_u2, qe);
  const float nn = length(n);
  float3 rest = mul_cols(s->end_f0, s->end_f1, s->end_f2, q1 - qe);
  if (nn > 0.0f) {
    n /= nn;
    const float rn = dot(rest, n);
    if (rn < 0.0f) rest -= rn * n;
  }
  const float3 x = xe + rest;
  *qc = to_unit_end(s, x);
  return x;
}

inline float3 apply_friction(__global const DrapeClShape* s, float3 qc, float3 before, float3 x0,
                             float mu_s, float mu_k, float3 x) {
  const float3 n = mul_cols_t(s->end_u0, s->end_u1, s->end_u2, qc);
  const float nn = sq(n);
  if (!(nn > 0.0f)) return x;
  const float3 surface_move = (s->end_c.xyz + mul_cols(s->end_f0, s->end_f1, s->end_f2, qc)) -
                              (s->start_c.xyz + mul_cols(s->start_f0, s->start_f1, s->start_f2, qc));
  const float3 rel = (x - x0) - surface_move;
  const float3 tangential = rel - (dot(rel, n) / nn) * n;
  const float slip2 = sq(tangential);
  const float depth2 = sq(x - before);
  const float kinetic = slip2 > 0.0f ? fmin(mu_k * sqrt(depth2 / slip2), 1.0f) : 0.0f;
  const float f = slip2 < mu_s * mu_s * depth2 ? 1.0f : kinetic;
  return x - f * tangential;
}

inline int first_containing(const CollideSpan* sp, uint mask, float3 x, CollideCounters* st) {
  if (!box_overlaps(x, x, sp->bound_min, sp->bound_max)) return -1;
  for (uint k = 0; k < sp->count; ++k) {
    __global const DrapeClShape* s = sp->shapes + k;
    if (!shape_allowed(s, sp->flags, mask)) continue;
    if (!box_contains(s->end_min.xyz, s->end_max.xyz, x)) continue;
    ++st->tests;
    if (sq(to_unit_end(s, x)) < s->inside_tol2) return (int)k;
  }
  return -1;
}

inline float3 escape_overlap(const CollideSpan* sp, uint mask, float3 x, CollideCounters* st) {
  const bool exact = (sp->flags & DRAPE_CL_EXACT) != 0u;
  int containing[DCL_MAX_ESCAPE_CANDIDATES];
  float3 targets[DCL_MAX_ESCAPE_CANDIDATES];
  int m = 0;
  if (box_overlaps(x, x, sp->bound_min, sp->bound_max)) {
    for (uint k = 0; k < sp->count && m < DCL_MAX_ESCAPE_CANDIDATES; ++k) {
      __global const DrapeClShape* s = sp->shapes + k;
      if (!shape_allowed(s, sp->flags, mask)) continue;
      if (!box_contains(s->end_min.xyz, s->end_max.xyz, x)) continue;
      ++st->tests;
      const float3 q = to_unit_end(s, x);
      const float r2 = sq(q);
      if (!(r2 < s->inside_tol2)) continue;
      float3 qc;
      targets[m] = respond(s, x, q, r2, exact, &qc);
      containing[m++] = (int)k;
    }
  }
  const float limit2 = sp->max_escape > 0.0f ? sp->max_escape * sp->max_escape : INFINITY;
  float best = limit2;
  float3 best_x = x;
  for (int i = 0; i < m; ++i) {
    const float d = sq(targets[i] - x);
    if (d < best && first_containing(sp, mask, targets[i], st) < 0) {
      best = d;
      best_x = targets[i];
    }
  }
  if (best < limit2) return best_x;
  const int n = (int)sp->count;
  for (int i = 0; i < m; ++i) {
    __global const DrapeClShape* s0 = sp->shapes + containing[i];
    float3 dir = targets[i] - x;
    const float len = length(dir);
    if (len > 1e-12f) {
      dir = dir / len;
    } else {
      const int a = s0->smallest_axis;
      dir = a == 0 ? s0->rot0.xyz : a == 1 ? s0->rot1.xyz : s0->rot2.xyz;
    }
    float t = 0.0f;
    bool out = false;
    for (int jump = 0; jump <= n && t * t < best; ++jump) {
      const float3 p = x + t * dir;
      const int k = first_containing(sp, mask, p, st);
      if (k < 0) {
        out = true;
        break;
      }
      __global const DrapeClShape* s = sp->shapes + k;
      const float3 q = to_unit_end(s, p);
      const float3 v = mul_cols(s->end_u0, s->end_u1, s->end_u2, dir);
      const float a = sq(v), b = dot(q, v), c = sq(q) - 1.0f;
      const float step = a > 0.0f ? (-b + sqrt(fmax(b * b - a * c, 0.0f))) / a : 0.0f;
      t += fmax(step, 1e-7f) * 1.000001f;
    }
    if (out && t * t < best) {
      best = t * t;
      best_x = x + t * dir;
    }
  }
  return best_x;
}

/* resolveParticle: pass 0 (discrete + swept + friction), then the sequential passes, then the
 * escape step. x0: position at the span start (valid when has_prev). */
inline float3 resolve_particle(const CollideSpan* sp, uint mask, float3 x, float3 x0, bool has_prev,
                               CollideCounters* st) {
  const bool exact = (sp->flags & DRAPE_CL_EXACT) != 0u;
  const bool cont = (sp->flags & DRAPE_CL_CONTINUOUS) != 0u && has_prev;
  const bool friction = has_prev && (sp->static_friction > 0.0f || sp->kinetic_friction > 0.0f);
  const float3 lo = cont ? fmin(x, x0) : x;
  const float3 hi = cont ? fmax(x, x0) : x;
  const float3 x_end = x;
  bool moved = false;
  if (!box_overlaps(lo, hi, sp->bound_min, sp->bound_max)) return x;
  for (uint k = 0; k < sp->count; ++k) {
    __global const DrapeClShape* s = sp->shapes + k;
    if (!shape_allowed(s, sp->flags, mask)) continue;
    const bool in_box = cont ? box_overlaps(lo, hi, s->swept_min.xyz, s->swept_max.xyz)
                             : box_contains(s->end_min.xyz, s->end_max.xyz, x_end);
    if (!in_box) continue;
    ++st->tests;
    const float3 q1 = to_unit_end(s, x);
    const float r2 = sq(q1);
    const bool inside = r2 < 1.0f;
    float3 q0 = (float3)(0.0f);
    float q0sq = 0.0f;
    bool crossed = false;
    if (cont) {
      q0 = mul_cols(s->start_u0, s->start_u1, s->start_u2, x0 - s->start_c.xyz);
      q0sq = sq(q0);
      const float3 d = q1 - q0;
      const float a = sq(d), b = dot(q0, d);
      crossed = !inside && (q0sq >= 1.0f) && (b < 0.0f) && (a > 0.0f) && (-b <= a) &&
                (q0sq * a - b * b < s->graze * a);
    }
    if (!(inside || crossed)) continue;
    /* contact() */
    float3 target, qc;
    bool swept = false;
    if (inside) {
      target = respond(s, x, q1, r2, exact, &qc);
      if (cont && q0sq >= s->inside_tol2) {
        const float d0 = dot(qc, q0), d1 = dot(qc, q1);
        const float kCos2 = DCL_DEEP_CONTACT_COS * DCL_DEEP_CONTACT_COS;
        const bool in_cone = (d0 >= 0.0f) && (d1 >= 0.0f) && (d0 * d0 >= kCos2 * q0sq) &&
                             (d1 * d1 >= kCos2 * r2);
        if (!in_cone) {
          const float3 qe = entry_point(q0, q0sq, q1);
          if (dot(qc, qe) < DCL_DEEP_CONTACT_COS) {
            target = slide_from_entry(s, qe, q1, &qc);
            swept = true;
          }
        }
      }
    } else {
      target = slide_from_entry(s, entry_point(q0, q0sq, q1), q1, &qc);
      swept = true;
    }
    ++st->contacts;
    if (swept) ++st->swept_catches;
    const float3 before = x;
    x = target;
    if (friction)
      x = apply_friction(s, qc, before, x0, sp->static_friction, sp->kinetic_friction, x);
    moved = true;
  }
  /* Further sequential passes (kSequentialPasses = 2: one more), no friction. */
  if (moved) {
    moved = false;
    const float3 xp = x;
    if (box_overlaps(xp, xp, sp->bound_min, sp->bound_max)) {
      for (uint k = 0; k < sp->count; ++k) {
        __global const DrapeClShape* s = sp->shapes + k;
        if (!shape_allowed(s, sp->flags, mask)) continue;
        if (!box_contains(s->end_min.xyz, s->end_max.xyz, xp)) continue;
        ++st->tests;
        const float3 q = to_unit_end(s, x);
        const float r2 = sq(q);
        if (!(r2 < s->inside_tol2)) continue;
        float3 qc;
        x = respond(s, x, q, r2, exact, &qc);
        moved = true;
      }
    }
  }
  if (moved && first_containing(sp, mask, x, st) >= 0) {
    x = escape_overlap(sp, mask, x, st);
    ++st->escapes;
  }
  return x;
}

/* EllipsoidCollider::collide for one particle: p = predicted position (w = inverse mass),
 * prev = position at the span start. Returns the corrected position (w kept). */
inline float4 collide_particle(const CollideSpan* sp, uint mask, float4 p, float4 prev,
                               CollideCounters* st) {
  if (!(p.w > 0.0f) || sp->count == 0u) return p;
  const float3 x = p.xyz;
  const bool swept = (sp->flags & DRAPE_CL_CONTINUOUS) != 0u;
  if (!box_contains(sp->bound_min, sp->bound_max, x)) {
    if (!swept) return p;
    const float3 p0 = prev.xyz;
    if (!box_overlaps(fmin(x, p0), fmax(x, p0), sp->bound_min, sp->bound_max)) return p;
  }
  if (!all(isfinite(x))) return p;
  float3 x0 = prev.xyz;
  const bool has_prev = all(isfinite(x0));
  if (!has_prev) x0 = x;
  const float3 y = resolve_particle(sp, mask, x, x0, has_prev, st);
  return (float4)(y, p.w);
}

/* EllipsoidCollider::collideRims for one rim edge (native/src/proxies/collision_rims.cpp): the
 * same tests and arithmetic, every shape of the span in index order behind its group and box
 * tests (the CPU's grid only skips shapes that box test rejects). *pa and *pb are the edge's
 * particles (w = inverse mass), updated; true when the edge was pushed. The caller runs the edges
 * of one colour in parallel (no two share a particle). */
#define DCL_RIM_DEEP2 0.75f
#define DCL_RIM_END_T 0.02f
#define DCL_LIMB_ELONGATION 1.5f
inline bool collide_rim(const CollideSpan* sp, uint mask_a, uint mask_b, float4* pa, float4* pb,
                        CollideCounters* st) {
  const float wa = (*pa).w > 0.0f ? (*pa).w : 0.0f, wb = (*pb).w > 0.0f ? (*pb).w : 0.0f;
  if (wa == 0.0f && wb == 0.0f) return false;
  float3 xa = (*pa).xyz, xb = (*pb).xyz;
  if (!all(isfinite(xa)) || !all(isfinite(xb))) return false;
  const bool grouped = (sp->flags & DRAPE_CL_GROUPED) != 0u;
  const uint mask = mask_a & mask_b;
  if (grouped && mask == 0u) return false;
  if (!box_overlaps(fmin(xa, xb), fmax(xa, xb), sp->bound_min, sp->bound_max)) return false;
  bool moved = false;
  for (uint k = 0; k < sp->count; ++k) {
    __global const DrapeClShape* s = sp->shapes + k;
    if (!shape_allowed(s, sp->flags, mask)) continue;
    if (!box_overlaps(fmin(xa, xb), fmax(xa, xb), s->end_min.xyz, s->end_max.xyz)) continue;
    ++st->tests;
    const float3 q0 = to_unit_end(s, xa), q1 = to_unit_end(s, xb);
    const float3 d = q1 - q0;
    const float dd = sq(d);
    if (!(dd > 1e-12f)) continue;
    const float t = clamp(-dot(q0, d) / dd, 0.0f, 1.0f);
    if (t <= DCL_RIM_END_T || t >= 1.0f - DCL_RIM_END_T) continue;
    const float3 q = q0 + t * d;
    const float r2 = sq(q);
    if (!(r2 < DCL_RIM_DEEP2) || !(r2 > 1e-12f)) continue;
    float3 target = q * (1.0f / sqrt(r2));
    const float3 r = s->radii.xyz;
    const int axis = (r.y > r.x) ? (r.z > r.y ? 2 : 1) : (r.z > r.x ? 2 : 0);
    const float longest = axis == 0 ? r.x : axis == 1 ? r.y : r.z;
    const float middle = axis == 0 ? fmax(r.y, r.z) : axis == 1 ? fmax(r.z, r.x) : fmax(r.x, r.y);
    if (longest > DCL_LIMB_ELONGATION * middle) {
      const float qa = axis == 0 ? q.x : axis == 1 ? q.y : q.z;
      float3 across = q;
      if (axis == 0) across.x = 0.0f;
      else if (axis == 1) across.y = 0.0f;
      else across.z = 0.0f;
      const float a2 = sq(across);
      if (!(a2 > 1e-8f)) continue;
      target = across * sqrt((1.0f - qa * qa) / a2);
      if (axis == 0) target.x = qa;
      else if (axis == 1) target.y = qa;
      else target.z = qa;
    }
    const float3 delta = mul_cols(s->end_f0, s->end_f1, s->end_f2, target - q);
    const float ca = wa * (1.0f - t), cb = wb * t;
    const float den = ca * (1.0f - t) + cb * t;
    if (!(den > 0.0f)) continue;
    xa += (ca / den) * delta;
    xb += (cb / den) * delta;
    moved = true;
    ++st->contacts;
  }
  if (!moved) return false;
  if (wa > 0.0f) xa = resolve_particle(sp, grouped ? mask_a : 0xFFu, xa, xa, false, st);
  if (wb > 0.0f) xb = resolve_particle(sp, grouped ? mask_b : 0xFFu, xb, xb, false, st);
  *pa = (float4)(xa, (*pa).w);
  *pb = (float4)(xb, (*pb).w);
  return true;
}
