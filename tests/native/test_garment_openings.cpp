// Openings (cloth/garment_openings.h): the boundary loops of a mesh (boundaryLoops,
// cloth/garment_topology.h), the linking integral of a loop and a polyline, and every template's openings on the body it was dressed on, then carried off it.
#include "cloth/garment_openings.h"
#include "cloth/garment_solver.h"
#include "cloth/garment_topology.h"
#include "garment_scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <vector>

namespace drape {
namespace {

// A closed loop of n points round the z axis, radius r at height z; `wiggle` moves every other
// point up and down by that much (a crumpled hem).
std::vector<Vec3> openingCircle(int n, float r, float z, float wiggle = 0.0f) {
  std::vector<Vec3> loop;
  for (int k = 0; k < n; ++k) {
    const float a = 2.0f * kPi * static_cast<float>(k) / static_cast<float>(n);
    loop.emplace_back(r * std::cos(a), r * std::sin(a), z + ((k % 2) != 0 ? wiggle : -wiggle));
  }
  return loop;
}

std::vector<Vec3> openingLine(float z0, float z1, float x = 0.0f, int segments = 10) {
  std::vector<Vec3> line;
  for (int s = 0; s <= segments; ++s)
    line.emplace_back(x, 0.0f, z0 + (z1 - z0) * static_cast<float>(s) / static_cast<float>(segments));
  return line;
}

TEST(GarmentOpeningsGeometry, BoundaryLoopsOfAGridATubeAndAClosedSurface) {
  std::vector<float> flat;
  std::vector<uint32_t> indices;
  makeClothGrid(6, 4, 1.0f, 1.0f, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), flat, indices);
  const std::vector<std::vector<uint32_t>> grid = boundaryLoops(indices, flat.size() / 3);
  ASSERT_EQ(grid.size(), 1u);
  EXPECT_EQ(grid[0].size(), static_cast<size_t>(2 * (6 + 4) - 4));

  // A tube: the grid's first and last columns joined -> two loops of 6 (its ends).
  const int nx = 6, ny = 4;
  std::vector<uint32_t> tube;
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const auto id = [&](int a, int b) { return static_cast<uint32_t>(b * nx + (a % nx)); };
      tube.insert(tube.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  const std::vector<std::vector<uint32_t>> ends = boundaryLoops(tube, static_cast<size_t>(nx * ny));
  ASSERT_EQ(ends.size(), 2u);
  EXPECT_EQ(ends[0].size(), 6u);
  EXPECT_EQ(ends[1].size(), 6u);

  // A tetrahedron has no boundary; indices out of range are ignored, not read.
  const std::vector<uint32_t> tetra = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};
  EXPECT_TRUE(boundaryLoops(tetra, 4).empty());
  EXPECT_TRUE(boundaryLoops({0, 1, 7}, 3).empty());
}

TEST(GarmentOpeningsGeometry, LinkingOfALoopAndALine) {
  const std::vector<Vec3> loop = openingCircle(48, 0.05f, 0.0f);
  // Through the middle, far on both sides: +-1 (the sign follows the directions).
  EXPECT_NEAR(loopLinking(loop, openingLine(-5.0f, 5.0f)), 1.0f, 0.02f);
  EXPECT_NEAR(loopLinking(loop, openingLine(5.0f, -5.0f)), -1.0f, 0.02f);
  // Ending at the loop's centre: one half. Beside it or short of it: about 0.
  EXPECT_NEAR(loopLinking(loop, openingLine(-5.0f, 0.0f)), 0.5f, 0.02f);
  EXPECT_NEAR(std::fabs(loopLinking(loop, openingLine(-5.0f, 5.0f, 0.2f))), 0.0f, 0.02f);
  EXPECT_NEAR(std::fabs(loopLinking(loop, openingLine(-5.0f, -0.3f))), 0.0f, 0.03f);
  // A crumpled loop (every other point 4 cm up or down) still goes round once.
  EXPECT_NEAR(loopLinking(openingCircle(48, 0.05f, 0.0f, 0.04f), openingLine(-5.0f, 5.0f)), 1.0f, 0.03f);
  // A line through the loop's points or along its plane: finite, no NaN.
  const std::vector<Vec3> through = {Vec3(0.05f, 0.0f, -1.0f), Vec3(0.05f, 0.0f, 1.0f)};
  EXPECT_TRUE(std::isfinite(loopLinking(loop, through)));
  EXPECT_EQ(loopLinking({}, openingLine(-1.0f, 1.0f)), 0.0f);
  EXPECT_EQ(loopLinking(loop, {Vec3::Zero()}), 0.0f);
}

// The reference: Gauss's integral as the sum over every loop edge and polyline segment of the
// signed solid angle one subtends seen along the other (Klenin & Langowski 2000, eq. 15-16),
// what loopLinking computed before it went over a fan.
double segmentLinkingReference(const Vec3& p1f, const Vec3& p2f, const Vec3& p3f, const Vec3& p4f) {
  const Eigen::Vector3d p1 = p1f.cast<double>(), p2 = p2f.cast<double>(), p3 = p3f.cast<double>(),
                        p4 = p4f.cast<double>();
  const Eigen::Vector3d r13 = p3 - p1, r14 = p4 - p1, r23 = p3 - p2, r24 = p4 - p2, r12 = p2 - p1, r34 = p4 - p3;
  const Eigen::Vector3d c[4] = {r13.cross(r14), r14.cross(r24), r24.cross(r23), r23.cross(r13)};
  Eigen::Vector3d u[4];
  for (int i = 0; i < 4; ++i) {
    if (c[i].norm() <= 1e-15) return 0.0;
    u[i] = c[i].normalized();
  }
  double omega = 0.0;
  for (int i = 0; i < 4; ++i) omega += std::asin(std::clamp(u[i].dot(u[(i + 1) % 4]), -1.0, 1.0));
  const double side = r34.cross(r12).dot(r13);
  return (side > 0.0 ? omega : side < 0.0 ? -omega : 0.0) / (4.0 * static_cast<double>(kPi));
}

double loopLinkingReference(const std::vector<Vec3>& loop, const std::vector<Vec3>& polyline) {
  double sum = 0.0;
  for (size_t k = 0; k < loop.size(); ++k)
    for (size_t s = 0; s + 1 < polyline.size(); ++s)
      sum += segmentLinkingReference(loop[k], loop[(k + 1) % loop.size()], polyline[s], polyline[s + 1]);
  return sum;
}

// Crumpled, non-planar loops (a hem, a cuff) and bent polylines (a limb's ring centres), through
// them, ending in them, beside them, and with their ends in the loop's plane: the fan's count of
// crossings and its solid angles give the pairwise sum's value.
TEST(GarmentOpeningsGeometry, FanLinkingEqualsThePairwiseSum) {
  uint32_t seed = 12345u;
  auto uniform = [&](float lo, float hi) {
    seed = seed * 1664525u + 1013904223u;
    return lo + (hi - lo) * static_cast<float>(seed >> 8) / 16777216.0f;
  };
  int through = 0, partial = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const int n = 3 + trial % 40;
    const float r = uniform(0.03f, 0.3f);
    std::vector<Vec3> loop;
    for (int k = 0; k < n; ++k) {
      const float a = 2.0f * kPi * static_cast<float>(k) / static_cast<float>(n) + uniform(-0.5f, 0.5f) / static_cast<float>(n);
      const float rk = r * uniform(0.6f, 1.4f);
      loop.emplace_back(rk * std::cos(a), rk * std::sin(a), uniform(-0.5f, 0.5f) * r);
    }
    std::vector<Vec3> line;
    const int segments = 1 + trial % 9;
    Vec3 p(uniform(-0.5f, 0.5f) * r, uniform(-0.5f, 0.5f) * r, uniform(-1.0f, 0.0f));
    if (trial % 5 == 4) p.x() += 2.0f * r;  // beside the loop
    line.push_back(p);
    const float z_end = trial % 7 == 3 ? 0.0f : uniform(-0.5f, 1.0f);  // % 7 == 3: ends in the loop's plane z = 0
    for (int s = 1; s <= segments; ++s) {
      const float t = static_cast<float>(s) / static_cast<float>(segments);
      line.emplace_back(p.x() + uniform(-0.2f, 0.2f) * r, p.y() + uniform(-0.2f, 0.2f) * r, p.z() + t * (z_end - p.z()));
    }
    if (trial % 7 == 3) line.back().z() = 0.0f;
    const double reference = loopLinkingReference(loop, line);
    EXPECT_NEAR(loopLinking(loop, line), reference, 1e-5) << "trial " << trial;
    if (std::fabs(reference) > 0.9) ++through;
    if (std::fabs(reference) > 0.1 && std::fabs(reference) < 0.9) ++partial;
  }
  // The draw covers both kinds: polylines through the loop and polylines ending inside it.
  EXPECT_GT(through, 50);
  EXPECT_GT(partial, 50);
}

// A T-shirt's collar and the spine on Ges04_comehere (frame of drape_tests'
// GarmentOnRecording, printed as float round trips): the collar's pinned points are mirror images
// through the neck ring's centre, which is a point of the spine, so that point lies on the fan edge
// from the collar's first point to its opposite one, exactly to the rounding (one fan triangle's
// side came out 0, its neighbour's 8e-22). Without the plane tolerance that edge was crossed half
// once and the collar read -0.48 round the spine, off it; the pairwise sum says -0.98.
TEST(GarmentOpeningsGeometry, PolylinePointOnASharedFanEdge) {
  auto toVec3s = [](std::initializer_list<std::array<float, 3>> v) {
    std::vector<Vec3> out;
    for (const auto& p : v) out.emplace_back(p[0], p[1], p[2]);
    return out;
  };
  const std::vector<Vec3> collar = toVec3s({
    {-0.0656037927f, 0.202535719f, 2.62857413f}, {-0.054173395f, 0.205122352f, 2.64065218f},
    {-0.0452167392f, 0.207710356f, 2.65455914f}, {-0.0390780419f, 0.21020028f, 2.66976094f},
    {-0.0359930098f, 0.212496445f, 2.685673f}, {-0.0360803679f, 0.21451059f, 2.701684f},
    {-0.0393368155f, 0.216165349f, 2.71717882f}, {-0.0446022898f, 0.226590395f, 2.72383332f},
    {-0.0597472601f, 0.235436797f, 2.73907733f}, {-0.0734328181f, 0.228018567f, 2.75633097f},
    {-0.0798547119f, 0.218172491f, 2.76285052f}, {-0.0949034095f, 0.217424527f, 2.7679894f},
    {-0.110860452f, 0.216205165f, 2.77006364f}, {-0.127112702f, 0.214561269f, 2.76899362f},
    {-0.14303574f, 0.212556019f, 2.76482081f}, {-0.158017457f, 0.210266486f, 2.75770521f},
    {-0.171482146f, 0.207780629f, 2.74792027f}, {-0.182912558f, 0.205193996f, 2.73584223f},
    {-0.191869199f, 0.202605993f, 2.72193527f}, {-0.198007911f, 0.200116068f, 2.70673347f},
    {-0.201092929f, 0.197819903f, 2.69082141f}, {-0.201005429f, 0.195805743f, 2.67481017f},
    {-0.197749138f, 0.194150999f, 2.65931559f}, {-0.194309086f, 0.203389511f, 2.65017748f},
    {-0.180673078f, 0.210797638f, 2.63288045f}, {-0.165478557f, 0.201961324f, 2.61767983f},
    {-0.157231227f, 0.192143857f, 2.61364388f}, {-0.142182529f, 0.192891821f, 2.60850501f},
    {-0.126225471f, 0.194111198f, 2.60643077f}, {-0.109973244f, 0.195755079f, 2.60750079f},
    {-0.0940501988f, 0.197760329f, 2.61167359f}, {-0.079068467f, 0.200049862f, 2.6187892f}});
  const std::vector<Vec3> spine = toVec3s({
    {-0.0181315541f, -0.837393403f, 2.74609756f}, {-0.0662833005f, -0.340251625f, 2.72304392f},
    {-0.0743152276f, -0.257326156f, 2.71919847f}, {-0.0823471546f, -0.174400687f, 2.71535277f},
    {-0.0889187381f, -0.106552601f, 2.7122066f}, {-0.0954903141f, -0.0387044847f, 2.70906019f},
    {-0.100221351f, 0.0112546422f, 2.70499754f}, {-0.104952388f, 0.061213769f, 2.70093465f},
    {-0.10863208f, 0.100070849f, 2.69777489f}, {-0.112311773f, 0.138927937f, 2.69461489f},
    {-0.118542969f, 0.205158174f, 2.6882472f}, {-0.120906428f, 0.230617329f, 2.68503165f},
    {-0.123269893f, 0.256076485f, 2.6818161f}, {-0.114462316f, 0.294937998f, 2.68244147f},
    {-0.105654746f, 0.333799481f, 2.68306708f}, {-0.102188654f, 0.349092841f, 2.68331337f},
    {-0.0987225696f, 0.364386171f, 2.68355942f}, {-0.095256485f, 0.379679501f, 2.6838057f},
    {-0.0917904004f, 0.394972861f, 2.68405175f}, {-0.0868388489f, 0.416820496f, 2.68440342f},
    {-0.0818872973f, 0.438668132f, 2.68475509f}, {-0.0779260546f, 0.45614624f, 2.68503642f},
    {-0.0739648193f, 0.473624349f, 2.68531775f}, {-0.0680229515f, 0.499841511f, 2.68573976f}});
  const double reference = loopLinkingReference(collar, spine);
  EXPECT_NEAR(reference, -0.981, 0.001);
  EXPECT_NEAR(loopLinking(collar, spine), reference, 1e-5);
}

// A loop of n points in the plane of `ring` (its frame's first and third columns; the second is
// the chain's direction), radius r round `centre`: the ring's own ellipse (ringPointAt) moved and
// made round.
std::vector<Vec3> loopInRingPlane(const RingPose& ring, const Vec3& centre, float r, int n = 48) {
  RingPose round = ring;
  round.centre = centre;
  round.forward_m = round.side_m = r;
  std::vector<Vec3> loop;
  for (int k = 0; k < n; ++k) {
    const float a = 2.0f * kPi * static_cast<float>(k) / static_cast<float>(n);
    loop.push_back(ringPointAt(round, std::cos(a), std::sin(a)));
  }
  return loop;
}

// The body parts run to the tips of the mesh (crown, fingertips, toes), not to the last ring's
// centre: a cuff round the hand, the fingers through it, is on the arm. Ending at the hand joint,
// as the arms did before, that cuff read 0.5, and a cuff at a CMU take's wrist (the hand joint
// 3.5 cm past it) went off whenever the hand bent.
TEST(GarmentOpeningsOnTheBody, BodyPartsRunToTheTipsSoACuffRoundTheHandIsOn) {
  Context ctx(test::defaultDesc());
  const BodyModel& body = ctx.restBody();
  const std::vector<std::vector<Vec3>> parts = GarmentOpenings::bodyPolylines(body);
  ASSERT_EQ(parts.size(), 5u);  // spine, arm L / R, leg L / R
  EXPECT_EQ(parts[0].back(), body.apex(Chain::Head));
  EXPECT_EQ(parts[1].back(), body.apex(Chain::ArmL));
  EXPECT_EQ(parts[2].back(), body.apex(Chain::ArmR));
  EXPECT_EQ(parts[3].back(), body.apex(Chain::LegL));
  EXPECT_EQ(parts[4].back(), body.apex(Chain::LegR));

  const RingPose& hand = body.rings()[static_cast<size_t>(body.chainFirstRing(Chain::ArmR) +
                                                          body.chainRingCount(Chain::ArmR) - 1)];
  const float r = std::max(hand.forward_m, hand.side_m) + 0.025f;
  // Round the hand ring: the fingers (to the apex) go through it.
  EXPECT_GE(std::fabs(loopLinking(loopInRingPlane(hand, hand.centre, r), parts[2])), GarmentOpenings::kBindLinking);
  // Slid 2 cm past the fingertips: off.
  const Vec3 past = body.apex(Chain::ArmR) + 0.02f * hand.frame.col(1);
  EXPECT_LT(std::fabs(loopLinking(loopInRingPlane(hand, past, r), parts[2])), GarmentOpenings::kOffLinking);
}

struct OpeningsOfKind {
  GarmentKind kind;
  uint32_t openings;  // hem, collar and sleeves; waistband and legs; a skirt's hem and waistband
};

class GarmentOpeningsOfTemplates : public ::testing::TestWithParam<OpeningsOfKind> {};

TEST_P(GarmentOpeningsOfTemplates, EveryOpeningRoundItsBodyPartUntilCarriedOff) {
  Context ctx(test::defaultDesc());
  std::string err;
  GarmentSim* g = test::addTemplate(ctx, GetParam().kind, 1000, ClothSolverKind::Xpbd, GarmentSimParams{}, err);
  ASSERT_NE(g, nullptr) << err;
  const GarmentAccuracy dressed = g->measure(ctx.restEllipsoids(), nullptr, &ctx.restBody());
  EXPECT_EQ(dressed.openings.tracked, GetParam().openings);
  EXPECT_EQ(dressed.openings.off, 0u);
  // Without a body, nothing is counted.
  EXPECT_EQ(g->measure(ctx.restEllipsoids(), nullptr).openings.tracked, 0u);

  // The rim gate's marks (markOn): dressed, the particles of the openings round a limb (sleeves,
  // armholes, trouser legs; not the hem, collar or waist round the spine) and no others.
  GarmentOpenings o;
  std::vector<Vec3> at(g->particleCount());
  for (size_t i = 0; i < at.size(); ++i) at[i] = g->positions()[i].head<3>();
  o.bind(g->mesh().indices, at, ctx.restBody());
  std::vector<uint8_t> on;
  o.markOn(g->positions(), g->particleCount(), ctx.restBody(), on);
  ASSERT_EQ(on.size(), g->particleCount());
  size_t rim_particles = 0;
  for (const std::vector<uint32_t>& loop : boundaryLoops(g->mesh().indices, g->particleCount()))
    rim_particles += loop.size();
  const size_t marked = static_cast<size_t>(std::count(on.begin(), on.end(), uint8_t{1}));
  // Some (a skirt's hem goes round a leg most, its waist round the spine), never all: every kind
  // has a loop round the spine (hem, collar or waist).
  EXPECT_GT(marked, 0u);
  EXPECT_LT(marked, rim_particles);

  // Carried 1 m sideways, off the body: every opening is off.
  Eigen::Vector4f* x = g->solverFace()->mutableX();
  for (size_t i = 0; i < g->particleCount(); ++i) x[i].x() += 1.0f;
  const GarmentAccuracy carried = g->measure(ctx.restEllipsoids(), nullptr, &ctx.restBody());
  EXPECT_EQ(carried.openings.tracked, GetParam().openings);
  EXPECT_EQ(carried.openings.off, GetParam().openings);
  // ... and the gate marks nothing.
  o.markOn(g->positions(), g->particleCount(), ctx.restBody(), on);
  EXPECT_EQ(std::count(on.begin(), on.end(), uint8_t{1}), 0);
}

INSTANTIATE_TEST_SUITE_P(Kinds, GarmentOpeningsOfTemplates,
                         ::testing::Values(OpeningsOfKind{GarmentKind::TShirt, 4}, OpeningsOfKind{GarmentKind::LongSleeve, 4},
                                           OpeningsOfKind{GarmentKind::Dress, 4}, OpeningsOfKind{GarmentKind::Skirt, 2},
                                           OpeningsOfKind{GarmentKind::Trousers, 3}),
                         [](const ::testing::TestParamInfo<OpeningsOfKind>& info) {
                           std::string name = garmentKindName(info.param.kind);
                           name.erase(std::remove(name.begin(), name.end(), '-'), name.end());
                           return name;
                         });

}  // namespace
}  // namespace drape
