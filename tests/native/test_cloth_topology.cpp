// Garment topology (native/src/cloth/garment_topology.h): lumped masses, constraint kinds on a
// grid, tethers, a valid colouring, and rejection of bad meshes with a message and no change.
#include "cloth/garment_topology.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <vector>

namespace drape {
namespace {

struct Mesh {
  std::vector<float> positions;
  std::vector<uint32_t> indices;
};

Mesh grid(int nx, int ny, float size = 1.0f) {
  Mesh m;
  makeClothGrid(nx, ny, size, size, Vec3::Zero(), Vec3::UnitX(), -Vec3::UnitY(), m.positions,
                m.indices);
  return m;
}

bool build(const Mesh& m, const TopologyParams& p, GarmentTopology& out, std::string& error) {
  return buildGarmentTopology(m.positions.data(), m.positions.size() / 3, m.indices.data(),
                              m.indices.size(), p, out, error);
}

// No two constraints of one colour share a particle the solver writes.
void expectValidColouring(const DistanceConstraints& c, bool check_b, const char* what) {
  ASSERT_EQ(c.colour_offsets.front(), 0u) << what;
  ASSERT_EQ(c.colour_offsets.back(), c.size()) << what;
  for (size_t col = 0; col < c.colours(); ++col) {
    std::set<uint32_t> seen;
    EXPECT_LT(c.colour_offsets[col], c.colour_offsets[col + 1]) << what << ": empty colour";
    for (uint32_t k = c.colour_offsets[col]; k < c.colour_offsets[col + 1]; ++k) {
      EXPECT_TRUE(seen.insert(c.a[k]).second) << what << " colour " << col << " particle " << c.a[k];
      if (check_b) {
        EXPECT_TRUE(seen.insert(c.b[k]).second) << what << " colour " << col << " particle " << c.b[k];
      }
    }
  }
}

TEST(ClothTopology, GridMassesAndConstraintKinds) {
  const int n = 30;
  const Mesh m = grid(n, n);
  TopologyParams p;
  p.area_density = 0.2f;
  p.pinned = {0, static_cast<uint32_t>(n - 1)};
  GarmentTopology t;
  std::string error;
  ASSERT_TRUE(build(m, p, t, error)) << error;
  EXPECT_TRUE(error.empty());
  ASSERT_EQ(t.particleCount(), static_cast<size_t>(n * n));
  double total = 0.0;
  for (float mass : t.mass) total += static_cast<double>(mass);
  EXPECT_NEAR(total, 0.2, 1e-5);                 // density x 1 m^2
  const float cell = 1.0f / static_cast<float>(n - 1);
  // Corner (0,0) touches 2 triangles of the split, (n-1,0) only 1: masses in thirds.
  EXPECT_NEAR(t.mass[0], 2.0f * 0.5f * cell * cell * 0.2f / 3.0f, 1e-9f);
  EXPECT_NEAR(t.mass[n - 1], 0.5f * cell * cell * 0.2f / 3.0f, 1e-9f);
  EXPECT_EQ(t.inverse_mass[0], 0.0f);
  EXPECT_EQ(t.inverse_mass[n - 1], 0.0f);
  EXPECT_GT(t.inverse_mass[1], 0.0f);
  const size_t quads = static_cast<size_t>((n - 1) * (n - 1));
  EXPECT_EQ(t.stretch.size(), 2 * static_cast<size_t>(n * (n - 1)) + quads);
  EXPECT_EQ(t.shear.size(), quads);  // the other diagonal of each quad
  EXPECT_EQ(t.bend.size(), 2 * static_cast<size_t>((n - 1) * (n - 2)));
  for (size_t k = 0; k < t.shear.size(); ++k)
    EXPECT_NEAR(t.shear.rest[k], cell * std::sqrt(2.0f), 1e-6f);
  // Two tethers per free particle, anchors pinned, rest = Euclidean distance at rest.
  EXPECT_EQ(t.tether.size(), 2 * static_cast<size_t>(n * n - 2));
  for (size_t k = 0; k < t.tether.size(); ++k) {
    EXPECT_EQ(t.inverse_mass[t.tether.b[k]], 0.0f);
    EXPECT_GT(t.inverse_mass[t.tether.a[k]], 0.0f);
    EXPECT_FLOAT_EQ(t.tether.rest[k],
                    (t.rest_positions[t.tether.a[k]] - t.rest_positions[t.tether.b[k]]).norm());
  }
}

TEST(ClothTopology, ColouringSharesNoParticleWithinAColour) {
  Mesh m = grid(17, 23);
  // Shuffle the triangle order deterministically so the greedy order differs from the grid's.
  const size_t tris = m.indices.size() / 3;
  std::vector<uint32_t> shuffled;
  for (size_t k = 0; k < tris; ++k) {
    const size_t f = (k * 7919) % tris;  // 7919 is prime, coprime with tris
    shuffled.insert(shuffled.end(), m.indices.begin() + static_cast<std::ptrdiff_t>(3 * f),
                    m.indices.begin() + static_cast<std::ptrdiff_t>(3 * f + 3));
  }
  m.indices = shuffled;
  TopologyParams p;
  p.pinned = {0, 5, 16, 100};
  p.max_tethers_per_particle = 3;
  GarmentTopology t;
  std::string error;
  ASSERT_TRUE(build(m, p, t, error)) << error;
  expectValidColouring(t.stretch, true, "stretch");
  expectValidColouring(t.shear, true, "shear");
  expectValidColouring(t.bend, true, "bend");
  expectValidColouring(t.tether, false, "tether");
  EXPECT_EQ(t.tether.colours(), 3u);  // three tethers per particle, coloured by the free end
  EXPECT_LE(t.stretch.colours(), 13u);  // greedy bound: 2 * max degree (6) + 1
  // A hand-made conflict set: constraints sharing particles must land in different colours.
  DistanceConstraints c;
  c.a = {0, 1, 2, 0};
  c.b = {1, 2, 3, 3};
  c.rest = {1, 1, 1, 1};
  colourConstraints(c, 4, true);
  expectValidColouring(c, true, "cycle");
  EXPECT_EQ(c.colours(), 2u);
}

TEST(ClothTopology, DeterministicBuild) {
  const Mesh m = grid(12, 9);
  TopologyParams p;
  p.pinned = {3, 7};
  GarmentTopology a, b;
  std::string error;
  ASSERT_TRUE(build(m, p, a, error));
  ASSERT_TRUE(build(m, p, b, error));
  EXPECT_EQ(a.stretch.a, b.stretch.a);
  EXPECT_EQ(a.bend.b, b.bend.b);
  EXPECT_EQ(a.tether.a, b.tether.a);
  EXPECT_EQ(a.tether.colour_offsets, b.tether.colour_offsets);
}

TEST(ClothTopology, RejectsBadInputWithMessageAndNoChange) {
  const Mesh good = grid(4, 4);
  GarmentTopology out;
  std::string error;
  TopologyParams p;
  ASSERT_TRUE(build(good, p, out, error));
  const size_t before = out.stretch.size();
  auto expectRejected = [&](const Mesh& m, const TopologyParams& params, const char* what) {
    std::string message;
    EXPECT_FALSE(build(m, params, out, message)) << what;
    EXPECT_FALSE(message.empty()) << what;
    EXPECT_EQ(out.particleCount(), 16u) << what;
    EXPECT_EQ(out.stretch.size(), before) << what;
  };
  expectRejected(Mesh{}, p, "empty");
  Mesh no_tris = good;
  no_tris.indices.clear();
  expectRejected(no_tris, p, "no triangles");
  Mesh ragged = good;
  ragged.indices.pop_back();
  expectRejected(ragged, p, "index count not a multiple of 3");
  Mesh range = good;
  range.indices[4] = 16;
  expectRejected(range, p, "index out of range");
  Mesh repeated = good;
  repeated.indices[1] = repeated.indices[0];
  expectRejected(repeated, p, "repeated index");
  Mesh collinear = good;  // squash the first row onto a line through vertex 0's triangle
  collinear.positions[3 * 5 + 0] = collinear.positions[3 * 1 + 0];
  collinear.positions[3 * 5 + 1] = collinear.positions[3 * 1 + 1];
  expectRejected(collinear, p, "zero-area triangle");
  Mesh nan = good;
  nan.positions[7] = std::numeric_limits<float>::quiet_NaN();
  expectRejected(nan, p, "NaN position");
  Mesh inf = good;
  inf.positions[0] = std::numeric_limits<float>::infinity();
  expectRejected(inf, p, "infinite position");
  for (float density : {0.0f, -0.2f, std::numeric_limits<float>::quiet_NaN()}) {
    TopologyParams bad = p;
    bad.area_density = density;
    expectRejected(good, bad, "density");
  }
  TopologyParams pin = p;
  pin.pinned = {16};
  expectRejected(good, pin, "pinned out of range");
  TopologyParams tethers = p;
  tethers.max_tethers_per_particle = -1;
  expectRejected(good, tethers, "negative tether count");
  Mesh lonely = good;  // a vertex used by no triangle would have no mass
  lonely.positions.insert(lonely.positions.end(), {5.0f, 5.0f, 5.0f});
  std::string message;
  EXPECT_FALSE(buildGarmentTopology(lonely.positions.data(), 17, lonely.indices.data(),
                                    lonely.indices.size(), p, out, message));
  EXPECT_NE(message.find("no triangle"), std::string::npos) << message;
  EXPECT_FALSE(buildGarmentTopology(nullptr, 16, good.indices.data(), good.indices.size(), p, out,
                                    message));
}

}  // namespace
}  // namespace drape
