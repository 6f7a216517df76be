// A flat rectangle of cloth as the solver tests build it: makeClothGrid (cloth/garment_topology.h)
// then buildGarmentTopology with the caller's TopologyParams (pins, tethers, density); the build
// is EXPECTed to succeed.
#pragma once

#include "cloth/garment_topology.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace drape {
namespace test {

struct ClothGrid {
  int nx = 20, ny = 20;                // particles per side
  float width = 1.0f, height = 1.0f;   // metres
  Vec3 origin = Vec3::Zero();
  Vec3 u = Vec3::UnitX();              // along the width
  Vec3 v = Vec3(0.0f, -1.0f, 0.0f);    // along the height (down: a hanging sheet)
};

inline GarmentTopology clothGridTopology(const ClothGrid& g, const TopologyParams& params) {
  std::vector<float> positions;
  std::vector<uint32_t> indices;
  makeClothGrid(g.nx, g.ny, g.width, g.height, g.origin, g.u, g.v, positions, indices);
  GarmentTopology t;
  std::string error;
  EXPECT_TRUE(buildGarmentTopology(positions.data(), positions.size() / 3, indices.data(), indices.size(), params,
                                   t, error))
      << error;
  return t;
}

}  // namespace test
}  // namespace drape
