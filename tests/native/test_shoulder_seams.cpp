// Shoulder seams that follow the shoulders (cloth/shoulder_seams.h): a top's (and a dress's) seam
// pins move with a shoulder that rises against the torso, measured from where it sat while its arm
// hung; the collar and a dress's waist stay; skirts and trousers have no seam pins.
#include "body/body_model.h"
#include "body/body_shape.h"
#include "cloth/garment_templates.h"
#include "cloth/shoulder_seams.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace drape {
namespace {

struct Scene {
  ResolvedShape shape;
  BodyModel body;
  GarmentMesh mesh;
  std::vector<int> side;  // per pin: 0 left shoulder, 1 right, -1 not a seam pin (rest body)

  explicit Scene(GarmentKind kind) : shape(resolveShape(BodyShapeInput{})), body(shape, BodyModelParams{}) {
    body.update(restPose(shape, 65.0f));  // the pose templates are cut on
    GarmentTemplateParams p;
    p.kind = kind;
    p.target_particles = 2000;
    std::string err;
    EXPECT_TRUE(makeGarmentTemplate(body, p, mesh, err)) << err;
    const int top = body.chainFirstRing(Chain::Torso) + body.chainRingCount(Chain::Torso) - 1;
    const Vec3 l = body.rings()[static_cast<size_t>(body.chainFirstRing(Chain::ArmL))].centre;
    const Vec3 r = body.rings()[static_cast<size_t>(body.chainFirstRing(Chain::ArmR))].centre;
    for (size_t k = 0; k < mesh.pinned.size(); ++k) {
      const Vec3& x = mesh.positions[mesh.pinned[k]];
      side.push_back(mesh.pin_ring[k] != top ? -1 : (x - r).squaredNorm() < (x - l).squaredNorm() ? 1 : 0);
    }
  }

  // Arms hanging straight down; the right shoulder (and its arm) `lift` metres higher and its upper
  // arm `raise_deg` from straight down towards straight up, sideways.
  SkeletonPose pose(float lift, float raise_deg) const {
    SkeletonPose p = restPose(shape, 90.0f);
    const Vec3 up(0.0f, 1.0f, 0.0f);
    const float a = raise_deg * 3.14159265f / 180.0f;
    const Vec3 dir = Vec3(-std::sin(a), -std::cos(a), 0.0f);  // the right arm goes out along -x
    const Joint arm[4] = {Joint::ShoulderR, Joint::ElbowR, Joint::WristR, Joint::HandR};
    p.position[idx(Joint::ShoulderR)] += lift * up;
    for (int k = 1; k < 4; ++k) {
      const float len = (p.position[idx(arm[k])] - p.position[idx(arm[k - 1])]).norm();
      p.position[idx(arm[k])] = p.position[idx(arm[k - 1])] + len * dir;
    }
    return p;
  }

  std::vector<Vec3> shifts(const ShoulderSeams& s) const {
    std::vector<Vec3> t(mesh.pinned.size(), Vec3::Zero());
    s.shift(body, t);
    return t;
  }
};

TEST(ShoulderSeams, SeamPinsFollowARisingShoulder) {
  for (GarmentKind kind : {GarmentKind::TShirt, GarmentKind::LongSleeve, GarmentKind::Dress}) {
    Scene sc(kind);
    ShoulderSeams seams;
    seams.bind(sc.body, sc.mesh.positions, sc.mesh.pinned, sc.mesh.pin_ring);
    ASSERT_TRUE(seams.active());
    int left = 0, right = 0;
    for (int s : sc.side) {
      left += s == 0 ? 1 : 0;
      right += s == 1 ? 1 : 0;
    }
    ASSERT_GT(left, 0);
    ASSERT_GT(right, 0);

    sc.body.update(sc.pose(0.0f, 0.0f));
    for (int f = 0; f < 40; ++f) seams.observe(sc.body, 1.0f / 30.0f);
    for (const Vec3& t : sc.shifts(seams)) EXPECT_LT(t.norm(), 1e-4f) << "the shoulder has not moved";

    // The right shoulder up 8 cm with its arm raised overhead (Ges01's waving arm: 10 cm).
    sc.body.update(sc.pose(0.08f, 160.0f));
    const std::vector<Vec3> t = sc.shifts(seams);
    for (size_t k = 0; k < t.size(); ++k) {
      if (sc.side[k] == 1) {
        EXPECT_GT(t[k].y(), 0.05f) << "pin " << k << " of the right seam";
        EXPECT_LT(t[k].y(), 0.11f) << "pin " << k << " of the right seam";
      } else {
        EXPECT_LT(t[k].norm(), 0.005f) << "pin " << k << " (left seam, collar or waist) moved with the right shoulder";
      }
    }
    // More of the raised arm (the baseline is not learnt while it is up): the same place.
    for (int f = 0; f < 60; ++f) seams.observe(sc.body, 1.0f / 30.0f);
    const std::vector<Vec3> again = sc.shifts(seams);
    for (size_t k = 0; k < t.size(); ++k) EXPECT_LT((again[k] - t[k]).norm(), 1e-5f);
  }
}

TEST(ShoulderSeams, AnArmRaisedFromTheStartIsMeasuredOnceItHangs) {
  Scene sc(GarmentKind::TShirt);
  ShoulderSeams seams;
  seams.bind(sc.body, sc.mesh.positions, sc.mesh.pinned, sc.mesh.pin_ring);
  sc.body.update(sc.pose(0.08f, 160.0f));
  for (int f = 0; f < 60; ++f) seams.observe(sc.body, 1.0f / 30.0f);
  const std::vector<Vec3> before = sc.shifts(seams);
  for (size_t k = 0; k < before.size(); ++k) {
    if (sc.side[k] == 1) EXPECT_EQ(before[k].norm(), 0.0f) << "the right arm never hung: its seam stays put";
    else EXPECT_LT(before[k].norm(), 1e-4f) << "the left arm hung where it hangs now";
  }
  sc.body.update(sc.pose(0.0f, 0.0f));
  for (int f = 0; f < 30; ++f) seams.observe(sc.body, 1.0f / 30.0f);
  sc.body.update(sc.pose(0.08f, 160.0f));
  for (size_t k = 0; k < sc.side.size(); ++k)
    if (sc.side[k] == 1) EXPECT_GT(sc.shifts(seams)[k].y(), 0.05f);
  // A new placement forgets it.
  seams.restart();
  for (const Vec3& t : sc.shifts(seams)) EXPECT_EQ(t.norm(), 0.0f);
}

TEST(ShoulderSeams, NotForGarmentsWithoutSeamPins) {
  for (GarmentKind kind : {GarmentKind::Skirt, GarmentKind::Trousers}) {
    Scene sc(kind);
    ShoulderSeams seams;
    seams.bind(sc.body, sc.mesh.positions, sc.mesh.pinned, sc.mesh.pin_ring);
    EXPECT_FALSE(seams.active()) << garmentKindName(kind);
    sc.body.update(sc.pose(0.0f, 0.0f));
    for (int f = 0; f < 40; ++f) seams.observe(sc.body, 1.0f / 30.0f);
    sc.body.update(sc.pose(0.08f, 160.0f));
    for (const Vec3& t : sc.shifts(seams)) EXPECT_EQ(t.norm(), 0.0f);
  }
}

TEST(ShoulderSeams, BadInputChangesNothing) {
  Scene sc(GarmentKind::TShirt);
  ShoulderSeams seams;
  std::vector<int> short_rings(sc.mesh.pin_ring.begin(), sc.mesh.pin_ring.end() - 1);
  seams.bind(sc.body, sc.mesh.positions, sc.mesh.pinned, short_rings);
  EXPECT_FALSE(seams.active()) << "one ring per pin expected";
  seams.bind(sc.body, sc.mesh.positions, sc.mesh.pinned, sc.mesh.pin_ring);
  sc.body.update(sc.pose(0.0f, 0.0f));
  for (float dt : {0.0f, -1.0f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()})
    seams.observe(sc.body, dt);
  for (const Vec3& t : sc.shifts(seams)) EXPECT_EQ(t.norm(), 0.0f) << "no time observed";
  std::vector<Vec3> few(2, Vec3::Zero());
  seams.shift(sc.body, few);  // fewer targets than pins: only those
  EXPECT_EQ(few[0].norm(), 0.0f);
}

}  // namespace
}  // namespace drape
