// Ring-space skinning (cloth/ring_skin.h). RingSkin::bind skips the segments whose lower bound
// says they can be neither a point's nearest segment nor one of its blended ones; this checks the
// result against binding every segment (the method as written in the header), bit for bit, for
// points on and around the body, with and without blending, placed on the rings bound to and on
// moved, rescaled rings.
#include "garment_scene.h"
#include "random_draws.h"
#include "sanitizer_scale.h"

#include "cloth/garment_templates.h"
#include "cloth/ring_skin.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace drape {
namespace {

// The brute-force binding: every segment of every chain, nearest first found, blend weights
// exp(-(d - d_min) / blend) kept from 0.018 up, normalised; placement summed in chain order.
struct Reference {
  std::vector<RingBinding> primary, blend;
  std::vector<float> weight;
  std::vector<uint32_t> offset{0};

  void bind(const BodyModel& body, const std::vector<Vec3>& points, float blend_m) {
    for (const Vec3& p : points) {
      std::vector<RingBinding> cands;
      for (int c = 0; c < kChainCount; ++c) {
        const int first = body.chainFirstRing(Chain(c)), n = body.chainRingCount(Chain(c));
        for (int i = 0; i + 1 < n; ++i) cands.push_back(bindToSegment(body.rings(), c, first + i, p));
      }
      RingBinding best = cands.front();
      for (const RingBinding& b : cands)
        if (b.dist < best.dist) best = b;
      primary.push_back(best);
      const size_t begin = blend.size();
      float wsum = 0.0f;
      if (blend_m > 0.0f) {
        for (const RingBinding& b : cands) {
          const float w = std::exp(-(b.dist - best.dist) / blend_m);
          if (w < 0.018f) continue;
          blend.push_back(b);
          weight.push_back(w);
          wsum += w;
        }
      } else {
        blend.push_back(best);
        weight.push_back(1.0f);
        wsum = 1.0f;
      }
      for (size_t k = begin; k < weight.size(); ++k) weight[k] /= wsum;
      offset.push_back(static_cast<uint32_t>(blend.size()));
    }
  }
  Vec3 place(const std::vector<RingPose>& rings, size_t i) const {
    Vec3 sum = Vec3::Zero();
    for (uint32_t k = offset[i]; k < offset[i + 1]; ++k) sum += weight[k] * placeBinding(rings, blend[k]);
    return sum;
  }
};

bool sameBits(const Vec3& a, const Vec3& b) { return std::memcmp(a.data(), b.data(), sizeof(float) * 3) == 0; }

TEST(RingSkin, SkippingFarSegmentsBindsAsEverySegment) {
  Context ctx(test::defaultDesc());
  const BodyModel& body = ctx.restBody();
  // Points of two garments (on the body, under the arms, between the legs) and random points
  // up to 25 cm around it.
  std::vector<Vec3> points;
  std::string err;
  for (GarmentKind kind : {GarmentKind::TShirt, GarmentKind::Trousers}) {
    GarmentTemplateParams tp;
    tp.kind = kind;
    tp.target_particles = test::repeatsUnderSanitizers(2000, 4);
    GarmentMesh mesh;
    ASSERT_TRUE(makeGarmentTemplate(body, tp, mesh, err)) << err;
    points.insert(points.end(), mesh.positions.begin(), mesh.positions.end());
  }
  Vec3 lo = Vec3::Constant(1e9f), hi = -lo;
  for (const RingPose& r : body.rings()) {
    lo = lo.cwiseMin(r.centre);
    hi = hi.cwiseMax(r.centre);
  }
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < test::repeatsUnderSanitizers(1500, 4); ++i) {
    const Vec3 f = test::draw3(u, rng);
    points.push_back(lo - Vec3::Constant(0.25f) + f.cwiseProduct(hi - lo + Vec3::Constant(0.5f)));
  }
  // Moved and rescaled rings: a turned, shifted body with thicker limbs.
  std::vector<RingPose> moved = body.rings();
  const Mat3 R = Eigen::AngleAxisf(0.4f, Vec3(0.2f, 1.0f, 0.1f).normalized()).toRotationMatrix();
  for (RingPose& r : moved) {
    r.centre = R * r.centre + Vec3(0.3f, -0.1f, 0.5f);
    r.frame = R * r.frame;
    r.forward_m *= 1.15f;
    r.side_m *= 0.9f;
  }
  for (float blend : {0.0f, 0.015f, 0.05f}) {
    SCOPED_TRACE(::testing::Message() << "blend " << blend);
    RingSkin skin;
    skin.bind(body, points, blend);
    Reference ref;
    ref.bind(body, points, blend);
    ASSERT_EQ(skin.size(), points.size());
    size_t differing = 0, blended = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      const RingBinding& a = skin.primary(i);
      const RingBinding& b = ref.primary[i];
      const bool same = a.chain == b.chain && a.r0 == b.r0 && a.t == b.t && a.dist == b.dist &&
                        sameBits(a.local, b.local) && sameBits(skin.place(body.rings(), i), ref.place(body.rings(), i)) &&
                        sameBits(skin.place(moved, i), ref.place(moved, i));
      differing += same ? 0 : 1;
      blended += ref.offset[i + 1] - ref.offset[i] > 1 ? 1 : 0;
    }
    EXPECT_EQ(differing, 0u);
    if (blend > 0.0f) {
      EXPECT_GT(blended, points.size() / 20);  // the blend is exercised, not only the nearest
    }
  }
}

}  // namespace
}  // namespace drape
