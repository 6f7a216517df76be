// Sleeve cloth that also meets the torso (GarmentSim::maskFor's sleeve_meets_torso): which
// particles do, and what it does on the real take where a hanging sleeve's inner side used to
// sink into the torso (docs/garments.md, "Sleeves meet the torso").
#include "body/arm_clearance.h"
#include "capi/context.h"
#include "cloth/garment_sim.h"
#include "garment_scene.h"
#include "proxies/proxy_builder.h"
#include "test_data.h"

#include <gtest/gtest.h>

#include <cstdio>

namespace drape {
namespace {

constexpr uint8_t kTorso = chainGroup(Chain::Torso);
constexpr uint8_t kArmL = chainGroup(Chain::ArmL), kArmR = chainGroup(Chain::ArmR);

// A long-sleeve (its sleeves reach the wrists): with the arms kept clear of the torso (the
// default), the cloth nearest an upper arm between kSleeveMeetsTorsoFrom and kSleeveMeetsTorsoTo of
// the way to the elbow meets that arm and the torso, and nothing else does: not the armpit end,
// not the elbow and forearm, not the torso cloth. With the arms on their bones no sleeve cloth
// meets the torso, nor when the gap between arm and torso leaves no room for two layers of cloth
// (clearance up to twice the garment's collision margin).
TEST(SleeveGroups, OnlyTheUpperArmsSleeveClothMeetsTheTorso) {
  drape_context_desc clear_desc = test::defaultDesc(), bones_desc = test::defaultDesc();
  bones_desc.arms_clear_torso = 0;
  Context clear(clear_desc), bones(bones_desc);
  std::string err;
  GarmentSim* g = test::addTemplate(clear, GarmentKind::LongSleeve, 1500, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
  ASSERT_NE(g, nullptr) << err;
  GarmentSim* g_bones =
      test::addTemplate(bones, GarmentKind::LongSleeve, 1500, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
  ASSERT_NE(g_bones, nullptr) << err;

  // The rings the masks are judged on: the rest body's with its arms moved clear (create()).
  const BodyModel& body = clear.restBody();
  std::vector<RingPose> rings = body.rings();
  Vec3 unused[2];
  keepArmsOutOfTorso(body, rings, ArmClearance{clear_desc.arm_torso_clearance_m, 1.0f}, unused);

  const auto& masks = g->particleMasks();
  const auto& rest = g->mesh().positions;
  ASSERT_EQ(masks.size(), rest.size());
  int meets = 0, armpit = 0, forearm = 0;
  for (size_t i = 0; i < masks.size(); ++i) {
    float u = -1.0f;
    const Chain chain = static_cast<Chain>(GarmentSim::nearestChain(body, rings, rest[i], &u));
    const uint8_t m = masks[i];
    if (chain != Chain::ArmL && chain != Chain::ArmR) {
      EXPECT_EQ(m & (kArmL | kArmR), 0) << "particle " << i << " nearest the " << chainName(chain);
      continue;
    }
    EXPECT_EQ(m & (kArmL | kArmR), chain == Chain::ArmL ? kArmL : kArmR) << "particle " << i;
    const bool upper = u >= GarmentSim::kSleeveMeetsTorsoFrom && u <= GarmentSim::kSleeveMeetsTorsoTo;
    EXPECT_EQ((m & kTorso) != 0, upper) << "particle " << i << " at u = " << u;
    EXPECT_EQ(m & ~(kArmL | kArmR | kTorso), 0) << "particle " << i;  // no head, leg or thigh bits
    meets += upper ? 1 : 0;
    armpit += u < GarmentSim::kSleeveMeetsTorsoFrom ? 1 : 0;
    forearm += u > 1.0f ? 1 : 0;
  }
  std::printf("[ figures  ] long-sleeve, %zu particles: %d sleeve particles meet the torso, %d at the armpit end and "
              "%d on the forearm do not\n",
              masks.size(), meets, armpit, forearm);
  EXPECT_GT(meets, 50);
  EXPECT_GT(armpit, 0);
  EXPECT_GT(forearm, 50);
  for (size_t i = 0; i < g_bones->particleMasks().size(); ++i) {
    const uint8_t m = g_bones->particleMasks()[i];
    EXPECT_FALSE((m & (kArmL | kArmR)) && (m & kTorso)) << "particle " << i << ", arms on the bones";
  }

  // No room: 8 mm between arm and torso and the default 4 mm margin; 1 cm and a 6 mm margin.
  drape_context_desc tight_desc = test::defaultDesc();
  tight_desc.arm_torso_clearance_m = 0.008f;
  Context tight(tight_desc);
  GarmentSimParams thick;
  thick.collision_margin_m = 0.006f;
  const struct {
    Context* ctx;
    GarmentSimParams params;
    const char* what;
  } no_room[] = {{&tight, GarmentSimParams{}, "8 mm clearance"}, {&clear, thick, "6 mm margin"}};
  for (const auto& c : no_room) {
    GarmentSim* n = test::addTemplate(*c.ctx, GarmentKind::LongSleeve, 1500, ClothSolverKind::Xpbd, c.params, err);
    ASSERT_NE(n, nullptr) << err;
    int sleeve = 0;
    for (size_t i = 0; i < n->particleMasks().size(); ++i) {
      const uint8_t m = n->particleMasks()[i];
      sleeve += (m & (kArmL | kArmR)) ? 1 : 0;
      EXPECT_FALSE((m & (kArmL | kArmR)) && (m & kTorso)) << "particle " << i << ", " << c.what;
    }
    EXPECT_GT(sleeve, 300) << c.what;
  }
}

// Ges01: while the right arm waves overhead the left hangs, and its sleeve's inner side, meeting
// only the arm, lay inside the torso beside it: the worst frame's P99 depth inside the body mesh
// was 11-13 mm at 1 500-2 500 particles (sleeve vertices up to 31 mm deep), now 4.6-6.7 mm in
// drape-replay. Here (the same scene through the test driver) the bound is above what was
// measured, 2 000 particles, and below every figure from before.
TEST(SleeveGroups, Ges01HangingSleeveStaysOutOfTheTorso) {
  DRAPE_REQUIRE_SHARED(path, "kinect_v2_msft_labanotation/Ges01_wavehand.csv");
  Recording rec;
  std::string err;
  Context ctx(test::defaultDesc());
  ASSERT_TRUE(readRecordingFile(path, 0, rec, err)) << err;
  GarmentSim* g = test::addTemplate(ctx, GarmentKind::TShirt, 2000, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
  ASSERT_NE(g, nullptr) << err;
  const test::SceneSummary s = test::replay(ctx, *g, rec, err, /*measure_body=*/true);
  ASSERT_EQ(s.frames, static_cast<int>(rec.frames.size())) << err;
  std::printf("[ figures  ] Ges01 T-shirt, 2 000 particles: worst frame's penetration P99 %.2f mm, max %.2f mm, "
              "inside %llu, off in %d frames\n",
              s.penetration_p99_max_mm, s.penetration_max_mm, static_cast<unsigned long long>(s.proxy_inside),
              s.openings_off_frames);
  EXPECT_TRUE(s.finite);
  EXPECT_EQ(s.proxy_inside, 0u);
  EXPECT_LT(s.penetration_p99_max_mm, 9.0f);
}

}  // namespace
}  // namespace drape
