#include "body/mesh_metrics.h"
#include "common/plain3.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_map>

namespace drape {

MeshCheck checkMesh(const std::vector<Vec3>& positions, const std::vector<uint32_t>& indices,
                    float min_area_m2) {
  MeshCheck c;
  std::ostringstream problem;
  if (indices.size() % 3 != 0) {
    c.first_problem = "index count is not a multiple of 3";
    return c;
  }
  // Directed edge -> count. Key packs (from, to) into 64 bits.
  std::unordered_map<uint64_t, int> directed;
  directed.reserve(indices.size() * 2);
  auto key = [](uint32_t a, uint32_t b) { return (static_cast<uint64_t>(a) << 32) | b; };
  const size_t n = positions.size();
  for (size_t t = 0; t < indices.size(); t += 3) {
    const uint32_t v[3] = {indices[t], indices[t + 1], indices[t + 2]};
    if (v[0] >= n || v[1] >= n || v[2] >= n) {
      c.first_problem = "index out of range";
      return c;
    }
    const float area =
        0.5f * (positions[v[1]] - positions[v[0]]).cross(positions[v[2]] - positions[v[0]]).norm();
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2] || !(area >= min_area_m2)) {
      if (c.degenerate_triangles == 0 && problem.tellp() == 0)
        problem << "degenerate triangle " << t / 3 << " (area " << area << " m^2)";
      ++c.degenerate_triangles;
    }
    for (int e = 0; e < 3; ++e) ++directed[key(v[e], v[(e + 1) % 3])];
  }
  bool consistent = true;
  for (const auto& [k, count] : directed) {
    const uint32_t a = static_cast<uint32_t>(k >> 32), b = static_cast<uint32_t>(k & 0xffffffffu);
    const auto rev = directed.find(key(b, a));
    const int reverse = rev == directed.end() ? 0 : rev->second;
    const int total = count + reverse;
    if (total == 1) ++c.boundary_edges;
    if (total > 2) ++c.nonmanifold_edges;
    if (count != 1 || reverse != 1) {
      if (consistent && problem.tellp() == 0)
        problem << "edge " << a << "->" << b << " used " << count << "x, reverse " << reverse << "x";
      consistent = false;
    }
  }
  // A boundary edge has no reverse entry, so it was counted once; a non-manifold one may have
  // been counted from both directions, which only matters for the reported tally.
  c.watertight = c.boundary_edges == 0 && c.nonmanifold_edges == 0;
  c.consistent_winding = consistent;
  c.first_problem = problem.str();
  return c;
}

double signedVolume(const std::vector<Vec3>& positions, const std::vector<uint32_t>& indices) {
  // Divergence theorem relative to the first vertex (better conditioned than the origin when the
  // body stands metres away from the sensor).
  if (positions.empty()) return 0.0;
  const Eigen::Vector3d o = positions[0].cast<double>();
  double six_v = 0.0;
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const Eigen::Vector3d a = positions[indices[t]].cast<double>() - o;
    const Eigen::Vector3d b = positions[indices[t + 1]].cast<double>() - o;
    const Eigen::Vector3d c = positions[indices[t + 2]].cast<double>() - o;
    six_v += a.dot(b.cross(c));
  }
  return six_v / 6.0;
}

double triangleSolidAngle(const Vec3& p, const Vec3& a3, const Vec3& b3, const Vec3& c3) {
  const Eigen::Vector3d o = p.cast<double>();
  const Eigen::Vector3d a = a3.cast<double>() - o, b = b3.cast<double>() - o, c = c3.cast<double>() - o;
  const double la = a.norm(), lb = b.norm(), lc = c.norm();
  const double num = a.dot(b.cross(c));
  const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
  return 2.0 * std::atan2(num, den);
}

double windingNumber(const std::vector<Vec3>& positions, const std::vector<uint32_t>& indices,
                     const Vec3& point) {
  double omega = 0.0;
  for (size_t t = 0; t + 2 < indices.size(); t += 3)
    omega += triangleSolidAngle(point, positions[indices[t]], positions[indices[t + 1]], positions[indices[t + 2]]);
  return omega / (4.0 * 3.14159265358979323846);
}

void vertexNormals(const std::vector<Vec3>& positions, const std::vector<uint32_t>& indices,
                   std::vector<Vec3>& normals) {
  // Plain3 (common/plain3.h): the bits of the Eigen expressions it replaced, in the OpenCL
  // kernel's order (cl_normals.h); the body mesh's normals were half of a body-only test's time in
  // the sanitizer build as Eigen calls.
  std::fill(normals.begin(), normals.end(), Vec3::Zero());
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const uint32_t a = indices[t], b = indices[t + 1], c = indices[t + 2];
    const Plain3<float> pa = plain3<float>(positions[a]);
    // The cross product's length is twice the area: area weighting comes for free.
    const Plain3<float> n = cross(plain3<float>(positions[b]) - pa, plain3<float>(positions[c]) - pa);
    addTo(normals[a], n);
    addTo(normals[b], n);
    addTo(normals[c], n);
  }
  for (Vec3& n : normals) {
    const Plain3<float> v = plain3<float>(n);
    const float len = norm(v);
    n = len > 1e-20f ? toVec3(v / len) : Vec3(0.0f, 1.0f, 0.0f);
  }
}

float polygonPerimeter(const Vec3* points, int count) {
  float p = 0.0f;
  for (int i = 0; i < count; ++i) p += (points[(i + 1) % count] - points[i]).norm();
  return p;
}

}  // namespace drape
