// Garments cut for the tracked person's skeleton (drape_context_desc.garment_fit, docs/garments.md
// "Cut for the person's skeleton"): restPoseWithBones keeps the rest pose's limb directions with the
// person's bone lengths and their torso's own geometry; once the tracker has calibrated, the context
// refits every garment to that rest body (same particles and triangles, a new rest shape), unless
// the person has the standard proportions; DRAPE_GARMENT_FIT_SHAPE never refits. Driven through
// drape::Context with the tracker in the loop.
#include "garment_scene.h"
#include "test_data.h"

#include "body/body_shape.h"
#include "cloth/garment_sim.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace drape {
namespace {

const ResolvedShape& standardShape() {
  static const ResolvedShape s = resolveShape(BodyShapeInput{});
  return s;
}

std::array<float, kBoneCount> boneLengthsOf(const SkeletonPose& p) {
  std::array<float, kBoneCount> l{};
  for (int b = 0; b < kBoneCount; ++b)
    l[static_cast<size_t>(b)] = (p.position[static_cast<size_t>(boneChild(b))] - p.position[static_cast<size_t>(boneParent(b))]).norm();
  return l;
}

float maxJointDistance(const SkeletonPose& a, const SkeletonPose& b) {
  float d = 0.0f;
  for (int j = 0; j < kJointCount; ++j) d = std::max(d, (a.position[static_cast<size_t>(j)] - b.position[static_cast<size_t>(j)]).norm());
  return d;
}

// The standard rest pose with every bone below `from` (the subtree of that joint) scaled by `s`
// about its parent joint: a person with longer or shorter limbs.
void scaleSubtree(SkeletonPose& p, Joint from, float s) {
  const int root = idx(from);
  const Vec3 pivot = p.position[static_cast<size_t>(kJointParent[static_cast<size_t>(root)])];
  for (int j = 0; j < kJointCount; ++j) {
    int k = j;
    while (k >= 0 && k != root) k = kJointParent[static_cast<size_t>(k)];
    if (k == root) p.position[static_cast<size_t>(j)] = pivot + s * (p.position[static_cast<size_t>(j)] - pivot);
  }
}

// A person unlike the standard one: legs 15 % shorter, spine 10 % longer, shoulders 4 cm higher
// (a Kinect v2 on Ges01 measures legs ~16 % shorter and the torso ~9 % longer than the standard
// proportions), arms of the standard length hanging 75 degrees down. Of the size the shape fits
// (its bones' median scale 1.0: Context::shapeFitsPerson), so the garments are cut for it at the
// calibration; with the arms 10 % longer too the median was 1.1, a shape too small for a tracked
// person (whose bones read ~15 % short), cut for the skeleton from the first pose.
SkeletonPose otherPerson() {
  SkeletonPose p = restPose(standardShape(), 75.0f);
  for (Joint hip : {Joint::HipL, Joint::HipR}) {
    const Vec3 h = p.position[static_cast<size_t>(idx(hip))];
    SkeletonPose q = p;
    scaleSubtree(q, hip == Joint::HipL ? Joint::KneeL : Joint::KneeR, 0.85f);
    p = q;
    p.position[static_cast<size_t>(idx(hip))] = h;
  }
  scaleSubtree(p, Joint::SpineMid, 1.1f);
  for (Joint elbow : {Joint::ElbowL, Joint::ElbowR}) scaleSubtree(p, elbow, 1.0f / 1.1f);
  for (Joint s : {Joint::ShoulderL, Joint::ShoulderR}) {
    SkeletonPose q = p;
    const Vec3 up(0.0f, 0.04f, 0.0f);
    const int root = idx(s);
    for (int j = 0; j < kJointCount; ++j) {
      int k = j;
      while (k >= 0 && k != root) k = kJointParent[static_cast<size_t>(k)];
      if (k == root) q.position[static_cast<size_t>(j)] += up;
    }
    p = q;
  }
  return p;
}

TEST(RestPoseWithBones, TheStandardBonesGiveTheStandardPose) {
  const SkeletonPose rest = restPose(standardShape(), 65.0f);
  const SkeletonPose again = restPoseWithBones(standardShape(), 65.0f, boneLengthsOf(rest), &rest);
  EXPECT_LT(maxJointDistance(rest, again), 1e-5f);
  const SkeletonPose noTorso = restPoseWithBones(standardShape(), 65.0f, boneLengthsOf(rest));
  EXPECT_LT(maxJointDistance(rest, noTorso), 1e-5f);
}

TEST(RestPoseWithBones, BonesTakeTheMeasuredLengthsAndKeepTheRestDirections) {
  const SkeletonPose rest = restPose(standardShape(), 65.0f);
  std::array<float, kBoneCount> l = boneLengthsOf(rest);
  for (float& v : l) v *= 1.2f;
  const int thigh = idx(Joint::KneeL) - 1;  // bone b ends at joint b + 1
  l[static_cast<size_t>(thigh)] = 0.31f;
  const SkeletonPose p = restPoseWithBones(standardShape(), 65.0f, l);
  EXPECT_LT((p.position[0] - rest.position[0]).norm(), 1e-6f) << "the pelvis stays";
  for (int b = 0; b < kBoneCount; ++b) {
    const Vec3 d = p.position[static_cast<size_t>(boneChild(b))] - p.position[static_cast<size_t>(boneParent(b))];
    const Vec3 r = rest.position[static_cast<size_t>(boneChild(b))] - rest.position[static_cast<size_t>(boneParent(b))];
    EXPECT_NEAR(d.norm(), l[static_cast<size_t>(b)], 1e-4f) << "bone " << b;
    EXPECT_GT(d.normalized().dot(r.normalized()), 0.99999f) << "bone " << b;
  }
}

TEST(RestPoseWithBones, UnseenOrAbsurdLengthsAreHeld) {
  const SkeletonPose rest = restPose(standardShape(), 65.0f);
  const std::array<float, kBoneCount> standard = boneLengthsOf(rest);
  std::array<float, kBoneCount> l = standard;
  l[0] = 0.0f;                                        // never seen: the standard length
  l[1] = std::numeric_limits<float>::quiet_NaN();    // the same
  l[2] = std::numeric_limits<float>::infinity();     // the same
  l[5] = 100.0f;                                      // at most 4x
  l[6] = 0.011f;                                      // at least 0.25x
  const std::array<float, kBoneCount> got = boneLengthsOf(restPoseWithBones(standardShape(), 65.0f, l));
  EXPECT_NEAR(got[0], standard[0], 1e-5f);
  EXPECT_NEAR(got[1], standard[1], 1e-5f);
  EXPECT_NEAR(got[2], standard[2], 1e-5f);
  EXPECT_NEAR(got[5], 4.0f * standard[5], 1e-4f);
  EXPECT_NEAR(got[6], 0.25f * standard[6], 1e-5f);
  for (int b = 7; b < kBoneCount; ++b) EXPECT_NEAR(got[static_cast<size_t>(b)], standard[static_cast<size_t>(b)], 1e-5f);
}

TEST(RestPoseWithBones, TheTorsoGeometryComesFromThePersonWhereverTheyStand) {
  // The other person, turned 90 degrees and 2 m to the side, leaning 10 degrees: the rest pose
  // takes their torso in the frame of their pelvis (spine up, hips across), so it does not depend on
  // where they stand or which way they face; the lean is part of that geometry.
  const SkeletonPose person = otherPerson();
  SkeletonPose moved = person;
  const Mat3 R = Eigen::AngleAxisf(0.5f * kPi, Vec3::UnitY()).toRotationMatrix();
  for (Vec3& x : moved.position) x = R * (x - person.position[0]) + Vec3(2.0f, 0.0f, 1.0f) + person.position[0];
  const std::array<float, kBoneCount> l = boneLengthsOf(person);
  const SkeletonPose a = restPoseWithBones(standardShape(), 65.0f, l, &person);
  const SkeletonPose b = restPoseWithBones(standardShape(), 65.0f, l, &moved);
  EXPECT_LT(maxJointDistance(a, b), 1e-4f);
  // The raised shoulders are in it: 4 cm above the standard pose's, relative to the spine.
  for (Joint s : {Joint::ShoulderL, Joint::ShoulderR}) {
    const float h = a.position[static_cast<size_t>(idx(s))].y() - a.position[static_cast<size_t>(idx(Joint::SpineShoulder))].y();
    const SkeletonPose rest = restPose(standardShape(), 65.0f);
    const float h0 = rest.position[static_cast<size_t>(idx(s))].y() - rest.position[static_cast<size_t>(idx(Joint::SpineShoulder))].y();
    EXPECT_NEAR(h - h0, 0.04f, 0.005f);
  }
  // A degenerate torso (every joint at one point) is ignored: the rest directions stay.
  SkeletonPose flat = person;
  for (Vec3& x : flat.position) x = Vec3(0.0f, 1.0f, 2.0f);
  const SkeletonPose c = restPoseWithBones(standardShape(), 65.0f, l, &flat);
  EXPECT_LT(maxJointDistance(c, restPoseWithBones(standardShape(), 65.0f, l)), 1e-6f);
}

TEST(TorsoAverage, AveragesTheTorsoInThePelvisFrameAndSkipsCollapsedOnes) {
  const SkeletonPose person = otherPerson();
  const std::array<float, kBoneCount> l = boneLengthsOf(person);
  TorsoAverage avg;
  EXPECT_TRUE(avg.empty());
  SkeletonPose collapsed = person;
  for (Vec3& x : collapsed.position) x = Vec3(0.0f, 1.0f, 2.0f);
  avg.add(collapsed);
  EXPECT_TRUE(avg.empty()) << "no pelvis frame: skipped";
  // The person turned and moved about, and leaning 10 degrees either way: the average is upright.
  for (int k = 0; k < 6; ++k) {
    SkeletonPose q = person;
    const Mat3 turn = Eigen::AngleAxisf(0.4f * static_cast<float>(k), Vec3::UnitY()).toRotationMatrix();
    for (Vec3& x : q.position) x = turn * (x - person.position[0]) + Vec3(0.3f * static_cast<float>(k), 0.0f, 0.1f) + person.position[0];
    const Mat3 lean = Eigen::AngleAxisf((k % 2 ? 1.0f : -1.0f) * 10.0f * kPi / 180.0f, turn * Vec3::UnitZ()).toRotationMatrix();
    for (int j : {idx(Joint::SpineShoulder), idx(Joint::Neck), idx(Joint::Head), idx(Joint::ShoulderL), idx(Joint::ShoulderR)})
      q.position[static_cast<size_t>(j)] = lean * (q.position[static_cast<size_t>(j)] - q.position[static_cast<size_t>(idx(Joint::SpineMid))]) +
                                           q.position[static_cast<size_t>(idx(Joint::SpineMid))];
    avg.add(q);
  }
  ASSERT_FALSE(avg.empty());
  const SkeletonPose mean = avg.mean();
  const SkeletonPose fromMean = restPoseWithBones(standardShape(), 65.0f, l, &mean);
  const SkeletonPose fromPerson = restPoseWithBones(standardShape(), 65.0f, l, &person);
  EXPECT_LT(maxJointDistance(fromMean, fromPerson), 0.005f);
  avg.clear();
  EXPECT_TRUE(avg.empty());
}

// A context with one garment on a person standing in `pose`, swaying 3 cm sideways.
struct Person {
  std::unique_ptr<Context> ctx;
  GarmentSim* garment = nullptr;
  SkeletonPose pose;
  double t = 0.0;
  int pushes = 0;

  Person(const SkeletonPose& p, GarmentKind kind, int32_t fit) : pose(p) {
    drape_context_desc d = test::defaultDesc();
    d.garment_fit = fit;
    ctx = std::make_unique<Context>(d);
    std::string err;
    garment = test::addTemplate(*ctx, kind, 800, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
    EXPECT_NE(garment, nullptr) << err;
  }
  void step() {
    SkeletonPose now = pose;
    const float x = 0.03f * static_cast<float>(std::sin(2.0 * t));
    for (Vec3& j : now.position) j += Vec3(x, 0.0f, 0.0f);
    Recording rec;
    rec.layout = Layout::Kinect2;
    t += 1.0 / 30.0;
    std::string err;
    // The first pose with the knees guessed: the garments are cut for the skeleton at the
    // calibration, the recut these tests are about (test::withGuessedKnees).
    const RecordingFrame f = pushes++ == 0 ? test::withGuessedKnees(test::kinect2FromPose(now, t)) : test::kinect2FromPose(now, t);
    ASSERT_EQ(test::pushAndStep(*ctx, rec, f, t, 1.0f / 30.0f, err), DRAPE_OK) << err;
  }
  // Median per-frame P99 stretch over `frames` frames; inside: particles inside an ellipsoid, summed.
  float medianP99(int frames, uint64_t* inside) {
    std::vector<float> p99;
    for (int f = 0; f < frames; ++f) {
      step();
      const GarmentAccuracy a = ctx->measureGarment(*garment);
      p99.push_back(a.stretch.p99);
      *inside += a.proxy_inside;
    }
    std::sort(p99.begin(), p99.end());
    return p99[p99.size() / 2];
  }
};

// Steps from the calibration's to the one that swaps the new cut in: the dressing's frames
// (GarmentSim::create: 0.5 s at 30 Hz, the default dress time), kRecutFramesPerStep a step, then
// the swap.
constexpr int kDressFrames = 15;
constexpr int kRecutSteps = (kDressFrames + Context::kRecutFramesPerStep - 1) / Context::kRecutFramesPerStep + 1;

TEST(GarmentFit, CalibrationRecutsTheGarmentsForThePersonsBones) {
  for (GarmentKind kind : {GarmentKind::Trousers, GarmentKind::TShirt}) {
    Person fitted(otherPerson(), kind, DRAPE_GARMENT_FIT_SKELETON);
    Person standard(otherPerson(), kind, DRAPE_GARMENT_FIT_SHAPE);
    ASSERT_NE(fitted.garment, nullptr);
    ASSERT_NE(standard.garment, nullptr);
    const size_t particles = fitted.garment->particleCount();
    const std::vector<uint32_t> triangles = fitted.garment->indices();
    const DistanceConstraints cut = fitted.garment->topology().stretch;
    for (int f = 0; f < 29; ++f) {
      fitted.step();
      standard.step();
    }
    EXPECT_EQ(fitted.garment->refits(), 0u) << "not calibrated yet";
    fitted.step();  // the 30th push calibrates: the new cut is made, then dressed over the next steps
    standard.step();
    EXPECT_TRUE(fitted.ctx->recutPending());
    EXPECT_FALSE(standard.ctx->recutPending());
    int steps = 0;
    while (fitted.garment->refits() == 0 && steps < 3 * kRecutSteps) {
      fitted.step();
      standard.step();
      ++steps;
    }
    EXPECT_EQ(steps, kRecutSteps) << "the old cut steps on while the new one is dressed, then they swap";
    EXPECT_FALSE(fitted.ctx->recutPending());
    EXPECT_EQ(fitted.garment->refits(), 1u);
    EXPECT_EQ(standard.garment->refits(), 0u);
    EXPECT_EQ(&fitted.ctx->garment(0), fitted.garment) << "the same garment object (the C ABI handle)";
    EXPECT_EQ(fitted.garment->particleCount(), particles);
    EXPECT_EQ(fitted.garment->indices(), triangles);
    double before = 0.0, after = 0.0;
    for (float r : cut.rest) before += r;
    for (float r : fitted.garment->topology().stretch.rest) after += r;
    EXPECT_GT(std::fabs(after / before - 1.0), 0.005) << "a new cut";
    // The rest body's ellipsoids come in the frames' count and order (collision groups by index).
    const std::vector<uint8_t>& groups = fitted.ctx->restEllipsoidGroups();
    const std::vector<ProxySource>& sources = fitted.ctx->proxies().sources();
    ASSERT_EQ(groups.size(), sources.size());
    for (size_t k = 0; k < groups.size(); ++k) ASSERT_EQ(groups[k], collisionGroups(sources[k])) << k;

    uint64_t insideFitted = 0, insideStandard = 0;
    const float a = fitted.medianP99(40, &insideFitted);
    const float b = standard.medianP99(40, &insideStandard);
    std::printf("[ figures  ] %s: median P99 stretch cut for the skeleton %.3f, for the shape %.3f; inside %llu / %llu\n",
                garmentKindName(kind), a, b, static_cast<unsigned long long>(insideFitted),
                static_cast<unsigned long long>(insideStandard));
    EXPECT_EQ(insideFitted, 0u);
    EXPECT_LT(a, b) << garmentKindName(kind);
    EXPECT_EQ(fitted.garment->refits(), 1u) << "once per calibration";
    for (size_t i = 0; i < particles; ++i) ASSERT_TRUE(fitted.garment->positions()[i].allFinite());
  }
}

TEST(GarmentFit, TheStandardProportionsKeepTheGarmentAsItIs) {
  // A person with the shape's own proportions (the garments' rest pose, arms as they like): the
  // calibration finds nothing to refit, so the garment steps exactly as with FIT_SHAPE.
  Person a(restPose(standardShape(), 70.0f), GarmentKind::TShirt, DRAPE_GARMENT_FIT_SKELETON);
  Person b(restPose(standardShape(), 70.0f), GarmentKind::TShirt, DRAPE_GARMENT_FIT_SHAPE);
  for (int f = 0; f < 40; ++f) {
    a.step();
    b.step();
  }
  EXPECT_EQ(a.garment->refits(), 0u);
  for (size_t i = 0; i < a.garment->particleCount(); ++i)
    ASSERT_EQ(a.garment->positions()[i], b.garment->positions()[i]) << "particle " << i;
}

TEST(GarmentFit, AGarmentAddedAfterCalibrationIsCutForThePersonAtOnce) {
  Person early(otherPerson(), GarmentKind::Trousers, DRAPE_GARMENT_FIT_SKELETON);
  for (int f = 0; f < 30 + kRecutSteps; ++f) early.step();
  ASSERT_EQ(early.garment->refits(), 1u);
  std::string err;
  GarmentSim* late = test::addTemplate(*early.ctx, GarmentKind::Trousers, 800, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
  ASSERT_NE(late, nullptr) << err;
  uint64_t inside = 0;
  early.medianP99(10, &inside);
  EXPECT_EQ(late->refits(), 0u) << "made on the person's rest body: nothing to refit";
  EXPECT_EQ(early.garment->refits(), 1u);
  EXPECT_EQ(inside, 0u);
}

// While a recut is being dressed (Context::Recut) the host goes on: a garment removed then takes
// its replacement with it and the others still swap; parameters set then are the replacement's
// too; a body shape change cancels the recut and refits every garment at once (on the skeleton's
// rest body of the new shape, with the calibrated bones).
TEST(GarmentFit, ARecutBeingDressedFollowsTheHost) {
  std::string err;
  {
    Person p(otherPerson(), GarmentKind::Trousers, DRAPE_GARMENT_FIT_SKELETON);
    GarmentSim* top = test::addTemplate(*p.ctx, GarmentKind::TShirt, 600, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
    ASSERT_NE(top, nullptr) << err;
    for (int f = 0; f < 32; ++f) p.step();
    ASSERT_TRUE(p.ctx->recutPending());
    ASSERT_TRUE(p.ctx->removeGarment(p.garment));
    p.garment = top;
    for (int f = 0; f < kRecutSteps; ++f) p.step();
    EXPECT_FALSE(p.ctx->recutPending());
    EXPECT_EQ(top->refits(), 1u);
    EXPECT_EQ(p.ctx->garmentCount(), 1u);
    for (size_t i = 0; i < top->particleCount(); ++i) ASSERT_TRUE(top->positions()[i].allFinite());
  }
  {
    Person p(otherPerson(), GarmentKind::Trousers, DRAPE_GARMENT_FIT_SKELETON);
    for (int f = 0; f < 32; ++f) p.step();
    ASSERT_TRUE(p.ctx->recutPending());
    GarmentSimParams q = p.garment->params();
    q.collision_margin_m = 0.006f;
    ASSERT_TRUE(p.garment->setParams(q, err)) << err;
    for (int f = 0; f < kRecutSteps; ++f) p.step();
    ASSERT_EQ(p.garment->refits(), 1u);
    EXPECT_EQ(p.garment->params().collision_margin_m, 0.006f) << "the host's parameters, set while it was dressed";
  }
  {
    Person p(otherPerson(), GarmentKind::Trousers, DRAPE_GARMENT_FIT_SKELETON);
    for (int f = 0; f < 32; ++f) p.step();
    ASSERT_TRUE(p.ctx->recutPending());
    BodyShapeInput in;
    in.height_m = 1.80f;
    in.weight_kg = 80.0f;
    ASSERT_EQ(p.ctx->setShape(in, err), DRAPE_OK) << err;
    EXPECT_FALSE(p.ctx->recutPending());
    EXPECT_EQ(p.garment->refits(), 1u) << "refitted to the new shape at once";
    for (int f = 0; f < 2 * kRecutSteps; ++f) p.step();
    EXPECT_EQ(p.garment->refits(), 1u) << "no recut for the old shape swapped in later";
    for (size_t i = 0; i < p.garment->particleCount(); ++i) ASSERT_TRUE(p.garment->positions()[i].allFinite());
  }
}

// Ges01's calibrated skeleton (the bundled Kinect take): the T-shirt made again there with the
// layout recorded on the standard body has the same vertices, triangles and attachments, and no
// collapsed edge (one of its seam edges came out 20 um long before separateShortEdges).
TEST(GarmentFit, ARemadeTemplateKeepsItsTopologyAndHasNoCollapsedEdge) {
  DRAPE_REQUIRE_SHARED(path, "kinect_v2_msft_labanotation/Ges01_wavehand.csv");
  Recording rec;
  std::string err;
  ASSERT_TRUE(readRecordingFile(path, 0, rec, err)) << err;
  drape_context_desc fit = test::defaultDesc();
  fit.garment_fit = DRAPE_GARMENT_FIT_SKELETON;
  Context standard(test::defaultDesc()), person(fit);
  GarmentTemplateParams tp;
  tp.kind = GarmentKind::TShirt;
  GarmentMesh first, again;
  TemplateLayout layout;
  ASSERT_TRUE(makeGarmentTemplate(standard.restBody(), tp, first, err, &layout)) << err;
  ASSERT_FALSE(layout.empty());
  double prev = rec.frames[0].time_s - 1.0 / 30.0;
  for (int i = 0; i < 31; ++i) {
    const RecordingFrame& f = rec.frames[static_cast<size_t>(i)];
    ASSERT_EQ(test::pushAndStep(person, rec, f, f.time_s, static_cast<float>(f.time_s - prev), err), DRAPE_OK) << err;
    prev = f.time_s;
  }
  ASSERT_TRUE(person.tracker().calibrated());
  ASSERT_TRUE(makeGarmentTemplate(person.restBody(), tp, again, err, nullptr, &layout)) << err;
  EXPECT_EQ(again.positions.size(), first.positions.size());
  EXPECT_EQ(again.indices, first.indices);
  EXPECT_EQ(again.pinned, first.pinned);
  EXPECT_EQ(again.pin_ring, first.pin_ring);
  float shortest = std::numeric_limits<float>::max(), moved = 0.0f;
  for (size_t t = 0; t + 2 < again.indices.size(); t += 3)
    for (size_t e = 0; e < 3; ++e)
      shortest = std::min(shortest, (again.positions[again.indices[t + e]] - again.positions[again.indices[t + (e + 1) % 3]]).norm());
  for (size_t i = 0; i < again.positions.size(); ++i) moved = std::max(moved, (again.positions[i] - first.positions[i]).norm());
  std::printf("[ figures  ] shortest edge %.4f m (spacing %.4f m); the cut moved up to %.3f m\n", shortest, layout.h, moved);
  EXPECT_GE(shortest, 0.24f * layout.h);
  EXPECT_GT(moved, 0.02f) << "another body: another cut";
  // A layout from another garment kind does not fit: refused, nothing written.
  GarmentTemplateParams skirt;
  skirt.kind = GarmentKind::Skirt;
  GarmentMesh untouched;
  EXPECT_FALSE(makeGarmentTemplate(person.restBody(), skirt, untouched, err, nullptr, &layout));
  EXPECT_NE(err.find("layout"), std::string::npos) << err;
  EXPECT_TRUE(untouched.positions.empty());
}

TEST(GarmentFit, OneRefitPerCalibration) {
  // The check runs at every step; a calibration is acted on once (80 frames, one refit).
  Person p(otherPerson(), GarmentKind::Skirt, DRAPE_GARMENT_FIT_SKELETON);
  for (int f = 0; f < 80; ++f) p.step();
  EXPECT_EQ(p.garment->refits(), 1u);
}

}  // namespace
}  // namespace drape
