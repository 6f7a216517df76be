// Torso cloth of template garments over the thighs (GarmentSim::maskFor, setLegsTrusted, the leg
// clearance after a placement): which cloth meets which leg, and when. docs/garments.md, "Torso
// cloth over the thighs".
#include "garment_scene.h"
#include "test_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace drape {
namespace {

constexpr uint8_t kLegBits = chainGroup(Chain::LegL) | chainGroup(Chain::LegR);
constexpr uint8_t kArmBits = chainGroup(Chain::ArmL) | chainGroup(Chain::ArmR);
constexpr uint8_t kOverBits = kTorsoOverLegL | kTorsoOverLegR;

// A T-shirt's torso cloth meets the leg on its side (the nearer thigh ring), never both; its
// sleeves and a pair of trousers' legs meet none that way; an OBJ garment's cloth (maskFor without
// torso_meets_legs) none at all.
TEST(GarmentLegGroups, TemplateTorsoClothMeetsTheLegOnItsSide) {
  Context ctx(test::defaultDesc());
  const BodyModel& body = ctx.restBody();
  const Vec3& thighL = body.rings()[static_cast<size_t>(body.chainFirstRing(Chain::LegL))].centre;
  const Vec3& thighR = body.rings()[static_cast<size_t>(body.chainFirstRing(Chain::LegR))].centre;
  for (GarmentKind kind : {GarmentKind::TShirt, GarmentKind::Trousers}) {
    std::string err;
    GarmentSim* g = test::addTemplate(ctx, kind, 600, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
    ASSERT_NE(g, nullptr) << err;
    const auto& masks = g->particleMasks();
    const auto& rest = g->mesh().positions;
    ASSERT_EQ(masks.size(), rest.size());
    size_t left = 0, right = 0;
    for (size_t i = 0; i < masks.size(); ++i) {
      const uint8_t m = masks[i];
      EXPECT_EQ(GarmentSim::maskFor(body, body.rings(), rest[i], false, true) & kOverBits, 0) << "particle " << i;
      const bool torso = (m & chainGroup(Chain::Torso)) && !(m & (kLegBits | kArmBits));
      if (!torso) {
        EXPECT_EQ(m & kOverBits, 0) << "sleeve or trouser-leg particle " << i;
        continue;
      }
      const bool l = (m & kTorsoOverLegL) != 0, r = (m & kTorsoOverLegR) != 0;
      EXPECT_NE(l, r) << "torso particle " << i << " meets exactly one leg";
      EXPECT_EQ(l, (rest[i] - thighL).squaredNorm() < (rest[i] - thighR).squaredNorm()) << "particle " << i;
      left += l;
      right += r;
    }
    EXPECT_GT(left, 0u);
    EXPECT_GT(right, 0u);
  }
}

// A leg the host does not trust (its hip or knee not Tracked: Context::beginStep) keeps its
// ellipsoids from the torso cloth, and the pelvis fill (built from both thighs) too; the other
// leg's and every other ellipsoid's groups stay as they were given.
TEST(GarmentLegGroups, UntrustedLegIsPassedThrough) {
  Context ctx(test::defaultDesc());
  std::string err;
  GarmentSim* g = test::addTemplate(ctx, GarmentKind::TShirt, 600, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
  ASSERT_NE(g, nullptr) << err;
  const std::vector<uint8_t>& base = ctx.restEllipsoidGroups();
  for (const bool left : {false, true}) {
    g->setLegsTrusted(left, !left);
    const std::vector<uint8_t>& now = g->ellipsoidGroups();
    ASSERT_EQ(now.size(), base.size());
    size_t legs = 0, pelvis = 0;
    for (size_t k = 0; k < base.size(); ++k) {
      if (base[k] == kPelvisFillGroups) {
        EXPECT_EQ(now[k], 0) << "the pelvis fill, ellipsoid " << k << ", met with a leg untrusted";
        ++pelvis;
        continue;
      }
      EXPECT_EQ(now[k] & ~kOverBits, base[k]) << "ellipsoid " << k;
      if (base[k] & chainGroup(Chain::LegL)) {
        EXPECT_EQ((now[k] & kTorsoOverLegL) != 0, left) << "ellipsoid " << k;
        ++legs;
      }
      if (base[k] & chainGroup(Chain::LegR)) {
        EXPECT_EQ((now[k] & kTorsoOverLegR) != 0, !left) << "ellipsoid " << k;
        ++legs;
      }
      if (!(base[k] & kLegBits)) EXPECT_EQ(now[k] & kOverBits, 0) << "ellipsoid " << k;
    }
    EXPECT_GT(legs, 0u);
    EXPECT_EQ(pelvis, 1u);
  }
  g->setLegsTrusted(true, true);
  for (size_t k = 0; k < base.size(); ++k) {
    if (base[k] & chainGroup(Chain::LegL)) EXPECT_NE(g->ellipsoidGroups()[k] & kTorsoOverLegL, 0);
    if (base[k] & chainGroup(Chain::LegR)) EXPECT_NE(g->ellipsoidGroups()[k] & kTorsoOverLegR, 0);
    if (base[k] == kPelvisFillGroups) EXPECT_EQ(g->ellipsoidGroups()[k], kPelvisFillGroups);
  }
}

// The pelvis fill is met by a T-shirt's torso cloth (both sides), not by template trousers (cut
// round it instead), nor by an OBJ garment's cloth, which has no kTorsoOverLeg bits (the first test).
TEST(GarmentLegGroups, PelvisFillMetByTopsNotByTrousers) {
  Context ctx(test::defaultDesc());
  const std::vector<uint8_t>& base = ctx.restEllipsoidGroups();
  const auto fill = std::find(base.begin(), base.end(), kPelvisFillGroups);
  ASSERT_NE(fill, base.end());
  EXPECT_EQ(std::count(base.begin(), base.end(), kPelvisFillGroups), 1);
  const size_t k = static_cast<size_t>(fill - base.begin());
  for (GarmentKind kind : {GarmentKind::TShirt, GarmentKind::Dress, GarmentKind::Trousers}) {
    std::string err;
    GarmentSim* g = test::addTemplate(ctx, kind, 600, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
    ASSERT_NE(g, nullptr) << err;
    const bool met = kind != GarmentKind::Trousers;
    EXPECT_EQ(g->ellipsoidGroups()[k], met ? kPelvisFillGroups : 0) << garmentKindName(kind);
    size_t meeting = 0;
    for (uint8_t m : g->particleMasks()) meeting += (m & g->ellipsoidGroups()[k]) != 0;
    if (met) {
      EXPECT_GT(meeting, 0u) << garmentKindName(kind);
    } else {
      EXPECT_EQ(meeting, 0u) << garmentKindName(kind);
    }
  }
}

// The close-range Kinect take starts on a person whose legs come forward into the lap (seated, or
// guessed so): the T-shirt is placed with its hem through the thighs. The thigh ellipsoids that
// hold torso cloth then do not meet it until it is out of them, while the other ellipsoids of a
// trusted leg do; after every step no ellipsoid that meets the torso cloth has any of it deep
// inside for more than one frame. Met, those ellipsoids pushed the hem out at once and tore it
// (P99 stretch 1.20 on its worst frame against the 0.95 of GarmentOnRecording). One frame: since
// the garment is carried into the first pose (cloth/placement_path.h) its hem lies over the
// guessed thigh instead of through it, and in frame 13 that thigh jumps over a hem particle (the
// centre of one of the two ellipsoids it ends in moves 4.7 cm in that frame), which is out again
// the next frame: the collider's escape step leaves a particle that would have to move more than
// 1 cm where its sequential passes put it (CollisionParams::max_escape_m), here inside two
// overlapping thigh ellipsoids.
TEST(GarmentLegGroups, ThighsPlacedThroughTheHemWaitUntilItIsOut) {
  DRAPE_REQUIRE_SHARED(path, "kinect_v2_msft_labanotation/KinectReader_joints_closerange.csv");
  Recording rec;
  std::string err;
  Context ctx(test::defaultDesc());
  GarmentSim* g = test::readTakeAndAddTShirt(ctx, path, 1000, rec, err);
  ASSERT_NE(g, nullptr) << err;
  const std::vector<uint8_t>& base = ctx.restEllipsoidGroups();
  size_t mostWaiting = 0;
  float worst_meeting = 0.0f;
  std::vector<uint8_t> deep_before, deep_now;  // per particle: deep inside a meeting leg ellipsoid
  int deep_particle_frames = 0;
  const size_t frames = std::min<size_t>(rec.frames.size(), 60);
  for (size_t f = 0; f < frames; ++f) {
    const float dt = f > 0 ? static_cast<float>(rec.frames[f].time_s - rec.frames[f - 1].time_s) : 1.0f / 30.0f;
    ASSERT_EQ(test::pushAndStep(ctx, rec, rec.frames[f], rec.frames[f].time_s, dt, err), DRAPE_OK) << err;
    const std::vector<Ellipsoid>& e = ctx.proxies().ellipsoids();
    const std::vector<uint8_t>& now = g->ellipsoidGroups();
    const auto& masks = g->particleMasks();
    const Eigen::Vector4f* x = g->positions();
    // A side is trusted this step when any of its leg's ellipsoids meets the torso cloth.
    bool trusted[2] = {false, false};
    for (size_t k = 0; k < base.size(); ++k) {
      if (base[k] & chainGroup(Chain::LegL) && now[k] & kTorsoOverLegL) trusted[0] = true;
      if (base[k] & chainGroup(Chain::LegR) && now[k] & kTorsoOverLegR) trusted[1] = true;
    }
    size_t waiting = 0;
    deep_now.assign(masks.size(), 0);
    for (size_t k = 0; k < base.size() && k < e.size(); ++k) {
      if (!(base[k] & kLegBits)) continue;
      const int side = (base[k] & chainGroup(Chain::LegL)) ? 0 : 1;
      const uint8_t over = side == 0 ? kTorsoOverLegL : kTorsoOverLegR;
      if (!(now[k] & over)) {
        waiting += trusted[side];
        continue;
      }
      for (size_t i = 0; i < masks.size(); ++i) {
        if (!(masks[i] & over)) continue;
        // -0.12: ~6 % of the radius, a few millimetres (cloth pinched where two ellipsoids it meets
        // overlap reached -0.05, and -0.101 in one frame since the strain limit holds the cloth
        // tighter); cloth the thigh had passed into lies up to its axis (-1).
        worst_meeting = std::min(worst_meeting, e[k].implicit(x[i].head<3>()));
        if (e[k].implicit(x[i].head<3>()) >= -0.12f) continue;
        EXPECT_FALSE(i < deep_before.size() && deep_before[i])
            << "frame " << f << ": torso particle " << i << " still deep inside leg ellipsoid " << k
            << ", which meets it (implicit " << e[k].implicit(x[i].head<3>()) << ")";
        deep_now[i] = 1;
      }
    }
    for (uint8_t d : deep_now) deep_particle_frames += d;
    deep_before.swap(deep_now);
    mostWaiting = std::max(mostWaiting, waiting);
  }
  std::printf("[ figures  ] at most %zu ellipsoids of a trusted leg waited for the hem to leave them; deepest torso "
              "particle in a leg ellipsoid that meets it: implicit %.4f; particle-frames deeper than -0.12: %d\n",
              mostWaiting, worst_meeting, deep_particle_frames);
  EXPECT_GT(mostWaiting, 0u);
  EXPECT_LE(deep_particle_frames, 3);
}

// A body shape change cuts the garments again (GarmentSim::refitted, both ways: the template made
// again, and the cut carried by ring skinning): a template's torso cloth still meets the leg on
// its side afterwards. (Until 2026-11-28 the new cut lost it.)
TEST(GarmentLegGroups, RefitKeepsTheTorsoClothMeetingTheLegs) {
  for (const bool remake : {true, false}) {
    Context ctx(test::defaultDesc());
    std::string err;
    GarmentSim* g = test::addTemplate(ctx, GarmentKind::TShirt, 600, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
    ASSERT_NE(g, nullptr) << err;
    auto torsoOverLegs = [&](const GarmentSim& garment) {
      size_t torso = 0, over = 0;
      for (uint8_t m : garment.particleMasks()) {
        if (!(m & chainGroup(Chain::Torso)) || (m & (kLegBits | kArmBits))) continue;
        ++torso;
        over += ((m & kTorsoOverLegL) != 0) != ((m & kTorsoOverLegR) != 0);
      }
      return std::make_pair(torso, over);
    };
    const auto before = torsoOverLegs(*g);
    ASSERT_GT(before.first, 0u);
    EXPECT_EQ(before.second, before.first);
    std::unique_ptr<GarmentSim> cut = g->refitted(ctx.restBody(), ctx.restEllipsoids(), ctx.restEllipsoidGroups(), err, remake);
    ASSERT_NE(cut, nullptr) << err;
    const auto after = torsoOverLegs(*cut);
    EXPECT_GT(after.first, 0u) << (remake ? "template made again" : "ring skinning");
    EXPECT_EQ(after.second, after.first) << (remake ? "template made again" : "ring skinning");
    // Through the context: a taller, heavier person.
    BodyShapeInput tall;
    tall.height_m = 1.90f;
    tall.weight_kg = 90.0f;
    ASSERT_EQ(ctx.setShape(tall, err), DRAPE_OK) << err;
    ASSERT_EQ(g->refits(), 1u);
    const auto reshaped = torsoOverLegs(*g);
    EXPECT_GT(reshaped.first, 0u);
    EXPECT_EQ(reshaped.second, reshaped.first);
  }
}

}  // namespace
}  // namespace drape
