/* Closest point on an axis-aligned ellipsoid (Eberly 2013, safeguarded Halley steps): the port of
 * closestPointOnEllipsoidFast (native/src/proxies/closest_point.cpp), the fallback of the exact
 * contact response for points the float Newton iteration does not settle. In double when the
 * device has cl_khr_fp64 (as the CPU), else in float (the results then differ by ~1e-6 m). */
#ifdef cl_khr_fp64
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double dreal;
#define DREAL_EPS_STEP 1e-15
#else
typedef float dreal;
#define DREAL_EPS_STEP 1e-7f
#endif

inline dreal cp_evalF(int N, const dreal* n, const dreal* r, dreal s, dreal* df_out, dreal* d2f_out) {
  dreal f = -1, df = 0, d2f = 0;
  for (int i = 0; i < N; ++i) {
    const dreal inv = 1 / (s + r[i]);
    const dreal ratio2 = (n[i] * inv) * (n[i] * inv);
    f += ratio2;
    df -= 2 * ratio2 * inv;
    d2f += 6 * ratio2 * inv * inv;
  }
  *df_out = df;
  *d2f_out = d2f;
  return f;
}

inline dreal cp_norm(int N, const dreal* n) {
  dreal m = 0;
  for (int i = 0; i < N; ++i) m = fmax(m, fabs(n[i]));
  if (m == 0) return 0;
  dreal s = 0;
  for (int i = 0; i < N; ++i) s += (n[i] / m) * (n[i] / m);
  return m * sqrt(s);
}

inline dreal cp_root(int N, const dreal* n, const dreal* r, dreal g) {
  dreal lo = n[N - 1] - 1;
  dreal hi = g < 0 ? (dreal)0 : cp_norm(N, n) - 1;
  if (g > 0) lo = fmax(lo, (dreal)0);
  dreal s = g < 0 ? hi : lo;
  dreal df = 0, d2f = 0;
  dreal f = cp_evalF(N, n, r, s, &df, &d2f);
  for (int i = 0; i < 200; ++i) {
    if (f == 0) return s;
    if (f > 0) lo = s; else hi = s;
    const dreal scale = fmax((dreal)1, fabs(s));
    const dreal denom = 2 * df * df - f * d2f;
    const dreal halley = denom > 0 ? 2 * f * df / denom : (dreal)0;
    const dreal newton = df < 0 ? f / df : (dreal)0;
    if (fabs(halley) <= DREAL_EPS_STEP * scale && fabs(newton) <= DREAL_EPS_STEP * scale) return s;
    dreal next = s - halley;
    dreal tol = (dreal)1e-6;
    if (!(next > lo && next < hi)) {
      next = s - newton;
      tol = (dreal)1e-8;
    }
    if (!(next > lo && next < hi)) {
      next = (dreal)0.5 * (lo + hi);
      tol = 0;
      if (next == lo || next == hi) return s;
    }
    const dreal dx = next - s;
    s = next;
    if (fabs(dx) <= tol * scale) return s;
    f = cp_evalF(N, n, r, s, &df, &d2f);
  }
  return s;
}

inline void cp_closest2(dreal e0, dreal e1, dreal y0, dreal y1, dreal* x0, dreal* x1) {
  if (y1 > 0) {
    if (y0 > 0) {
      const dreal z0 = y0 / e0, z1 = y1 / e1;
      const dreal g = z0 * z0 + z1 * z1 - 1;
      if (g != 0) {
        const dreal r0 = (e0 / e1) * (e0 / e1);
        const dreal n[2] = {r0 * z0, z1};
        const dreal r[2] = {r0, 1};
        const dreal s = cp_root(2, n, r, g);
        *x0 = r0 * y0 / (s + r0);
        *x1 = y1 / (s + 1);
      } else {
        *x0 = y0;
        *x1 = y1;
      }
    } else {
      *x0 = 0;
      *x1 = e1;
    }
  } else {
    const dreal numer0 = e0 * y0, denom0 = e0 * e0 - e1 * e1;
    if (numer0 < denom0) {
      const dreal xde0 = numer0 / denom0;
      *x0 = e0 * xde0;
      *x1 = e1 * sqrt(fmax((dreal)0, 1 - xde0 * xde0));
    } else {
      *x0 = e0;
      *x1 = 0;
    }
  }
}

inline void cp_closest3(const dreal* e, const dreal* y, dreal* x) {
  if (y[2] > 0) {
    if (y[1] > 0) {
      if (y[0] > 0) {
        const dreal z0 = y[0] / e[0], z1 = y[1] / e[1], z2 = y[2] / e[2];
        const dreal g = z0 * z0 + z1 * z1 + z2 * z2 - 1;
        if (g != 0) {
          const dreal r0 = (e[0] / e[2]) * (e[0] / e[2]);
          const dreal r1 = (e[1] / e[2]) * (e[1] / e[2]);
          const dreal n[3] = {r0 * z0, r1 * z1, z2};
          const dreal r[3] = {r0, r1, 1};
          const dreal s = cp_root(3, n, r, g);
          x[0] = r0 * y[0] / (s + r0);
          x[1] = r1 * y[1] / (s + r1);
          x[2] = y[2] / (s + 1);
        } else {
          x[0] = y[0];
          x[1] = y[1];
          x[2] = y[2];
        }
      } else {
        x[0] = 0;
        cp_closest2(e[1], e[2], y[1], y[2], &x[1], &x[2]);
      }
    } else {
      x[1] = 0;
      if (y[0] > 0) {
        cp_closest2(e[0], e[2], y[0], y[2], &x[0], &x[2]);
      } else {
        x[0] = 0;
        x[2] = e[2];
      }
    }
  } else {
    const dreal denom0 = e[0] * e[0] - e[2] * e[2];
    const dreal denom1 = e[1] * e[1] - e[2] * e[2];
    const dreal numer0 = e[0] * y[0], numer1 = e[1] * y[1];
    if (numer0 < denom0 && numer1 < denom1) {
      const dreal xde0 = numer0 / denom0, xde1 = numer1 / denom1;
      const dreal discr = 1 - xde0 * xde0 - xde1 * xde1;
      if (discr > 0) {
        x[0] = e[0] * xde0;
        x[1] = e[1] * xde1;
        x[2] = e[2] * sqrt(discr);
        return;
      }
    }
    x[2] = 0;
    cp_closest2(e[0], e[1], y[0], y[1], &x[0], &x[1]);
  }
}

/* radii > 0 and finite (the collider's inflated radii always are); p in the ellipsoid's frame. */
inline float3 closest_point_on_ellipsoid(float3 radii, float3 p) {
  const float rv[3] = {radii.x, radii.y, radii.z};
  const float pv[3] = {p.x, p.y, p.z};
  for (int i = 0; i < 3; ++i)
    if (!(rv[i] > 0.0f) || !isfinite(rv[i]) || !isfinite(pv[i])) return p;
  int perm[3] = {0, 1, 2};
  int t;
  if (rv[perm[0]] < rv[perm[1]]) { t = perm[0]; perm[0] = perm[1]; perm[1] = t; }
  if (rv[perm[1]] < rv[perm[2]]) { t = perm[1]; perm[1] = perm[2]; perm[2] = t; }
  if (rv[perm[0]] < rv[perm[1]]) { t = perm[0]; perm[0] = perm[1]; perm[1] = t; }
  dreal e[3], y[3], x[3];
  for (int j = 0; j < 3; ++j) {
    e[j] = (dreal)rv[perm[j]];
    y[j] = fabs((dreal)pv[perm[j]]);
  }
  cp_closest3(e, y, x);
  float out[3];
  for (int j = 0; j < 3; ++j) out[perm[j]] = (float)copysign(x[j], (dreal)pv[perm[j]]);
  return (float3)(out[0], out[1], out[2]);
}
