// ClNormalTables: the vertex -> triangles tables of drape_vertex_normals. cl_normals.h.
#include "backends/opencl/cl_normals.h"

namespace drape {

void ClNormalTables::clear() {
  indices.clear();
  face_offsets.assign(1, 0u);
  vertex_faces.clear();
}

bool ClNormalTables::append(const std::vector<uint32_t>& triangles, size_t vertex_count) {
  for (uint32_t i : triangles)
    if (i >= vertex_count) return false;
  const uint32_t vertex_base = static_cast<uint32_t>(vertices());
  const uint32_t triangle_base = static_cast<uint32_t>(indices.size() / 3);
  const uint32_t face_base = face_offsets.back();
  const size_t tris = triangles.size() / 3;
  // Counts, then their running sum: this mesh's offsets continue the previous meshes'.
  std::vector<uint32_t> count(vertex_count + 1, 0u);
  for (size_t k = 0; k < 3 * tris; ++k) ++count[triangles[k] + 1];
  for (size_t v = 0; v < vertex_count; ++v) count[v + 1] += count[v];
  for (size_t v = 0; v < vertex_count; ++v) face_offsets.push_back(face_base + count[v + 1]);
  vertex_faces.resize(face_base + 3 * tris);
  for (size_t t = 0; t < tris; ++t)
    for (int c = 0; c < 3; ++c) vertex_faces[face_base + count[triangles[3 * t + c]]++] = triangle_base + static_cast<uint32_t>(t);
  for (size_t k = 0; k < 3 * tris; ++k) indices.push_back(vertex_base + triangles[k]);
  return true;
}

}  // namespace drape
