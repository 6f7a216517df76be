// XPBD constraint passes per substep (XpbdParams::iterations, drape_cloth_params.iterations):
// more passes converge further (less stretch when substeps are few), the range is enforced and a
// rejected value changes nothing, and the C ABI carries the value both ways. drape-bench prices
// substeps against iterations (docs/benchmarks.md).
#include "capi_test_support.h"
#include "cloth_grid.h"
#include "cloth/cloth_stats.h"
#include "cloth/xpbd_solver.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

namespace drape {
namespace {

// 20 x 20 particles, 1 m square hanging in the XY plane from its two top corners, no tethers:
// with 2 substeps per 1/60 s frame one pass leaves clear stretch that more passes remove.
GarmentTopology hangingSquare() {
  TopologyParams p;
  p.area_density = 0.2f;
  p.pinned = {0, 19};
  p.max_tethers_per_particle = 0;
  return test::clothGridTopology(test::ClothGrid{}, p);
}

StretchStats stretchAfterOneSecond(int iterations) {
  XpbdSolver s(hangingSquare());
  XpbdParams p;
  p.iterations = iterations;
  std::string error;
  EXPECT_TRUE(s.setParams(p, error)) << error;
  for (int f = 0; f < 60; ++f) EXPECT_TRUE(s.step(1.0f / 60.0f, 2));
  std::vector<float> scratch;
  return stretchStats(s.topology(), s.positions(), scratch);
}

TEST(ClothIterations, MorePassesConvergeFurther) {
  const StretchStats one = stretchAfterOneSecond(1);
  const StretchStats eight = stretchAfterOneSecond(8);
  // One pass of Gauss-Seidel over a 20-particle column cannot hold it inextensible at 120 Hz.
  EXPECT_GT(one.max, 0.01f);
  EXPECT_LT(eight.max, 0.5f * one.max);
  EXPECT_LT(eight.p99, one.p99);
}

TEST(ClothIterations, RangeIsEnforcedAndARejectionChangesNothing) {
  XpbdSolver s(hangingSquare());
  std::string error;
  XpbdParams p;
  p.iterations = 3;
  ASSERT_TRUE(s.setParams(p, error)) << error;
  for (int bad : {0, -1, 65, 1000}) {
    XpbdParams q;
    q.iterations = bad;
    error.clear();
    EXPECT_FALSE(s.setParams(q, error)) << bad;
    EXPECT_NE(error.find("iterations"), std::string::npos) << error;
    EXPECT_EQ(s.params().iterations, 3);
  }
  p.iterations = 64;
  EXPECT_TRUE(s.setParams(p, error)) << error;
}

}  // namespace
}  // namespace drape

namespace {

TEST(CApiClothIterations, DefaultIsOneAndTheValueRoundTrips) {
  drape_cloth_params c;
  ASSERT_EQ(drape_cloth_params_init(&c), DRAPE_OK);
  EXPECT_EQ(c.iterations, 1u);

  drape_context* ctx = nullptr;
  ASSERT_EQ(drape_context_create(nullptr, &ctx), DRAPE_OK) << lastError();
  drape_garment_template t;
  ASSERT_EQ(drape_garment_template_init(&t), DRAPE_OK);
  t.particles = 500;
  c.iterations = 4;
  drape_garment* g = nullptr;
  ASSERT_EQ(drape_context_add_garment_template(ctx, nullptr, &t, &c, &g), DRAPE_OK) << lastError();
  drape_cloth_params back;
  back.struct_size = sizeof(back);
  ASSERT_EQ(drape_garment_get_params(g, &back), DRAPE_OK);
  EXPECT_EQ(back.iterations, 4u);
  back.iterations = 0;
  EXPECT_EQ(drape_garment_set_params(g, &back), DRAPE_ERROR_OUT_OF_RANGE);
  EXPECT_NE(lastError().find("iterations"), std::string::npos) << lastError();
  drape_cloth_params still;
  still.struct_size = sizeof(still);
  ASSERT_EQ(drape_garment_get_params(g, &still), DRAPE_OK);
  EXPECT_EQ(still.iterations, 4u);
  EXPECT_EQ(drape_context_destroy(ctx), DRAPE_OK);
}

}  // namespace
