#include "proxies/closest_point.h"

#include <algorithm>
#include <cmath>

namespace drape {
namespace {

enum class Root { Bisection, Halley };

// F(s) = sum_{i<N} (n_i / (s + r_i))^2 - 1 and its first two derivatives, with r_{N-1} = 1 (the
// smallest axis). F is convex and strictly decreasing on s > -1; its root s̄ gives the closest point
// x_i = r_i y_i / (s̄ + r_i) in Eberly's scaling.
template <int N>
double evalF(const double (&n)[N], const double (&r)[N], double s, double* deriv = nullptr,
             double* deriv2 = nullptr) {
  double f = -1.0, df = 0.0, d2f = 0.0;
  for (int i = 0; i < N; ++i) {
    const double inv = 1.0 / (s + r[i]);
    const double ratio2 = (n[i] * inv) * (n[i] * inv);
    f += ratio2;
    df -= 2.0 * ratio2 * inv;
    d2f += 6.0 * ratio2 * inv * inv;
  }
  if (deriv) *deriv = df;
  if (deriv2) *deriv2 = d2f;
  return f;
}

template <int N>
double norm(const double (&n)[N]) {
  double m = 0.0;
  for (double v : n) m = std::max(m, std::fabs(v));
  if (m == 0.0) return 0.0;
  double s = 0.0;
  for (double v : n) s += (v / m) * (v / m);
  return m * std::sqrt(s);
}

// Root of F on the bracket Eberly gives: F(z_{N-1} - 1) >= 0 and, for g >= 0 (outside),
// F(|n| - 1) <= 0; for g < 0 (inside) F(0) = g < 0.
template <int N>
double getRoot(const double (&n)[N], const double (&r)[N], double g, Root method) {
  double lo = n[N - 1] - 1.0;
  double hi = g < 0.0 ? 0.0 : norm(n) - 1.0;
  if (g > 0.0) lo = std::max(lo, 0.0);  // F(0) = g > 0
  if (method == Root::Bisection) {
    // Eberly: halve until the midpoint equals an end (at most ~1100 halvings for double).
    double s = 0.0;
    for (int i = 0; i < 1100; ++i) {
      s = 0.5 * (lo + hi);
      if (s == lo || s == hi) break;
      const double f = evalF(n, r, s);
      if (f > 0.0) {
        lo = s;
      } else if (f < 0.0) {
        hi = s;
      } else {
        break;
      }
    }
    return s;
  }
  // Safeguarded Halley iteration on F (cubic convergence; F, F' and F'' share the three
  // reciprocals, so a step costs one extra division). A step leaving the bracket [lo, hi] is
  // replaced by the Newton step, which for this convex decreasing F lands left of the root from
  // either side; if that leaves the bracket too, bisect. Start at the end nearer the root for
  // surface-near points: hi = 0 inside (F(0) = g < 0), lo = 0 outside (F(0) = g > 0).
  double s = g < 0.0 ? hi : lo;
  double df = 0.0, d2f = 0.0;
  double f = evalF(n, r, s, &df, &d2f);
  for (int i = 0; i < 200; ++i) {
    if (f == 0.0) return s;
    if (f > 0.0) {
      lo = s;
    } else {
      hi = s;
    }
    const double scale = std::max(1.0, std::fabs(s));
    const double denom = 2.0 * df * df - f * d2f;
    const double halley = denom > 0.0 ? 2.0 * f * df / denom : 0.0;  // s_new = s - step
    const double newton = df < 0.0 ? f / df : 0.0;
    // A step at the level of double rounding: s is the root to machine precision.
    if (std::fabs(halley) <= 1e-15 * scale && std::fabs(newton) <= 1e-15 * scale) return s;
    double next = s - halley;
    double tol = 1e-6;  // cubic convergence: the error after a step dx is O(dx^3)
    if (!(next > lo && next < hi)) {
      next = s - newton;
      tol = 1e-8;  // quadratic: O(dx^2)
    }
    if (!(next > lo && next < hi)) {
      next = 0.5 * (lo + hi);
      tol = 0.0;
      if (next == lo || next == hi) return s;
    }
    const double dx = next - s;
    s = next;
    if (std::fabs(dx) <= tol * scale) return s;
    f = evalF(n, r, s, &df, &d2f);
  }
  return s;
}

// 2-D: ellipse with e0 >= e1 > 0, point y0, y1 >= 0. Writes the closest point.
void closest2(double e0, double e1, double y0, double y1, Root method, double& x0, double& x1) {
  if (y1 > 0.0) {
    if (y0 > 0.0) {
      const double z0 = y0 / e0, z1 = y1 / e1;
      const double g = z0 * z0 + z1 * z1 - 1.0;
      if (g != 0.0) {
        const double r0 = (e0 / e1) * (e0 / e1);
        const double n[2] = {r0 * z0, z1};
        const double r[2] = {r0, 1.0};
        const double s = getRoot(n, r, g, method);
        x0 = r0 * y0 / (s + r0);
        x1 = y1 / (s + 1.0);
      } else {
        x0 = y0;
        x1 = y1;
      }
    } else {
      x0 = 0.0;
      x1 = e1;
    }
  } else {
    // On the major axis: the closest point leaves the axis when the point is inside the
    // evolute's cusp (|y0| < (e0^2 - e1^2) / e0).
    const double numer0 = e0 * y0, denom0 = e0 * e0 - e1 * e1;
    if (numer0 < denom0) {
      const double xde0 = numer0 / denom0;
      x0 = e0 * xde0;
      x1 = e1 * std::sqrt(std::max(0.0, 1.0 - xde0 * xde0));
    } else {
      x0 = e0;
      x1 = 0.0;
    }
  }
}

// 3-D: e0 >= e1 >= e2 > 0, y_i >= 0.
void closest3(const double (&e)[3], const double (&y)[3], Root method, double (&x)[3]) {
  if (y[2] > 0.0) {
    if (y[1] > 0.0) {
      if (y[0] > 0.0) {
        const double z0 = y[0] / e[0], z1 = y[1] / e[1], z2 = y[2] / e[2];
        const double g = z0 * z0 + z1 * z1 + z2 * z2 - 1.0;
        if (g != 0.0) {
          const double r0 = (e[0] / e[2]) * (e[0] / e[2]);
          const double r1 = (e[1] / e[2]) * (e[1] / e[2]);
          const double n[3] = {r0 * z0, r1 * z1, z2};
          const double r[3] = {r0, r1, 1.0};
          const double s = getRoot(n, r, g, method);
          x[0] = r0 * y[0] / (s + r0);
          x[1] = r1 * y[1] / (s + r1);
          x[2] = y[2] / (s + 1.0);
        } else {
          x[0] = y[0];
          x[1] = y[1];
          x[2] = y[2];
        }
      } else {
        x[0] = 0.0;
        closest2(e[1], e[2], y[1], y[2], method, x[1], x[2]);
      }
    } else {
      x[1] = 0.0;
      if (y[0] > 0.0) {
        closest2(e[0], e[2], y[0], y[2], method, x[0], x[2]);
      } else {
        x[0] = 0.0;
        x[2] = e[2];
      }
    }
  } else {
    // In the plane of the two larger axes: the closest point may leave the plane (towards the
    // smallest axis) when the point is deep enough inside.
    const double denom0 = e[0] * e[0] - e[2] * e[2];
    const double denom1 = e[1] * e[1] - e[2] * e[2];
    const double numer0 = e[0] * y[0], numer1 = e[1] * y[1];
    if (numer0 < denom0 && numer1 < denom1) {
      const double xde0 = numer0 / denom0, xde1 = numer1 / denom1;
      const double discr = 1.0 - xde0 * xde0 - xde1 * xde1;
      if (discr > 0.0) {
        x[0] = e[0] * xde0;
        x[1] = e[1] * xde1;
        x[2] = e[2] * std::sqrt(discr);
        return;
      }
    }
    x[2] = 0.0;
    closest2(e[0], e[1], y[0], y[1], method, x[0], x[1]);
  }
}

Vec3 closestPoint(const Vec3& radii, const Vec3& p, float* distance, Root method) {
  if (distance) *distance = 0.0f;
  for (int i = 0; i < 3; ++i) {
    if (!(radii[i] > 0.0f) || !std::isfinite(radii[i]) || !std::isfinite(p[i])) return p;
  }
  // Sort the axes so e0 >= e1 >= e2 (stable: ties keep axis order, so results are
  // deterministic), and reflect the point into the first octant.
  int perm[3] = {0, 1, 2};
  if (radii[perm[0]] < radii[perm[1]]) std::swap(perm[0], perm[1]);
  if (radii[perm[1]] < radii[perm[2]]) std::swap(perm[1], perm[2]);
  if (radii[perm[0]] < radii[perm[1]]) std::swap(perm[0], perm[1]);
  double e[3], y[3], x[3];
  for (int j = 0; j < 3; ++j) {
    e[j] = static_cast<double>(radii[perm[j]]);
    y[j] = std::fabs(static_cast<double>(p[perm[j]]));
  }
  closest3(e, y, method, x);
  Vec3 out;
  double d2 = 0.0;
  for (int j = 0; j < 3; ++j) {
    const double signed_x = std::copysign(x[j], static_cast<double>(p[perm[j]]));
    const double diff = signed_x - static_cast<double>(p[perm[j]]);
    d2 += diff * diff;
    out[perm[j]] = static_cast<float>(signed_x);
  }
  if (distance) *distance = static_cast<float>(std::sqrt(d2));
  return out;
}

}  // namespace

Vec3 closestPointOnEllipsoid(const Vec3& radii, const Vec3& local_point, float* distance) {
  return closestPoint(radii, local_point, distance, Root::Bisection);
}

Vec3 closestPointOnEllipsoidFast(const Vec3& radii, const Vec3& local_point, float* distance) {
  return closestPoint(radii, local_point, distance, Root::Halley);
}

}  // namespace drape
