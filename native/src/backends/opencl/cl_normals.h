// The tables drape_vertex_normals (opencl/kernels.cl) reads: each vertex's triangles, so every
// work-item sums its own vertex's face normals (no atomics) in the CPU's order (vertexNormals,
// body/mesh_metrics.h: triangles in ascending order). Meshes append one after another, their
// vertex and triangle indices shifted past the ones before: a batch of garments (their
// particles concatenated) gets its normals from one launch.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace drape {

struct ClNormalTables {
  std::vector<uint32_t> indices;            // 3 per triangle, vertex indices over every mesh
  std::vector<uint32_t> face_offsets{0};    // vertex v's triangles: [face_offsets[v], [v + 1])
  std::vector<uint32_t> vertex_faces;       // triangle indices, ascending per vertex

  void clear();
  size_t vertices() const { return face_offsets.size() - 1; }
  // Appends a mesh of vertex_count vertices (triangles: 3 indices each, into the mesh's own
  // vertices). False, nothing appended, when an index is out of range.
  bool append(const std::vector<uint32_t>& triangles, size_t vertex_count);
};

}  // namespace drape
