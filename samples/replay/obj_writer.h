// Wavefront OBJ output of one body or garment mesh: `v x y z`, `vn x y z`, `f a//a b//b c//c` (1-based).
#pragma once

#include <drape/drape.h>

#include <cstdint>
#include <string>
#include <vector>

namespace replay {

// "body_00042.obj" for frame 42.
std::string objFileName(uint32_t frame_index);
// "garment_00042.obj" for frame 42, written beside the body's.
std::string garmentObjFileName(uint32_t frame_index);
// "under_00042.obj": the garment worn under it (--under).
std::string underObjFileName(uint32_t frame_index);

// Writes the mesh to `path` (replacing it). Returns false and sets `error` on an I/O failure.
bool writeObj(const std::string& path, const std::vector<drape_vec3>& positions,
              const std::vector<drape_vec3>& normals, const std::vector<uint32_t>& indices,
              const std::string& comment, std::string& error);

}  // namespace replay
