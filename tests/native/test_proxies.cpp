// Tracking ellipsoids built from the rings: well-formed every frame, and measurably close to the
// body mesh on every shared recording (the paper's rule vs ours, docs/proxies.md).
#include "body/body_model.h"
#include "proxies/fidelity.h"
#include "proxies/proxy_builder.h"
#include "recording/recording.h"
#include "skeleton/layouts.h"
#include "skeleton/tracker.h"
#include "test_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <limits>

namespace drape {
namespace {

void expectWellFormed(const std::vector<Ellipsoid>& ellipsoids) {
  for (size_t i = 0; i < ellipsoids.size(); ++i) {
    const Ellipsoid& e = ellipsoids[i];
    ASSERT_TRUE(isFinite(e.centre)) << i;
    ASSERT_GT(e.radii.minCoeff(), 0.0f) << i;
    ASSERT_TRUE(std::isfinite(e.radii.maxCoeff())) << i;
    ASSERT_LT((e.rotation.transpose() * e.rotation - Mat3::Identity()).norm(), 1e-4f) << i;
    ASSERT_GT(e.rotation.determinant(), 0.0f) << i;
    // The cached inverse maps the centre to 0 and the end of each axis onto the unit sphere.
    for (int a = 0; a < 3; ++a)
      ASSERT_NEAR(e.toUnit(e.centre + e.rotation.col(a) * e.radii[a]).norm(), 1.0f, 1e-4f) << i;
  }
}

TEST(Proxies, PaperRuleCountsMatchThePaper) {
  const ResolvedShape shape = resolveShape(BodyShapeInput{});
  BodyModel body(shape, BodyModelParams{});
  const SkeletonPose pose = restPose(shape);
  body.update(pose);
  ProxyBuilder paper(ProxyRule::Paper);
  paper.build(body, pose);
  // One per torso and head ring, one per limb bone (3 per limb).
  const size_t rings = static_cast<size_t>(body.chainRingCount(Chain::Torso) + body.chainRingCount(Chain::Head));
  EXPECT_EQ(paper.ellipsoids().size(), rings + 4 * 3);
  expectWellFormed(paper.ellipsoids());
  ProxyBuilder ours(ProxyRule::Drape);
  ours.build(body, pose);
  expectWellFormed(ours.ellipsoids());
  const size_t count = ours.ellipsoids().size();
  ours.build(body, pose);
  EXPECT_EQ(ours.ellipsoids().size(), count) << "the count must not change between frames";
}

struct Take {
  const char* file;
};

class ProxiesOnRecording : public ::testing::TestWithParam<Take> {};

// A take pushed frame by frame through the tracker, for the default body.
struct TrackedTake {
  Recording rec;
  ResolvedShape shape = resolveShape(BodyShapeInput{});
  BodyModel body{shape, BodyModelParams{}};
  SkeletonTracker tracker;
  std::string err;
  bool open(const std::string& path) { return readRecordingFile(path, 0, rec, err); }
  // Opens the take and builds `proxies` on its body in the rest pose.
  bool openAtRest(const std::string& path, ProxyBuilder& proxies) {
    if (!open(path)) return false;
    proxies.build(body, restPose(shape));
    return true;
  }
  // Pushes frame i into the tracker (the body is the caller's to update); false and err when the
  // frame does not map to the canonical skeleton.
  bool track(size_t i) {
    SkeletonPose raw;
    if (!mapToCanonical(rec.layout, rec.frames[i].joints.data(), static_cast<int>(rec.frames[i].joints.size()), raw,
                        err))
      return false;
    tracker.push(raw, rec.frames[i].time_s);
    return true;
  }
};

// Every 10th frame: with the Drape rule the body sticks out of the union by P95 <= 2.5 mm on
// every measured frame, and the union sticks out of the body by P95 <= 10 mm on the median frame;
// the paper's rule leaves the body sticking out by P95 > 15 mm (the improvement is real).
TEST_P(ProxiesOnRecording, DrapeRuleFitsTheBodyWithinTenMillimetres) {
  DRAPE_REQUIRE_SHARED(path, GetParam().file);
  TrackedTake take;
  ASSERT_TRUE(take.open(path)) << take.err;
  BodyModel& body = take.body;
  const SkeletonTracker& tracker = take.tracker;
  ProxyBuilder ours(ProxyRule::Drape), paper(ProxyRule::Paper);
  ours.build(body, restPose(take.shape));
  paper.build(body, restPose(take.shape));
  TriangleBvh bvh;
  ASSERT_TRUE(bvh.build(body.positions(), body.indices()));
  std::vector<float> oursOut, oursBulge, paperGap;
  for (size_t i = 0; i < take.rec.frames.size(); ++i) {
    ASSERT_TRUE(take.track(i)) << take.err;
    body.update(tracker.pose());
    ours.build(body, tracker.pose());
    paper.build(body, tracker.pose());
    expectWellFormed(ours.ellipsoids());
    if (i % 10 != 0) continue;
    ASSERT_TRUE(bvh.refit(body.positions()));
    const auto& e = ours.ellipsoids();
    const FidelityReport f = measureFidelity(body.positions(), body.indices(), e.data(), static_cast<int>(e.size()), bvh, 128);
    oursOut.push_back(f.body_to_union_p95_mm);
    oursBulge.push_back(f.union_to_body_p95_mm);
    // Body samples (vertices and triangle centroids) outside by > 0.5 mm: 5 % on the Kinect takes,
    // 8.5 % on the CMU takes (short torso, docs/recording-format.md), all in the
    // junction stitches (shoulders, neck base, crotch) and the hand and foot caps.
    EXPECT_LT(f.outside_fraction, 0.10f) << "frame " << i;
    const auto& p = paper.ellipsoids();
    paperGap.push_back(measureFidelity(body.positions(), body.indices(), p.data(), static_cast<int>(p.size()), bvh, 32)
                           .body_to_union_p95_mm);
  }
  auto median = [](std::vector<float> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  EXPECT_LE(*std::max_element(oursOut.begin(), oursOut.end()), 2.5f) << "body sticks out of the proxies";
  EXPECT_LE(median(oursBulge), 10.0f) << "proxies stick out of the body";
  EXPECT_GT(median(paperGap), 15.0f) << "the paper's rule should leave gaps (if not, revisit docs/proxies.md)";
  std::printf("  %s: Drape P95 body->proxy %.1f mm, proxy->body %.1f mm (median frame); paper body->proxy %.1f mm\n",
              GetParam().file, median(oursOut), median(oursBulge), median(paperGap));
}

// How far the top of each shoulder (the stitch between the neck ring's side arc and the arm's
// junction ring: its vertices and triangle centroids) lies outside the union of `count`
// ellipsoids; the largest over both shoulders, mm.
float shoulderTopGapMm(const BodyModel& body, const std::vector<Ellipsoid>& e, size_t count) {
  const int K = body.ringPoints();
  const int top = body.chainFirstRing(Chain::Torso) + body.chainRingCount(Chain::Torso) - 1;
  std::vector<float> scratch;
  auto outside = [&](const Vec3& p) { return distanceOutsideUnion(e.data(), count, p, scratch); };
  float worst = 0.0f;
  for (bool left : {false, true}) {
    const std::vector<uint32_t>& t = body.shoulderTriangles(left);
    for (size_t i = 0; i + 2 < t.size(); i += 3) {
      bool armpit = false;
      Vec3 c = Vec3::Zero();
      for (int j = 0; j < 3; ++j) {
        armpit = armpit || static_cast<int>(t[i + j]) / K == top;
        c += body.positions()[t[i + j]] / 3.0f;
      }
      if (armpit) continue;  // the armpit half of the stitch: no fill there (docs/proxies.md)
      worst = std::max(worst, outside(c));
      for (int j = 0; j < 3; ++j) worst = std::max(worst, outside(body.positions()[t[i + j]]));
    }
  }
  return 1000.0f * worst;
}

// Tracks every frame of the take; on every 10th, updates its body, builds `proxies` on it and calls
// `measure`.
template <class Measure>
void everyTenthFrame(TrackedTake& take, ProxyBuilder& proxies, Measure measure) {
  for (size_t i = 0; i < take.rec.frames.size(); ++i) {
    ASSERT_TRUE(take.track(i)) << take.err;
    if (i % 10 != 0) continue;
    take.body.update(take.tracker.pose());
    proxies.build(take.body, take.tracker.pose());
    measure();
  }
}

// The pair of fills `from_end` ellipsoids before the end of `sources` (right side first): built
// from their chain's first ring, in that chain's group plus `extra_groups`.
void expectFillPair(const std::vector<ProxySource>& sources, const BodyModel& body, size_t from_end, Chain right,
                    Chain left, uint8_t extra_groups) {
  ASSERT_GE(sources.size(), from_end);
  for (int side = 0; side < 2; ++side) {
    const ProxySource& s = sources[sources.size() - from_end + static_cast<size_t>(side)];
    const Chain chain = side == 1 ? left : right;
    EXPECT_EQ(s.chain, chain);
    EXPECT_EQ(s.first_ring, body.chainFirstRing(chain));
    EXPECT_EQ(collisionGroups(s), (1u << static_cast<int>(chain)) | extra_groups);
  }
}

// The shoulder fills (the Drape rule's two before the hip fills) cover the top of the shoulders, which
// the ring ellipsoids leave open: cloth lying on them sank up to 2 cm into the body mesh there.
TEST_P(ProxiesOnRecording, ShoulderFillsCoverTheTopsOfTheShoulders) {
  DRAPE_REQUIRE_SHARED(path, GetParam().file);
  TrackedTake take;
  ProxyBuilder ours(ProxyRule::Drape);
  ASSERT_TRUE(take.openAtRest(path, ours)) << take.err;
  BodyModel& body = take.body;
  // The last four: the shoulder fills (right, left), then the hip fills.
  expectFillPair(ours.sources(), body, 4, Chain::ArmR, Chain::ArmL, 1u << static_cast<int>(Chain::Torso));
  float with = 0.0f, without = 0.0f;
  everyTenthFrame(take, ours, [&] {
    const auto& e = ours.ellipsoids();
    with = std::max(with, shoulderTopGapMm(body, e, e.size() - 2));
    without = std::max(without, shoulderTopGapMm(body, e, e.size() - 4));
  });
  std::printf("  %s: top of the shoulders outside the ellipsoids by up to %.1f mm, %.1f mm without the fills\n",
              GetParam().file, with, without);
  EXPECT_LT(with, 0.5f * without);
  EXPECT_LT(with, 25.0f);  // measured 12.5-17.7 mm on the six takes, 34.6-47.1 mm without the fills
}

// How far the hip stitch (the body mesh's triangles between the hip ring and a thigh's first ring:
// their vertices and centroids) lies outside the union of the first `count` ellipsoids but `skip`:
// each sample's distance, mm, appended to `out`.
void hipStitchGapsMm(const BodyModel& body, const std::vector<Ellipsoid>& e, size_t count, std::vector<float>& out,
                     size_t skip) {
  const int K = body.ringPoints();
  const int ringVertices = static_cast<int>(body.rings().size()) * K;
  const int hip = body.chainFirstRing(Chain::Torso);
  const int thighs[2] = {body.chainFirstRing(Chain::LegL), body.chainFirstRing(Chain::LegR)};
  std::vector<float> scratch;
  auto outside = [&](const Vec3& p) { return 1000.0f * distanceOutsideUnion(e.data(), count, p, scratch, skip); };
  const auto& t = body.indices();
  const auto& x = body.positions();
  for (size_t i = 0; i + 2 < t.size(); i += 3) {
    bool onHip = false, onThigh = false;
    Vec3 c = Vec3::Zero();
    for (int j = 0; j < 3; ++j) {
      const int v = static_cast<int>(t[i + j]);
      onHip = onHip || (v < ringVertices && v / K == hip);
      onThigh = onThigh || (v < ringVertices && (v / K == thighs[0] || v / K == thighs[1]));
      c += x[t[i + j]] / 3.0f;
    }
    if (!onHip || !onThigh) continue;
    out.push_back(outside(c));
    for (int j = 0; j < 3; ++j) out.push_back(outside(x[t[i + j]]));
  }
}

// Mean, P90 and max of a set of gaps.
std::array<float, 3> gapStats(std::vector<float> v) {
  std::sort(v.begin(), v.end());
  double sum = 0.0;
  for (float d : v) sum += d;
  return {static_cast<float>(sum / static_cast<double>(v.size())), v[v.size() * 9 / 10], v.back()};
}

// The hip stitch's gaps (hipStitchGapsMm) every tenth frame of the take, with and without some
// fills: mean, P90 and max of each, printed as "`what`: ... without `without_what` ...".
struct GapsWithAndWithout {
  std::array<float, 3> with{}, without{};
};
GapsWithAndWithout hipStitchGapsWithAndWithout(TrackedTake& take, ProxyBuilder& ours, size_t with_skip,
                                               size_t without_count_from_end, size_t without_skip,
                                               const char* without_what) {
  std::vector<float> with, without;
  everyTenthFrame(take, ours, [&] {
    const auto& e = ours.ellipsoids();
    hipStitchGapsMm(take.body, e, e.size(), with, with_skip);
    hipStitchGapsMm(take.body, e, e.size() - without_count_from_end, without, without_skip);
  });
  GapsWithAndWithout g;
  EXPECT_FALSE(with.empty());
  if (with.empty() || without.empty()) return g;
  g.with = gapStats(with);
  g.without = gapStats(without);
  std::printf("  hip stitch outside the ellipsoids by %.1f mm on average, P90 %.1f, max %.1f; without the %s "
              "%.1f, %.1f, %.1f\n", g.with[0], g.with[1], g.with[2], without_what, g.without[0], g.without[1],
              g.without[2]);
  return g;
}

// The one ellipsoid whose groups are kPelvisFillGroups (the Drape rule's, before the shoulder fills).
size_t pelvisFillIndex(const std::vector<ProxySource>& sources) {
  size_t found = sources.size();
  for (size_t k = 0; k < sources.size(); ++k) {
    if (collisionGroups(sources[k]) != kPelvisFillGroups) continue;
    EXPECT_EQ(found, sources.size()) << "a second pelvis fill at " << k;
    found = k;
  }
  EXPECT_LT(found, sources.size()) << "no pelvis fill";
  return found;
}

// The hip fills (the last two Drape-rule ellipsoids) span the stitch between the hip ring and the
// thighs, which the ring ellipsoids cover only near its ends: long on the CMU takes, whose hip
// joints (the femur heads) sit far below the pelvis (docs/proxies.md, "Hip fills").
TEST_P(ProxiesOnRecording, HipFillsSpanTheHipStitch) {
  DRAPE_REQUIRE_SHARED(path, GetParam().file);
  TrackedTake take;
  ProxyBuilder ours(ProxyRule::Drape);
  ASSERT_TRUE(take.openAtRest(path, ours)) << take.err;
  BodyModel& body = take.body;
  expectFillPair(ours.sources(), body, 2, Chain::LegR, Chain::LegL, 0);  // the other trouser leg passes it
  // Measured without the pelvis fill (PelvisFillCoversTheHipStitchWhereTheHipFillsDoNot).
  const size_t pelvis = pelvisFillIndex(ours.sources());
  std::printf("  %s:\n", GetParam().file);
  const GapsWithAndWithout g = hipStitchGapsWithAndWithout(take, ours, pelvis, 2, pelvis, "hip fills");
  const auto& w = g.with;
  const auto& wo = g.without;
  EXPECT_LE(w[0], wo[0]);
  EXPECT_LE(w[2], wo[2]);
  // Measured: on the CMU takes P90 28.0-29.1 mm without, 14.1-15.1 mm with; on the Kinect takes
  // the stitch is short (P90 0-0.5 mm) and the fills lie inside the ring ellipsoids.
  if (wo[1] > 10.0f) EXPECT_LT(w[1], 0.6f * wo[1]);
}

// The pelvis fill (built from the hip ring and both thighs) covers the hip stitch's front and back,
// which the hip fills, one side each and 0.75 across, leave open; on the CMU takes the T-shirt's hem
// sank into the lower belly there (docs/proxies.md, "Pelvis fill").
TEST_P(ProxiesOnRecording, PelvisFillCoversTheHipStitchWhereTheHipFillsDoNot) {
  DRAPE_REQUIRE_SHARED(path, GetParam().file);
  TrackedTake take;
  ProxyBuilder ours(ProxyRule::Drape);
  ASSERT_TRUE(take.openAtRest(path, ours)) << take.err;
  BodyModel& body = take.body;
  const size_t pelvis = pelvisFillIndex(ours.sources());
  ASSERT_LT(pelvis, ours.sources().size());
  const ProxySource& src = ours.sources()[pelvis];
  EXPECT_EQ(src.chain, Chain::Torso);
  EXPECT_EQ(src.first_ring, body.chainFirstRing(Chain::Torso));
  EXPECT_EQ(pelvis + 5, ours.sources().size()) << "the shoulder and hip fills stay the last four";
  std::printf("  %s:\n", GetParam().file);
  const GapsWithAndWithout g = hipStitchGapsWithAndWithout(take, ours, ours.sources().size(), 0, pelvis, "pelvis fill");
  const auto& w = g.with;
  const auto& wo = g.without;
  EXPECT_LE(w[0], wo[0]);
  EXPECT_LE(w[2], wo[2]);
  // Measured: on the CMU takes P90 14.1-15.1 mm without, 0 with, max 55.0-55.5 mm without,
  // 17.6-21.7 with; on the Kinect takes max 9.3-15.0 mm without, 5.1-13.7 with.
  if (wo[1] > 10.0f) EXPECT_LT(w[1], 0.3f * wo[1]);
  if (wo[2] > 20.0f) EXPECT_LT(w[2], 0.6f * wo[2]);
}

INSTANTIATE_TEST_SUITE_P(SharedData, ProxiesOnRecording,
                         ::testing::Values(Take{"kinect_v2_msft_labanotation/Ges01_wavehand.csv"},
                                           Take{"kinect_v2_msft_labanotation/Ges02_balancinghands.csv"},
                                           Take{"kinect_v2_msft_labanotation/Ges04_comehere.csv"},
                                           Take{"kinect_v2_msft_labanotation/KinectReader_joints_closerange.csv"},
                                           Take{"cmu_mocap_bvh/scaled_131_01.bvh"},
                                           Take{"cmu_mocap_bvh/scaled_131_03.bvh"}),
                         [](const ::testing::TestParamInfo<Take>& info) {
                           return test::takeTestName(info.param.file);
                         });

}  // namespace
}  // namespace drape
