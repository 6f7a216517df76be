// A garment on every real recording in ../shared/data (four Kinect v2 captures, four CMU BVH
// takes), driven exactly as the C ABI drives it: every output finite, no NaN reset, no particle
// inside an ellipsoid of its collision groups after a step except where cloth is pinched between
// touching body parts (under 0.5 % of particle-frames: the escape step is limited to 1 cm, see
// proxies/collision.h), speeds bounded, stretch bounded.
// The bounds are the measured worst case plus a margin (docs/garments.md has the figures); they
// are far from the product goal (P99 <= 5 %) and catch regressions, not quality.
#include "garment_scene.h"
#include "test_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

namespace drape {
namespace {

struct Take {
  const char* file;
  float p99_bound;  // per-frame P99 stretch, worst frame: measured worst + ~25 % (the CMU takes
                    // swing between 0.75 and 1.15 from one setting to the next: chaotic)
  int max_off;      // frames with an opening off its body part allowed, -1 = not checked
                    // (docs/garments.md, "Openings"). CMU: until the BVH reader put
                    // SpineShoulder level with the shoulders (docs/garments.md, "CMU takes: the
                    // spine mapped as a Kinect maps it") the shoulders came through the shirt and a
                    // sleeve was off in 772 / 417 / 749 / 555 frames of these takes here (worst
                    // frame's P99 0.74-1.01, inside 95-103); now 0 on the walks and 113 / 125 on
                    // the hops (airborne phases, arms flung), worst 0.44-0.52. Ges01: the waving
                    // arm's sleeve slid off at frame 51 and never came back (105 of 154 frames)
                    // until the seam pins followed the shoulders (cloth/shoulder_seams.h): 31
                    // then, at the end of the second raise (docs/garments.md, "Shoulder seams
                    // follow the shoulders"); 0
                    // since the garment is carried into the first pose (cloth/placement_path.h).
                    // Close range: 2 of 371 frames (around frame 52) once the shoulder fills came
                    // (docs/proxies.md), the renders of frames 51-53 showing the hands through the
                    // hem at the hips (torso cloth does not collide with the arms' ellipsoids);
                    // 0 now. Since the arms are kept clear of the torso (body/arm_clearance.h):
                    // the CMU hops 8 / 8, the walks 0, close range 0, Ges01 24 (the waving
                    // sleeve at this resolution; 0-85 at others before and after, docs/garments.md,
                    // "Arms clear of the torso"); worst frames' P99 0.21-0.29 on the CMU takes
};

const Take kTakes[] = {
    {"kinect_v2_msft_labanotation/Ges01_wavehand.csv", 1.0f, 60},
    {"kinect_v2_msft_labanotation/Ges02_balancinghands.csv", 0.4f, 0},
    {"kinect_v2_msft_labanotation/Ges04_comehere.csv", 0.45f, 0},
    {"kinect_v2_msft_labanotation/KinectReader_joints_closerange.csv", 0.95f, 2},
    {"cmu_mocap_bvh/131_01.bvh", 1.3f, 40},
    {"cmu_mocap_bvh/131_03.bvh", 1.3f, 250},
    {"cmu_mocap_bvh/scaled_131_01.bvh", 1.3f, 40},
    {"cmu_mocap_bvh/scaled_131_03.bvh", 1.3f, 250},
};

class GarmentOnRecording : public ::testing::TestWithParam<Take> {};

TEST_P(GarmentOnRecording, TShirtStaysFiniteOutsideAndBounded) {
  DRAPE_REQUIRE_SHARED(path, GetParam().file);
  Recording rec;
  std::string err;
  Context ctx(test::defaultDesc());
  GarmentSim* g = test::readTakeAndAddTShirt(ctx, path, 1000, rec, err);
  ASSERT_NE(g, nullptr) << err;
  const test::SceneSummary s = test::replay(ctx, *g, rec, err, /*measure_body=*/false);
  std::printf("[ figures  ] %s: %d frames, P99 stretch median %.3f worst %.3f, max %.3f, inside %llu, vmax %.2f m/s, "
              "%u openings, off in %d frames\n",
              GetParam().file, s.frames, s.p99_stretch_median, s.p99_stretch_worst, s.max_stretch,
              static_cast<unsigned long long>(s.proxy_inside), s.max_speed, s.openings, s.openings_off_frames);
  ASSERT_EQ(s.frames, static_cast<int>(rec.frames.size())) << err;
  EXPECT_TRUE(s.finite);
  EXPECT_EQ(s.nan_resets, 0);
  EXPECT_LT(static_cast<double>(s.proxy_inside), 0.005 * s.frames * static_cast<double>(g->particleCount()));
  EXPECT_LT(s.max_speed, 50.0f);  // limbs reach 10-15 m/s; corrections add to that, explosions far more
  EXPECT_LT(s.p99_stretch_worst, GetParam().p99_bound);
  EXPECT_EQ(s.openings, 4u);  // hem, collar, two sleeves
  if (GetParam().max_off >= 0) EXPECT_LE(s.openings_off_frames, GetParam().max_off) << "an opening left its body part";
}

// The close-range take's first frames guess both knees above the hips and the shins crossed (the
// legs are out of view); they come down within two seconds. A garment skinned straight onto that
// first pose was threaded through by the legs and stayed torn (skirt P99 stretch 4-6.7 over the
// take, dress 1.3-1.7); carried into it from the rest pose (cloth/placement_path.h) it comes
// through (docs/garments.md, "Dressed by moving into the first pose").
TEST(GarmentOnCloseRange, LowerBodyGarmentsComeThroughTheGuessedLegs) {
  DRAPE_REQUIRE_SHARED(path, "kinect_v2_msft_labanotation/KinectReader_joints_closerange.csv");
  Recording rec;
  std::string err;
  ASSERT_TRUE(readRecordingFile(path, 0, rec, err)) << err;
  for (GarmentKind kind : {GarmentKind::Skirt, GarmentKind::Dress, GarmentKind::Trousers}) {
    Context ctx(test::defaultDesc());
    GarmentSim* g = test::addTemplate(ctx, kind, 1000, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
    ASSERT_NE(g, nullptr) << err;
    const test::SceneSummary s = test::replay(ctx, *g, rec, err, /*measure_body=*/false);
    std::printf("[ figures  ] close range, %s: P99 stretch median %.3f p90 %.3f worst %.3f, max %.3f, inside %llu, "
                "off in %d frames\n",
                garmentKindName(kind), s.p99_stretch_median, s.p99_stretch_p90, s.p99_stretch_worst, s.max_stretch,
                static_cast<unsigned long long>(s.proxy_inside), s.openings_off_frames);
    ASSERT_EQ(s.frames, static_cast<int>(rec.frames.size())) << err;
    EXPECT_TRUE(s.finite);
    EXPECT_EQ(s.nan_resets, 0);
    if (kind == GarmentKind::Skirt) {  // skinned: median 2.62, off in all 371 frames
      EXPECT_LT(s.p99_stretch_median, 0.5f);
      EXPECT_LE(s.openings_off_frames, 30);
    } else if (kind == GarmentKind::Dress) {  // skinned: median 0.98, off in all 371 frames
      EXPECT_LT(s.p99_stretch_median, 0.3f);
      EXPECT_LE(s.openings_off_frames, 40);
    }
    // Trousers: cut for the standard body's legs, which the sensor measures shorter here, their
    // hems hang below the ankles in every frame either way (docs/garments.md, "Openings"); median
    // 0.51 skinned, 0.49 carried.
  }
}

// A template cut as drape_garment_desc_init cuts it (DRAPE_GARMENT_CUT_BY_KIND: trousers and long
// sleeves for the person's skeleton) and replayed over the first `max_frames` frames of a take,
// every third frame measured for openings off their body part.
struct ByKindRun {
  int measured = 0, off = 0;
  uint32_t refits_after_first = 0, refits = 0;
};

void replayByKind(const std::string& path, GarmentKind kind, uint32_t particles, size_t max_frames, ByKindRun& run) {
  Recording rec;
  std::string err;
  ASSERT_TRUE(readRecordingFile(path, 0, rec, err)) << err;
  Context ctx(test::defaultDesc());  // garment_fit: the shape's, as by default
  const Context::RestCut cut = ctx.cutFor(DRAPE_GARMENT_CUT_BY_KIND, garmentReachesLimbEnds(kind));
  if (garmentReachesLimbEnds(kind)) ASSERT_EQ(cut, Context::kCutSkeleton);
  GarmentTemplateParams tp;
  tp.kind = kind;
  tp.target_particles = particles;
  auto made = GarmentSim::createTemplate(tp, TopologyParams{}, ClothSolverKind::Xpbd, GarmentSimParams{}, 0.5f,
                                         ctx.restBody(cut), ctx.restEllipsoids(cut), ctx.restEllipsoidGroups(cut), err);
  ASSERT_NE(made, nullptr) << err;
  GarmentSim* g = ctx.adoptGarment(std::move(made), cut);
  double prev = rec.frames[0].time_s - 1.0 / 30.0;
  for (size_t f = 0; f < rec.frames.size() && f < max_frames; ++f) {
    const RecordingFrame& fr = rec.frames[f];
    ASSERT_EQ(test::pushAndStep(ctx, rec, fr, fr.time_s, static_cast<float>(fr.time_s - prev), err), DRAPE_OK) << err;
    prev = fr.time_s;
    if (f == 0) run.refits_after_first = g->refits();
    if (f % 3 != 0) continue;
    ++run.measured;
    if (ctx.measureGarment(*g).openings.off > 0) ++run.off;
  }
  run.refits = g->refits();
}

// Trousers as drape_garment_desc_init cuts them (DRAPE_GARMENT_CUT_BY_KIND) on the Kinect takes:
// cut for the person's legs from the first frame (the provisional fit of the first pose, whose
// limbs the sensor sees: capi/context.h), then again at the calibration when its bones move the
// rest pose by 1 cm or more; they are on the legs in every measured frame. Cut for the shape's
// standard legs until the calibration (before 2026-11-29's thirteenth session), their hems hung
// past the feet for the first second (the Kinect measures these people's legs 16 % shorter), and on
// the shape's cut throughout they were off in every frame (docs/garments.md, "Cut by kind" and "Cut
// for the first pose").
class TrousersByKindOnRecording : public ::testing::TestWithParam<const char*> {};

TEST_P(TrousersByKindOnRecording, StayOnTheLegsFromTheFirstFrame) {
  DRAPE_REQUIRE_SHARED(path, GetParam());
  ByKindRun run;
  ASSERT_NO_FATAL_FAILURE(replayByKind(path, GarmentKind::Trousers, 1000, SIZE_MAX, run));
  std::printf("[ figures  ] %s: trousers off in %d of %d measured frames; cut again %u time(s) by the first step, %u in all\n",
              GetParam(), run.off, run.measured, run.refits_after_first, run.refits);
  EXPECT_EQ(run.refits_after_first, 1u) << "cut for the first pose before its first step";
  EXPECT_LE(run.refits, 2u) << "and at most once more, at the calibration";
  EXPECT_GT(run.measured, 45);
  EXPECT_EQ(run.off, 0) << "a trouser leg off its leg";
}

// The long-sleeve on the CMU hop takes (airborne phases, arms flung; a stub of a hand 3.5 cm past
// the wrist), 2 000 particles, the matrix's 300 frames: with its cuff at a tenth of the forearm
// above the wrist (arm station 1.9, before 2026-11-29's fifteenth session) it rode onto the hand
// and a sleeve was off in 41 and 33 of the 100 measured frames here; a quarter above (1.75) in 5
// and 0 (docs/garments.md, "The long sleeve's cuff"), and 0 and 0 with the closer cuff below.
// Release only (asan_slow: *131_0* instances).
class LongSleeveByKindOnRecording : public ::testing::TestWithParam<const char*> {
 protected:
  // The take's first 300 frames at `particles`: every one of its 100 measured frames is measured,
  // at most 10 with a sleeve off its arm.
  void expectSleevesOn(uint32_t particles) {
    DRAPE_REQUIRE_SHARED(path, GetParam());
    ByKindRun run;
    ASSERT_NO_FATAL_FAILURE(replayByKind(path, GarmentKind::LongSleeve, particles, 300, run));
    std::printf("[ figures  ] %s: long-sleeve (%u particles) off in %d of %d measured frames\n", GetParam(),
                particles, run.off, run.measured);
    EXPECT_EQ(run.measured, 100);
    EXPECT_LE(run.off, 10) << "a sleeve off its arm";
  }
};

TEST_P(LongSleeveByKindOnRecording, KeepsItsSleevesOnAHoppingPerson) { expectSleevesOn(2000); }

// The same at 1 500 particles, where the cuff's 16 particles are 4-5 cm apart: cut to the full ease
// (2.5 cm) the stub hand crossed the cuff's rim between two of them and the sleeve counted off
// until the linking came back; at 0.6 of the ease (kLongSleeveCuffEaseScale, docs/garments.md,
// "A closer cuff") it stays on. Off in 39 and 41 of the 100 measured frames at the full ease, 1 and
// 0 now.
TEST_P(LongSleeveByKindOnRecording, KeepsItsSleevesAtFifteenHundredParticles) { expectSleevesOn(1500); }

// Coarse garments: the smallest count of each kind that stays on the limbs over the shared takes
// (drape.h at `particles`; docs/cloth-solver.md, "Coarse garments come off"), on Ges04 (a person
// beckoning, arms raised and lowered), the whole take, every third frame measured. Below these
// counts the limbs leave their tubes on this take: the long-sleeve at 400 particles in 44 of the 58
// measured frames, the T-shirt at 200 in 37, the dress at 300 in 32. The long-sleeve's floor was 800
// until its rings along the sleeve were bounded by the cuff (garment_templates.cpp,
// kBentSleeveRingsPerCuffPerimeter): at 500 it was off in 48 here. Release only (asan_slow: its
// instances are named Ges04*).
struct CoarseGarment {
  GarmentKind kind;
  uint32_t particles;
  const char* name;
};

class CoarseGarmentOnRecording : public ::testing::TestWithParam<CoarseGarment> {};

TEST_P(CoarseGarmentOnRecording, StaysOnAtTheDocumentedFloor) {
  DRAPE_REQUIRE_SHARED(path, "kinect_v2_msft_labanotation/Ges04_comehere.csv");
  ByKindRun run;
  ASSERT_NO_FATAL_FAILURE(replayByKind(path, GetParam().kind, GetParam().particles, SIZE_MAX, run));
  std::printf("[ figures  ] Ges04: %s at %u particles off in %d of %d measured frames\n", GetParam().name,
              GetParam().particles, run.off, run.measured);
  EXPECT_GT(run.measured, 50);
  EXPECT_EQ(run.off, 0) << "an opening off its body part";
}

INSTANTIATE_TEST_SUITE_P(SharedData, CoarseGarmentOnRecording,
                         ::testing::Values(CoarseGarment{GarmentKind::LongSleeve, 500, "longsleeve"},
                                           CoarseGarment{GarmentKind::Trousers, 500, "trousers"},
                                           CoarseGarment{GarmentKind::Dress, 500, "dress"},
                                           CoarseGarment{GarmentKind::Skirt, 500, "skirt"},
                                           CoarseGarment{GarmentKind::TShirt, 300, "tshirt"}),
                         [](const ::testing::TestParamInfo<CoarseGarment>& info) {
                           return std::string("Ges04_") + info.param.name;
                         });

INSTANTIATE_TEST_SUITE_P(SharedData, LongSleeveByKindOnRecording,
                         ::testing::Values("cmu_mocap_bvh/131_03.bvh", "cmu_mocap_bvh/scaled_131_03.bvh"),
                         [](const ::testing::TestParamInfo<const char*>& info) { return test::takeTestName(info.param); });

INSTANTIATE_TEST_SUITE_P(SharedData, TrousersByKindOnRecording,
                         ::testing::Values("kinect_v2_msft_labanotation/Ges01_wavehand.csv",
                                           "kinect_v2_msft_labanotation/Ges02_balancinghands.csv",
                                           "kinect_v2_msft_labanotation/Ges04_comehere.csv"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           std::string name = info.param;
                           name = name.substr(name.find('/') + 1);
                           return name.substr(0, name.find('_'));
                         });

INSTANTIATE_TEST_SUITE_P(SharedData, GarmentOnRecording, ::testing::ValuesIn(kTakes),
                         [](const ::testing::TestParamInfo<Take>& info) { return test::takeTestName(info.param.file); });

}  // namespace
}  // namespace drape
