// Body model on synthetic poses: closed mesh, volume, girths, shoulder junction.
#include "body/body_model.h"
#include "body/mesh_metrics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace drape {
namespace {

ResolvedShape shapeOf(float height, float weight) {
  BodyShapeInput in;
  in.height_m = height;
  in.weight_kg = weight;
  return resolveShape(in);
}

void expectClosed(const BodyModel& body, const char* what) {
  const MeshCheck c = checkMesh(body.positions(), body.indices());
  EXPECT_TRUE(c.watertight) << what << ": " << c.first_problem << " boundary=" << c.boundary_edges
                            << " nonmanifold=" << c.nonmanifold_edges;
  EXPECT_TRUE(c.consistent_winding) << what << ": " << c.first_problem;
  EXPECT_EQ(c.degenerate_triangles, 0) << what << ": " << c.first_problem;
}

TEST(BodyModel, RestPoseIsClosedAndOutward) {
  for (int K : {8, 20, 64}) {
    for (int extra : {0, 1, 3}) {
      BodyModelParams p;
      p.ring_points = K;
      p.rings_per_segment = extra;
      BodyModel body(shapeOf(1.70f, 65.0f), p);
      body.update(restPose(body.shape()));
      expectClosed(body, ("K=" + std::to_string(K) + " extra=" + std::to_string(extra)).c_str());
      EXPECT_GT(signedVolume(body.positions(), body.indices()), 0.0) << "K=" << K;
    }
  }
}

TEST(BodyModel, VolumeMatchesWeightOverDensity) {
  for (auto [h, w] : {std::pair{1.70f, 65.0f}, {1.55f, 50.0f}, {1.85f, 95.0f}, {1.63f, 66.0f}}) {
    BodyModel body(shapeOf(h, w), BodyModelParams{});
    body.update(restPose(body.shape()));
    const double litres = 1000.0 * signedVolume(body.positions(), body.indices());
    const double expected = w / 1010.0 * 1000.0;
    EXPECT_NEAR(litres, expected, 0.10 * expected) << "height " << h << " weight " << w;
  }
}

TEST(BodyModel, MeasuredRingsMatchGirths) {
  for (int K : {8, 20, 64}) {
    BodyModelParams p;
    p.ring_points = K;
    const ResolvedShape shape = shapeOf(1.70f, 65.0f);
    BodyModel body(shape, p);
    body.update(restPose(shape));
    int measured = 0;
    for (size_t r = 0; r < body.stations().size(); ++r) {
      const int m = body.stations()[r].measure;
      if (m < 0) continue;
      ++measured;
      const float perimeter = polygonPerimeter(&body.positions()[r * K], K);
      EXPECT_NEAR(perimeter, shape.m[m], 0.01f * shape.m[m]) << measureName(static_cast<Measure>(m));
    }
    EXPECT_EQ(measured, 4 + 2 * 4);  // neck, chest, waist, hip; thigh, calf, upper arm, forearm per side
  }
}

}  // namespace
}  // namespace drape
