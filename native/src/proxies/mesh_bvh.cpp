#include "proxies/mesh_bvh.h"

#include "body/mesh_metrics.h"
#include "common/plain3.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace drape {
namespace {

// Closest point on segment [a, b] to p, and its squared distance.
Vec3 closestOnSegment(const Vec3& p, const Vec3& a, const Vec3& b, float& d2) {
  const Vec3 ab = b - a;
  const float len2 = ab.squaredNorm();
  float t = len2 > 0.0f ? (p - a).dot(ab) / len2 : 0.0f;
  t = std::min(1.0f, std::max(0.0f, t));
  const Vec3 q = a + t * ab;
  d2 = (p - q).squaredNorm();
  return q;
}

// What the ray o + t d, t > 0, does at triangle (a, b, c): misses it, crosses it leaving the solid
// (+1: through an outward face) or entering (-1), or passes too close to an edge or a vertex, or
// along the triangle's plane through it, to tell (the caller tries another direction).
enum class RayHit : int { Entering = -1, Miss = 0, Leaving = 1, Ambiguous = 2 };

// Moller-Trumbore in double precision. Barycentric coordinates within kEdgeTol of a triangle's
// border make the ray ambiguous: it may cross the two triangles sharing that edge both or neither
// in float data.
inline RayHit rayTriangle(const Plain3<double>& oo, const Plain3<double>& dd, const Vec3& af, const Vec3& bf,
                          const Vec3& cf) {
  using D3 = Plain3<double>;
  constexpr double kEdgeTol = 1e-7;
  const D3 a = plain3<double>(af);
  const D3 e1 = plain3<double>(bf) - a;
  const D3 e2 = plain3<double>(cf) - a;
  const D3 pv = cross(dd, e2);
  const double det = dot(e1, pv);
  const double scale = norm(e1) * norm(e2);
  if (!(scale > 0.0)) return RayHit::Miss;  // degenerate: bounds no volume
  if (std::fabs(det) < 1e-9 * scale) {
    // Along the plane: ambiguous only if the ray runs through the triangle's plane near p.
    return std::fabs(dot(oo - a, cross(e1, e2))) < 1e-9 * scale ? RayHit::Ambiguous : RayHit::Miss;
  }
  const D3 tv = oo - a;
  const double u = dot(tv, pv) / det;
  if (u < -kEdgeTol || u > 1.0 + kEdgeTol) return RayHit::Miss;
  const D3 qv = cross(tv, e1);
  const double v = dot(dd, qv) / det;
  if (v < -kEdgeTol || u + v > 1.0 + kEdgeTol) return RayHit::Miss;
  const double t = dot(e2, qv) / det;
  if (t <= 0.0) return RayHit::Miss;  // behind p (p on the surface itself: its depth is ~0 either way)
  if (u < kEdgeTol || v < kEdgeTol || u + v > 1.0 - kEdgeTol) return RayHit::Ambiguous;
  // det = -d . (e1 x e2): negative where the ray leaves through the (outward) face.
  return det < 0.0 ? RayHit::Leaving : RayHit::Entering;
}

// Three fixed ray directions in no symmetry plane of a body (none along an axis or a diagonal).
using RayDirections = Eigen::Vector3d[3];
const RayDirections& rayDirections() {
  static const RayDirections kDirs = {Eigen::Vector3d(0.2673, 0.5345, 0.8018).normalized(),
                                           Eigen::Vector3d(-0.7071, 0.3015, -0.6396).normalized(),
                                           Eigen::Vector3d(0.5774, -0.8165, 0.1543).normalized()};
  return kDirs;
}

// The projected triangle with corners (u0, v0), (u1, v1), (u2, v2) as three edge lines a u + b v + c,
// each the signed distance to its edge's line, positive inside (the triangle's orientation either
// way): a point lies within m of the triangle's inside when all three are >= -m. A triangle with
// no area gets lines that pass every point (the exact test decides).
inline void edgeLines(const double* c, double* line) {
  const double area2 = (c[2] - c[0]) * (c[5] - c[1]) - (c[3] - c[1]) * (c[4] - c[0]);
  for (int e = 0; e < 3; ++e) {
    const double au = c[2 * e], av = c[2 * e + 1];
    const double eu = c[(2 * e + 2) % 6] - au, ev = c[(2 * e + 3) % 6] - av;
    const double len = std::sqrt(eu * eu + ev * ev);
    double* l = line + 3 * e;
    if (area2 == 0.0 || !(len > 0.0)) {
      l[0] = l[1] = 0.0, l[2] = 1.0;
      continue;
    }
    const double k = (area2 > 0.0 ? 1.0 : -1.0) / len;
    l[0] = -ev * k, l[1] = eu * k, l[2] = (ev * au - eu * av) * k;
  }
}

inline float boxDistance2(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  float d2 = 0.0f;
  for (int i = 0; i < 3; ++i) {
    const float below = lo[i] - p[i];
    const float above = p[i] - hi[i];
    const float d = std::max(0.0f, std::max(below, above));
    d2 += d * d;
  }
  return d2;
}

}  // namespace

Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                            TriangleFeature* feature) {
  TriangleFeature f = TriangleFeature::Face;
  Vec3 result;
  const Vec3 ab = b - a, ac = c - a;
  // The six dot products in Plain3 (common/plain3.h): the same bits, and no Eigen calls in the
  // sanitizer build for every triangle a closest-point query visits.
  const Plain3<float> pab = plain3<float>(ab), pac = plain3<float>(ac), pp = plain3<float>(p);
  const Plain3<float> ap = pp - plain3<float>(a), bp = pp - plain3<float>(b), cp = pp - plain3<float>(c);
  const float d1 = dot(pab, ap), d2 = dot(pac, ap);
  const float d3 = dot(pab, bp), d4 = dot(pac, bp);
  const float d5 = dot(pab, cp), d6 = dot(pac, cp);
  const float vc = d1 * d4 - d3 * d2;
  const float vb = d5 * d2 - d1 * d6;
  const float va = d3 * d6 - d5 * d4;
  if (d1 <= 0.0f && d2 <= 0.0f) {
    f = TriangleFeature::VertexA;
    result = a;
  } else if (d3 >= 0.0f && d4 <= d3) {
    f = TriangleFeature::VertexB;
    result = b;
  } else if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) {
    f = TriangleFeature::EdgeAB;
    const float den = d1 - d3;  // = |ab|^2
    result = den > 0.0f ? Vec3(a + (d1 / den) * ab) : a;
  } else if (d6 >= 0.0f && d5 <= d6) {
    f = TriangleFeature::VertexC;
    result = c;
  } else if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) {
    f = TriangleFeature::EdgeCA;
    const float den = d2 - d6;  // = |ac|^2
    result = den > 0.0f ? Vec3(a + (d2 / den) * ac) : a;
  } else if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f) {
    f = TriangleFeature::EdgeBC;
    const float den = (d4 - d3) + (d5 - d6);  // = |bc|^2
    result = den > 0.0f ? Vec3(b + ((d4 - d3) / den) * (c - b)) : b;
  } else {
    const float sum = va + vb + vc;  // = |ab x ac|^2 up to rounding
    if (sum > 0.0f) {
      const float inv = 1.0f / sum;
      result = a + ab * (vb * inv) + ac * (vc * inv);
    } else {
      // Degenerate (collinear) triangle that fell through every region test: nearest of the
      // three sides.
      float e0 = 0.0f, e1 = 0.0f, e2 = 0.0f;
      const Vec3 q0 = closestOnSegment(p, a, b, e0);
      const Vec3 q1 = closestOnSegment(p, b, c, e1);
      const Vec3 q2 = closestOnSegment(p, c, a, e2);
      if (e0 <= e1 && e0 <= e2) {
        result = q0;
        f = TriangleFeature::EdgeAB;
      } else if (e1 <= e2) {
        result = q1;
        f = TriangleFeature::EdgeBC;
      } else {
        result = q2;
        f = TriangleFeature::EdgeCA;
      }
    }
  }
  if (feature) *feature = f;
  return result;
}

void TriangleBvh::clear() {
  nodes_.clear();
  tris_.clear();
  corners_.clear();
  face_normals_.clear();
  edge_normals_.clear();
  vertex_normals_.clear();
  indices_.clear();
  vertex_count_ = 0;
  depth_ = 0;
}

bool TriangleBvh::build(const std::vector<Vec3>& positions, const std::vector<uint32_t>& indices,
                        bool allow_refit) {
  if (allow_refit && !nodes_.empty() && positions.size() == vertex_count_ && indices == indices_)
    return refit(positions);

  clear();
  const size_t tri_count = indices.size() / 3;
  if (indices.size() % 3 != 0 || tri_count == 0 || tri_count > (size_t{1} << 31)) return false;
  for (const uint32_t i : indices)
    if (i >= positions.size()) return false;
  for (const Vec3& v : positions)
    if (!isFinite(v)) return false;

  indices_ = indices;
  vertex_count_ = positions.size();

  // Edge ids: sort (undirected key, corner) pairs so equal edges are adjacent.
  std::vector<std::pair<uint64_t, uint32_t>> edges(indices.size());
  for (size_t t = 0; t < tri_count; ++t) {
    for (size_t k = 0; k < 3; ++k) {
      const uint32_t u = indices[3 * t + k], w = indices[3 * t + (k + 1) % 3];
      const uint64_t key = (static_cast<uint64_t>(std::min(u, w)) << 32) | std::max(u, w);
      edges[3 * t + k] = {key, static_cast<uint32_t>(3 * t + k)};
    }
  }
  std::sort(edges.begin(), edges.end());
  std::vector<uint32_t> corner_edge(indices.size());
  uint32_t edge_count = 0;
  for (size_t i = 0; i < edges.size(); ++i) {
    if (i > 0 && edges[i].first != edges[i - 1].first) ++edge_count;
    corner_edge[edges[i].second] = edge_count;
  }
  ++edge_count;

  // Top-down median split over an index permutation.
  std::vector<Vec3> centroids(tri_count);
  for (size_t t = 0; t < tri_count; ++t)
    centroids[t] = (positions[indices[3 * t]] + positions[indices[3 * t + 1]] +
                    positions[indices[3 * t + 2]]) / 3.0f;
  tris_.resize(tri_count);
  for (size_t t = 0; t < tri_count; ++t) tris_[t].id = static_cast<uint32_t>(t);
  nodes_.reserve(2 * (tri_count / kLeafSize + 1));
  buildNode(0, static_cast<uint32_t>(tri_count), centroids, 1);
  if (depth_ > kStackSize - 2) {  // unreachable for a median split below 2^31 triangles
    clear();
    return false;
  }
  for (Tri& tri : tris_) {
    for (uint32_t k = 0; k < 3; ++k) {
      tri.v[k] = indices[3 * size_t{tri.id} + k];
      tri.e[k] = corner_edge[3 * size_t{tri.id} + k];
    }
  }

  corners_.resize(3 * tri_count);
  face_normals_.resize(tri_count);
  edge_normals_.resize(edge_count);
  vertex_normals_.resize(positions.size());
  updateGeometry(positions);
  refitBoxes();
  return true;
}

uint32_t TriangleBvh::buildNode(uint32_t begin, uint32_t end, std::vector<Vec3>& centroids,
                                int level) {
  const uint32_t index = static_cast<uint32_t>(nodes_.size());
  nodes_.push_back(Node{});
  depth_ = std::max(depth_, level);
  if (end - begin <= static_cast<uint32_t>(kLeafSize)) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  Vec3 lo = centroids[tris_[begin].id], hi = lo;
  for (uint32_t s = begin + 1; s < end; ++s) {
    lo = lo.cwiseMin(centroids[tris_[s].id]);
    hi = hi.cwiseMax(centroids[tris_[s].id]);
  }
  int axis = 0;
  const Vec3 extent = hi - lo;
  if (extent[1] > extent[axis]) axis = 1;
  if (extent[2] > extent[axis]) axis = 2;
  const uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(tris_.begin() + begin, tris_.begin() + mid, tris_.begin() + end,
                   [&](const Tri& x, const Tri& y) {
                     return centroids[x.id][axis] < centroids[y.id][axis];
                   });
  // Recursion depth is the tree depth, which the median split bounds by log2(n) + 1.
  buildNode(begin, mid, centroids, level + 1);
  const uint32_t right = buildNode(mid, end, centroids, level + 1);
  nodes_[index].first = right;
  nodes_[index].count = 0;
  return index;
}

bool TriangleBvh::refit(const std::vector<Vec3>& positions) {
  if (nodes_.empty() || positions.size() != vertex_count_) return false;
  updateGeometry(positions);
  refitBoxes();
  return true;
}

// Plain3 (common/plain3.h): the bits of the Eigen expressions it replaced; refitting the body's
// tree for every measured frame was 18 % of three stress scenarios' time in the sanitizer build as
// Eigen calls (perf).
void TriangleBvh::updateGeometry(const std::vector<Vec3>& positions) {
  using P3 = Plain3<float>;
  for (Vec3& n : edge_normals_) n.setZero();
  for (Vec3& n : vertex_normals_) n.setZero();
  for (size_t s = 0; s < tris_.size(); ++s) {
    const Tri& tri = tris_[s];
    const Vec3 a = positions[tri.v[0]], b = positions[tri.v[1]], c = positions[tri.v[2]];
    corners_[3 * s] = a;
    corners_[3 * s + 1] = b;
    corners_[3 * s + 2] = c;
    const P3 pa = plain3<float>(a), pb = plain3<float>(b), pc = plain3<float>(c);
    const P3 ab = pb - pa, ac = pc - pa;
    const P3 cr = cross(ab, ac);
    const float len = norm(cr);
    if (!(len > 0.0f)) {
      face_normals_[s].setZero();
      continue;
    }
    const P3 n = cr / len;
    face_normals_[s] = toVec3(n);
    for (int k = 0; k < 3; ++k) addTo(edge_normals_[tri.e[k]], n);
    // Interior angles (|cross| is the same for all three corners); the third from the sum.
    const float angle_a = std::atan2(len, dot(ab, ac));
    const float angle_b = std::atan2(len, dot(pc - pb, pa - pb));
    const float angle_c = std::max(0.0f, kPi - angle_a - angle_b);
    addTo(vertex_normals_[tri.v[0]], angle_a * n);
    addTo(vertex_normals_[tri.v[1]], angle_b * n);
    addTo(vertex_normals_[tri.v[2]], angle_c * n);
  }
  auto normalise = [](std::vector<Vec3>& v) {
    for (Vec3& n : v) {
      const P3 p = plain3<float>(n);
      const float len = norm(p);
      if (len > 0.0f) n = toVec3(p / len);
      else n.setZero();
    }
  };
  normalise(edge_normals_);
  normalise(vertex_normals_);
}

void TriangleBvh::refitBoxes() {
  // Depth-first storage: both children of node i have larger indices, so a backward sweep sees
  // children before parents.
  for (size_t i = nodes_.size(); i-- > 0;) {
    Node& n = nodes_[i];
    if (n.count > 0) {
      Vec3 lo = corners_[3 * n.first], hi = lo;
      for (uint32_t k = 3 * n.first + 1; k < 3 * (n.first + n.count); ++k) {
        lo = lo.cwiseMin(corners_[k]);
        hi = hi.cwiseMax(corners_[k]);
      }
      n.lo = lo;
      n.hi = hi;
    } else {
      const Node& l = nodes_[i + 1];
      const Node& r = nodes_[n.first];
      n.lo = l.lo.cwiseMin(r.lo);
      n.hi = l.hi.cwiseMax(r.hi);
    }
  }
}

void TriangleBvh::testTriangle(uint32_t slot, const Vec3& p, float& best2, Hit& hit) const {
  TriangleFeature f;
  const Vec3 q = closestPointOnTriangle(p, corners_[3 * slot], corners_[3 * slot + 1],
                                        corners_[3 * slot + 2], &f);
  const float d2 = (p - q).squaredNorm();
  if (d2 < best2) {
    best2 = d2;
    hit.point = q;
    hit.triangle = static_cast<int>(slot);  // slot for now; finishHit maps it to the id
    hit.feature = f;
  }
}

void TriangleBvh::finishHit(const Vec3& p, Hit& hit) const {
  if (hit.triangle < 0) {
    hit.point = p;
    return;
  }
  const size_t slot = static_cast<size_t>(hit.triangle);
  const Tri& tri = tris_[slot];
  hit.triangle = static_cast<int>(tri.id);
  hit.distance = (p - hit.point).norm();
  hit.normal = face_normals_[slot];
  switch (hit.feature) {
    case TriangleFeature::Face: hit.pseudo_normal = face_normals_[slot]; break;
    case TriangleFeature::EdgeAB: hit.pseudo_normal = edge_normals_[tri.e[0]]; break;
    case TriangleFeature::EdgeBC: hit.pseudo_normal = edge_normals_[tri.e[1]]; break;
    case TriangleFeature::EdgeCA: hit.pseudo_normal = edge_normals_[tri.e[2]]; break;
    case TriangleFeature::VertexA: hit.pseudo_normal = vertex_normals_[tri.v[0]]; break;
    case TriangleFeature::VertexB: hit.pseudo_normal = vertex_normals_[tri.v[1]]; break;
    case TriangleFeature::VertexC: hit.pseudo_normal = vertex_normals_[tri.v[2]]; break;
  }
}

TriangleBvh::Hit TriangleBvh::closest(const Vec3& p, float max_distance) const {
  Hit hit;
  if (nodes_.empty() || !(max_distance > 0.0f)) {
    hit.point = p;
    return hit;
  }
  float best2 = max_distance * max_distance;
  struct Entry {
    uint32_t node;
    float d2;
  };
  Entry stack[kStackSize];
  int sp = 0;
  stack[sp++] = {0, boxDistance2(p, nodes_[0].lo, nodes_[0].hi)};
  while (sp > 0) {
    const Entry e = stack[--sp];
    if (e.d2 >= best2) continue;
    const Node& n = nodes_[e.node];
    if (n.count > 0) {
      for (uint32_t s = n.first; s < n.first + n.count; ++s) testTriangle(s, p, best2, hit);
      continue;
    }
    const uint32_t left = e.node + 1, right = n.first;
    const float dl = boxDistance2(p, nodes_[left].lo, nodes_[left].hi);
    const float dr = boxDistance2(p, nodes_[right].lo, nodes_[right].hi);
    // Push the farther child first so the nearer one is searched first and tightens best2.
    // The stack never holds more than depth + 1 entries (checked at build).
    if (dl <= dr) {
      if (dr < best2) stack[sp++] = {right, dr};
      if (dl < best2) stack[sp++] = {left, dl};
    } else {
      if (dl < best2) stack[sp++] = {left, dl};
      if (dr < best2) stack[sp++] = {right, dr};
    }
  }
  finishHit(p, hit);
  return hit;
}

TriangleBvh::Hit TriangleBvh::closestBruteForce(const Vec3& p) const {
  Hit hit;
  float best2 = std::numeric_limits<float>::infinity();
  for (uint32_t s = 0; s < tris_.size(); ++s) testTriangle(s, p, best2, hit);
  finishHit(p, hit);
  return hit;
}

float TriangleBvh::signedDistance(const Vec3& p) const {
  const Hit h = closest(p);
  if (h.triangle < 0) return std::numeric_limits<float>::infinity();
  return hitSign(p, h) * h.distance;
}

bool TriangleBvh::rayCrossings(const Vec3& p, const Eigen::Vector3d& d, int& crossings) const {
  const Eigen::Vector3d o = p.cast<double>();
  const Eigen::Vector3d inv(1.0 / d.x(), 1.0 / d.y(), 1.0 / d.z());
  crossings = 0;
  uint32_t stack[kStackSize];
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    const Node& n = nodes_[stack[--sp]];
    // Slab test, the box grown by a hair so that rounding never drops a triangle on its face.
    double t_in = 0.0, t_out = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      const double a = (static_cast<double>(n.lo[k]) - 1e-6 - o[k]) * inv[k];
      const double b = (static_cast<double>(n.hi[k]) + 1e-6 - o[k]) * inv[k];
      t_in = std::max(t_in, std::min(a, b));
      t_out = std::min(t_out, std::max(a, b));
    }
    if (t_in > t_out) continue;
    if (n.count == 0) {
      const uint32_t self = static_cast<uint32_t>(&n - nodes_.data());
      stack[sp++] = n.first;
      stack[sp++] = self + 1;
      continue;
    }
    // The triangle tests in plain doubles (common/plain3.h): every triangle of every visited leaf,
    // for every vertex whose depth a measurement asks.
    const Plain3<double> dd{d.x(), d.y(), d.z()}, oo{o.x(), o.y(), o.z()};
    for (uint32_t s = n.first; s < n.first + n.count; ++s) {
      const RayHit h = rayTriangle(oo, dd, corners_[3 * s], corners_[3 * s + 1], corners_[3 * s + 2]);
      if (h == RayHit::Ambiguous) return false;
      crossings += static_cast<int>(h);
    }
  }
  return true;
}

int TriangleBvh::winding(const Vec3& p) const {
  if (nodes_.empty() || !p.allFinite()) return 0;
  const RayDirections& kDirs = rayDirections();
  // The count is the same along any ray that crosses no edge (the mesh is closed), but its cost is
  // the boxes the ray passes: the ray first tried is the one of the six (kDirs and their
  // opposites) that leaves the root box soonest (a quarter fewer boxes and a third fewer triangles
  // tested per ray for a garment's particles).
  const Node& root = nodes_[0];
  Eigen::Vector3d first = kDirs[0];
  double first_exit = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& dir : kDirs) {
    for (const double sign : {1.0, -1.0}) {
      const Eigen::Vector3d d = sign * dir;
      double exit = std::numeric_limits<double>::infinity();
      for (int k = 0; k < 3; ++k) exit = std::min(exit, ((d[k] > 0.0 ? root.hi[k] : root.lo[k]) - p[k]) / d[k]);
      if (exit < first_exit) {
        first_exit = exit;
        first = d;
      }
    }
  }
  int crossings = 0;
  if (rayCrossings(p, first, crossings)) return crossings;
  for (const Eigen::Vector3d& d : kDirs)
    if (rayCrossings(p, d, crossings)) return crossings;
  // Every ray grazed an edge: the solid-angle sum over every triangle (body/mesh_metrics.h).
  double omega = 0.0;
  for (size_t s = 0; s < tris_.size(); ++s)
    omega += triangleSolidAngle(p, corners_[3 * s], corners_[3 * s + 1], corners_[3 * s + 2]);
  return static_cast<int>(std::lround(omega / (4.0 * 3.14159265358979323846)));
}

float TriangleBvh::depthInside(const Vec3& p) const {
  if (nodes_.empty() || winding(p) < 1) return 0.0f;
  return closest(p).distance;
}

void TriangleBvh::depthsInside(const Vec3* points, size_t n, float* out) const {
  if (n == 0) return;
  std::fill(out, out + n, 0.0f);
  if (nodes_.empty()) return;
  // The plane across the ray direction d: orthonormal u, v (double), every triangle's corners
  // projected onto it. A ray from p crosses a triangle, or passes it closely enough to be
  // ambiguous, only where p's projection lies in the triangle's up to the crossing test's
  // barycentric tolerance (far below kGrow), so the triangles whose projection lies within kGrow
  // of p's are every triangle the test must see: a grid of cells lists those whose projected box
  // (grown by kGrow) covers the cell, and each one's edge lines tell within kGrow exactly.
  constexpr double kGrow = 1e-4;
  const Eigen::Vector3d d = rayDirections()[0];
  const Eigen::Vector3d helper = std::fabs(d.x()) < 0.6 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d u = d.cross(helper).normalized(), v = d.cross(u);
  const size_t tri_count = tris_.size();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  // Scratch kept per thread (a few hundred kilobytes for a body): a fresh allocation this size
  // per call is zeroed anew, which cost as much as the rays saved.
  thread_local std::vector<double> box, lines;
  thread_local std::vector<uint32_t> start, next, slots;
  box.resize(4 * tri_count);   // per slot: lo u, lo v, hi u, hi v
  lines.resize(9 * tri_count);  // per slot: its projection's three edge lines (edgeLines)
  double lo_u = kInf, lo_v = kInf, hi_u = -kInf, hi_v = -kInf;
  for (size_t t = 0; t < tri_count; ++t) {
    double b[4] = {kInf, kInf, -kInf, -kInf};
    double flat[6];
    for (size_t c = 0; c < 3; ++c) {
      const Eigen::Vector3d q = corners_[3 * t + c].cast<double>();
      const double pu = q.dot(u), pv = q.dot(v);
      flat[2 * c] = pu, flat[2 * c + 1] = pv;
      b[0] = std::min(b[0], pu), b[1] = std::min(b[1], pv), b[2] = std::max(b[2], pu), b[3] = std::max(b[3], pv);
    }
    edgeLines(flat, &lines[9 * t]);
    double* grown = &box[4 * t];
    grown[0] = b[0] - kGrow, grown[1] = b[1] - kGrow, grown[2] = b[2] + kGrow, grown[3] = b[3] + kGrow;
    lo_u = std::min(lo_u, grown[0]), lo_v = std::min(lo_v, grown[1]);
    hi_u = std::max(hi_u, grown[2]), hi_v = std::max(hi_v, grown[3]);
  }
  // About one triangle per cell (a body's triangles are a few centimetres across), at most 1024
  // cells along a side.
  const double extent_u = std::max(hi_u - lo_u, 1e-6), extent_v = std::max(hi_v - lo_v, 1e-6);
  const double cell = std::max(std::sqrt(extent_u * extent_v / static_cast<double>(tri_count)),
                               std::max(extent_u, extent_v) / 1024.0);
  const int nu = std::max(1, std::min(1024, static_cast<int>(std::ceil(extent_u / cell))));
  const int nv = std::max(1, std::min(1024, static_cast<int>(std::ceil(extent_v / cell))));
  auto cellU = [&](double x) { return std::min(nu - 1, std::max(0, static_cast<int>((x - lo_u) / cell))); };
  auto cellV = [&](double y) { return std::min(nv - 1, std::max(0, static_cast<int>((y - lo_v) / cell))); };
  // Each cell's triangles, compressed: start[c] .. start[c + 1] in `slots` (a counting sort).
  const size_t cells = static_cast<size_t>(nu) * static_cast<size_t>(nv);
  start.assign(cells + 1, 0);
  auto forCells = [&](size_t t, auto&& f) {
    const double* b = &box[4 * t];
    if (!(b[0] <= b[2] && b[1] <= b[3])) return;  // a non-finite corner (a refit takes any floats): no crossing
    const int u1 = cellU(b[2]), v1 = cellV(b[3]);
    for (int cv = cellV(b[1]); cv <= v1; ++cv)
      for (int cu = cellU(b[0]); cu <= u1; ++cu) f(static_cast<size_t>(cv) * static_cast<size_t>(nu) + static_cast<size_t>(cu));
  };
  for (size_t t = 0; t < tri_count; ++t) forCells(t, [&](size_t c) { ++start[c + 1]; });
  for (size_t c = 0; c < cells; ++c) start[c + 1] += start[c];
  next.assign(start.begin(), start.end() - 1);
  slots.resize(start.back());
  for (size_t t = 0; t < tri_count; ++t) forCells(t, [&](size_t c) { slots[next[c]++] = static_cast<uint32_t>(t); });

  const Plain3<double> dd{d.x(), d.y(), d.z()};
  for (size_t i = 0; i < n; ++i) {
    const Vec3& p = points[i];
    if (!p.allFinite()) continue;  // depthInside: 0
    const Eigen::Vector3d o = p.cast<double>();
    const double pu = o.dot(u), pv = o.dot(v);
    int crossings = 0;
    bool ambiguous = false;
    if (pu >= lo_u && pu <= hi_u && pv >= lo_v && pv <= hi_v) {  // else no triangle to cross
      const size_t c = static_cast<size_t>(cellV(pv)) * static_cast<size_t>(nu) + static_cast<size_t>(cellU(pu));
      const Plain3<double> oo{o.x(), o.y(), o.z()};
      for (uint32_t k = start[c]; k < start[c + 1] && !ambiguous; ++k) {
        const uint32_t t = slots[k];
        const double* l = &lines[9 * t];
        const double inside = std::min(std::min(l[0] * pu + l[1] * pv + l[2], l[3] * pu + l[4] * pv + l[5]),
                                       l[6] * pu + l[7] * pv + l[8]);
        if (inside < -kGrow) continue;  // farther than kGrow outside its projection
        const RayHit h = rayTriangle(oo, dd, corners_[3 * t], corners_[3 * t + 1], corners_[3 * t + 2]);
        if (h == RayHit::Ambiguous) ambiguous = true;
        else crossings += static_cast<int>(h);
      }
    }
    if (ambiguous) {
      out[i] = depthInside(p);  // the one-point way: other directions, then the solid angles
    } else if (crossings >= 1) {
      out[i] = closest(p).distance;
    }
  }
}

}  // namespace drape
