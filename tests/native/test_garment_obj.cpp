// OBJ garments (native/src/cloth/garment_obj.h): the parser's edge cases and errors, the real
// MakeHuman suits in ../shared/data (counts, the source weight, the fit onto light, default and
// heavy bodies against an un-retargeted placement, the pinned waistband and collar).
#include "body/body_model.h"
#include "body/body_shape.h"
#include "body/mesh_metrics.h"
#include "cloth/garment_obj.h"
#include "cloth/garment_topology.h"
#include "proxies/mesh_bvh.h"
#include "test_data.h"

#include "sanitizer_scale.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <iterator>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace drape {
namespace {

constexpr const char* kDir = "garments_makehuman_cc0/";

// Reads a file of the MakeHuman set into `mesh`, skipping the test when the data is absent.
#define LOAD_SUIT(mesh, file)                                             \
  DRAPE_REQUIRE_SHARED(mesh##_path, std::string(kDir) + (file));         \
  ObjMesh mesh;                                                           \
  {                                                                       \
    std::string load_err;                                                 \
    ASSERT_TRUE(readObjFile(mesh##_path, mesh, load_err)) << load_err;    \
  }

bool parse(const std::string& text, ObjMesh& m, std::string& err) {
  return parseObj(text.data(), text.size(), m, err);
}

// ---- Parser -----------------------------------------------------------------------------------

TEST(GarmentObjParse, FaceFormsNegativeIndicesAndIgnoredStatements) {
  const std::string text =
      "# comment\r\n"
      "mtllib x.mtl\r\n"
      "o thing\r\n"
      "v 0 0 0\r\n"
      "v 1 0 0 1.0\r\n"
      "v 0 1 0\r\n"
      "v +1 1 0  # trailing comment\r\n"
      "vt 0 0\r\n"
      "vn 0 0 1\r\n"
      "\r\n"
      "g group\r\n"
      "s off\r\n"
      "usemtl cloth\r\n"
      "f 1/1 2/1/1 3//1\r\n"
      "f -3 -1 -2\r\n";
  ObjMesh m;
  std::string err;
  ASSERT_TRUE(parse(text, m, err)) << err;
  ASSERT_EQ(m.positions.size(), 4u);
  EXPECT_EQ(m.positions[3], Vec3(1, 1, 0));
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 1, 3, 2}));
}

TEST(GarmentObjParse, QuadsSplitAlongShorterDiagonalNgonsFanned) {
  // Quad 1-2-3-4 whose 2-4 diagonal is the shorter one; then the same quad rotated so 1-3 is.
  const std::string quads =
      "v 0 0 0\nv 2 -1 0\nv 4 0 0\nv 2 1 0\n"
      "f 1 2 3 4\nf 2 3 4 1\n";
  ObjMesh m;
  std::string err;
  ASSERT_TRUE(parse(quads, m, err)) << err;
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 3, 1, 2, 3, 1, 2, 3, 1, 3, 0}));
  ASSERT_TRUE(parse("v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nf 1 2 3 4 5\n", m, err)) << err;
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 4}));
}

TEST(GarmentObjParse, UnusedVerticesDroppedAndForwardReferences) {
  ObjMesh m;
  std::string err;
  ASSERT_TRUE(parse("v 9 9 9\nf 2 3 5\nv 0 0 0\nv 1 0 0\nv 7 7 7\nv 0 1 0\n", m, err)) << err;
  ASSERT_EQ(m.positions.size(), 3u);
  EXPECT_EQ(m.positions[0], Vec3(0, 0, 0));
  EXPECT_EQ(m.positions[2], Vec3(0, 1, 0));
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2}));
}

TEST(GarmentObjParse, ErrorsNameTheLineAndLeaveOutputUntouched) {
  const std::string v3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  const struct {
    std::string text, expect;
  } cases[] = {
      {"v 0 0 0\nv 1 x 0\n", "line 2: malformed number 'x'"},
      {"v 0 0 0\nv 1 0\n", "line 2: vertex needs x y z"},
      {"v 0 0 0\nv 1 nan 0\n", "line 2: non-finite coordinate"},
      {"v 0 0 0\nv 1 1e60 0\n", "line 2: non-finite coordinate"},
      {v3 + "f 0 1 2\n", "line 4: vertex index 0"},
      {v3 + "f 1 2 4\n", "line 4: vertex index 4 out of range (3 vertices)"},
      {v3 + "f -1 -2 -4\n", "line 4: relative vertex index -4 out of range"},
      {v3 + "\nf 1 2\n", "line 5: face with 2 vertices"},
      {v3 + "f 1 2 1\n", "line 4: degenerate face"},
      {v3 + "f 1/a 2 3\n", "line 4: malformed face corner '1/a'"},
      {v3 + "curv 0 1 1 2\n", "line 4: unsupported statement 'curv'"},
      {v3 + "# only vertices\n", "no faces"},
      {"", "no faces"},
  };
  for (const auto& c : cases) {
    ObjMesh m;
    m.positions.assign(1, Vec3(5, 5, 5));
    std::string err;
    EXPECT_FALSE(parse(c.text, m, err)) << c.text;
    EXPECT_NE(err.find(c.expect), std::string::npos) << "got '" << err << "' for:\n" << c.text;
    EXPECT_EQ(m.positions.size(), 1u);
    EXPECT_TRUE(m.indices.empty());
  }
}

TEST(GarmentObjParse, ReadFileReportsIoErrors) {
  ObjMesh m;
  std::string err;
  EXPECT_FALSE(readObjFile("/nonexistent/dir/garment.obj", m, err));
  EXPECT_NE(err.find("cannot open '/nonexistent/dir/garment.obj'"), std::string::npos) << err;
}

// ---- Real files -------------------------------------------------------------------------------

// Vertex sets of the connected components, largest first.
std::vector<std::vector<uint32_t>> components(const ObjMesh& m) {
  std::vector<uint32_t> parent(m.positions.size());
  for (uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto find = [&](uint32_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    parent[find(m.indices[t])] = find(m.indices[t + 1]);
    parent[find(m.indices[t + 1])] = find(m.indices[t + 2]);
  }
  std::vector<std::vector<uint32_t>> byRoot(parent.size());
  for (uint32_t i = 0; i < parent.size(); ++i) byRoot[find(i)].push_back(i);
  std::vector<std::vector<uint32_t>> out;
  for (auto& c : byRoot) if (!c.empty()) out.push_back(std::move(c));
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.size() > b.size(); });
  return out;
}

TEST(GarmentObjReal, CountsMatchTheDataReadme) {
  const struct {
    const char* file;
    size_t verts, quads, components;
  } files[] = {{"female_casualsuit02.obj", 2876, 2744, 3},
               {"female_elegantsuit01.obj", 2205, 2096, 2},
               {"male_casualsuit02.obj", 2136, 2060, 2},
               {"body_proxy_female1605.obj", 1605, 1584, 2}};
  for (const auto& f : files) {
    LOAD_SUIT(m, f.file);
    EXPECT_EQ(m.positions.size(), f.verts) << f.file;
    EXPECT_EQ(m.indices.size(), 6 * f.quads) << f.file;
    EXPECT_EQ(components(m).size(), f.components) << f.file;
  }
}

TEST(GarmentObjReal, SourceWeightIsTheBodyProxyVolumeTimesDensity) {
  LOAD_SUIT(m, "body_proxy_female1605.obj");
  const auto comps = components(m);
  ASSERT_EQ(comps.size(), 2u);
  ASSERT_EQ(comps[1].size(), 50u);  // the separate mouth part
  std::vector<char> body(m.positions.size(), 0);
  for (uint32_t v : comps[0]) body[v] = 1;
  std::vector<uint32_t> tris;
  std::vector<Vec3> metres;
  for (const Vec3& v : m.positions) metres.push_back(0.1f * v);  // decimetres
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    if (body[m.indices[t]]) tris.insert(tris.end(), &m.indices[t], &m.indices[t] + 3);
  }
  const double kg = signedVolume(metres, tris) * 1010.0;
  std::printf("body proxy: %.6f m^3 -> %.2f kg\n", kg / 1010.0, kg);
  EXPECT_NEAR(kg, ObjFitParams{}.source_weight_kg, 0.02 * kg);
}

// ---- Fitting ----------------------------------------------------------------------------------

struct ObjTestBody {
  ResolvedShape shape;
  BodyModel model;
  ObjTestBody(float height, float weight, float arm_down = 35.0f, BodyModelParams params = {})
      : shape(resolve(height, weight)), model(shape, params) {
    model.update(restPose(shape, arm_down));
  }
  static ResolvedShape resolve(float height, float weight) {
    BodyShapeInput in;
    in.height_m = height;
    in.weight_kg = weight;
    return resolveShape(in);
  }
};
const ObjTestBody& objLightBody() { static const ObjTestBody b(1.55f, 45.0f); return b; }
const ObjTestBody& objDefaultBody() { static const ObjTestBody b(1.70f, 65.0f); return b; }
const ObjTestBody& objHeavyBody() { static const ObjTestBody b(1.85f, 110.0f); return b; }

// How the garment sits on the body: signed distance to the body mesh (negative inside; inside
// from the winding number, since the body mesh intersects itself at the shoulders and crotch).
struct Fit {
  float median = 0, median_abs = 0, p90_abs = 0, deep = 0;  // metres; deep: fraction > 2 cm inside
};
Fit measure(const std::vector<Vec3>& pts, const BodyModel& body) {
  TriangleBvh bvh;
  bvh.build(body.positions(), body.indices());
  std::vector<float> d, a;
  int deep = 0;
  // Under the sanitizers the statistics are over every fourth vertex: the fit under test has run
  // on all of them, and this test-side winding number over every body triangle per vertex was 80 %
  // of GarmentObjFit.SuitsSitOnLightDefaultAndHeavyBodies' ASan time (perf record).
  const size_t stride = test::kSanitizedBuild ? 4 : 1;
  for (size_t i = 0; i < pts.size(); i += stride) {
    const Vec3& p = pts[i];
    const float dist = bvh.closest(p).distance;
    const bool inside = windingNumber(body.positions(), body.indices(), p) > 0.5;
    d.push_back(inside ? -dist : dist);
    a.push_back(dist);
    deep += inside && dist > 0.02f;
  }
  const auto q = [](std::vector<float> v, double f) {
    std::nth_element(v.begin(), v.begin() + static_cast<long>(f * (v.size() - 1)), v.end());
    return v[static_cast<size_t>(f * (v.size() - 1))];
  };
  return {q(d, 0.5), q(a, 0.5), q(a, 0.9), static_cast<float>(deep) / static_cast<float>(d.size())};
}

// The suits with the source parameters docs/garment-obj.md gives for them: the male suit was
// made for a taller body than the base mesh (collar 1.50 m above the floor, the female suits'
// 1.35 m).
struct Suit {
  const char* file;
  float height, weight;
  size_t pins;  // waistband + collar
};
const Suit kSuits[] = {{"female_casualsuit02.obj", 1.60f, 46.3f, 64 + 20},
                       {"female_elegantsuit01.obj", 1.60f, 46.3f, 26},  // the open jacket stays free
                       {"male_casualsuit02.obj", 1.76f, 60.0f, 26 + 20},
                       {"body_proxy_female1605.obj", 1.60f, 46.3f, 0}};

ObjFitParams paramsFor(const Suit& s) {
  ObjFitParams p;
  p.source_height_m = s.height;
  p.source_weight_kg = s.weight;
  return p;
}

// Edge lengths after the fit over before (the placement on the source body), sorted.
std::vector<float> edgeRatios(const ObjMesh& m, const std::vector<Vec3>& before, const std::vector<Vec3>& after) {
  std::vector<float> r;
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = m.indices[t + k], b = m.indices[t + (k + 1) % 3];
      r.push_back((after[a] - after[b]).norm() / (before[a] - before[b]).norm());
    }
  }
  std::sort(r.begin(), r.end());
  return r;
}

void expectSane(const ObjMesh& m, const GarmentMesh& g) {
  ASSERT_EQ(g.positions.size(), m.positions.size());
  EXPECT_EQ(g.indices, m.indices);
  ASSERT_EQ(g.pin_ring.size(), g.pinned.size());
  ASSERT_EQ(g.pin_local.size(), g.pinned.size());
  for (const Vec3& v : g.positions) ASSERT_TRUE(isFinite(v));
  for (const Vec3& v : g.pin_local) ASSERT_TRUE(isFinite(v));
  TopologyParams tp;  // the cloth solvers accept it as it is
  tp.pinned = g.pinned;
  GarmentTopology topo;
  std::string err;
  EXPECT_TRUE(buildGarmentTopology(g.positions.data()->data(), g.positions.size(), g.indices.data(), g.indices.size(),
                                   tp, topo, err)) << err;
}

// Under the sanitizers the first suit only (tests/native/sanitizer_scale.h).
constexpr int kSuitsToFit = test::repeatsUnderSanitizers(static_cast<int>(std::size(kSuits)), 100);

TEST(GarmentObjFit, SuitsSitOnLightDefaultAndHeavyBodies) {
  for (const Suit& s : std::vector<Suit>(kSuits, kSuits + kSuitsToFit)) {
    LOAD_SUIT(m, s.file);
    std::string err;
    std::vector<Vec3> placed;
    ASSERT_TRUE(placeObjOnSourceBody(m, paramsFor(s), placed, err)) << err;
    for (const ObjTestBody* b : {&objLightBody(), &objDefaultBody(), &objHeavyBody()}) {
      GarmentMesh g;
      ASSERT_TRUE(fitObjGarment(m, paramsFor(s), b->model, g, err)) << err;
      expectSane(m, g);
      const Fit f = measure(g.positions, b->model);
      const std::vector<float> r = edgeRatios(m, placed, g.positions);
      const float med = r[r.size() / 2], p99 = r[r.size() * 99 / 100];
      std::printf("%-26s on %.2f m / %3.0f kg: median %+4.1f cm, median |d| %3.1f cm, P90 |d| %3.1f cm, "
                  "> 2 cm inside %4.1f %%; edge ratio median %.2f P99 %.2f\n", s.file, b->shape.input.height_m,
                  b->shape.input.weight_kg, 100 * f.median, 100 * f.median_abs, 100 * f.p90_abs, 100 * f.deep, med,
                  p99);
      EXPECT_LT(f.median_abs, 0.03f) << s.file;
      EXPECT_LT(f.p90_abs, 0.09f) << s.file;
      EXPECT_LT(f.deep, 0.12f) << s.file;
      EXPECT_LT(p99, 1.65f * med) << s.file;  // grows with the body without tearing
    }
  }
}

TEST(GarmentObjFit, RetargetingBeatsPlainPlacementOnHeavyBody) {
  const ObjTestBody& heavy = objHeavyBody();
  for (const Suit& s : std::vector<Suit>(kSuits, kSuits + kSuitsToFit)) {
    LOAD_SUIT(m, s.file);
    std::string err;
    const ObjFitParams p = paramsFor(s);
    GarmentMesh g;
    std::vector<Vec3> placed, scaled;
    ASSERT_TRUE(fitObjGarment(m, p, heavy.model, g, err)) << err;
    ASSERT_TRUE(placeObjOnSourceBody(m, p, placed, err)) << err;
    // A fairer baseline than the plain placement: scaled by the height ratio about the floor.
    const Vec3 floor(0.0f, 0.0f, restPose(heavy.shape).position[idx(Joint::Pelvis)].z());
    for (const Vec3& v : placed) scaled.push_back(floor + (v - floor) * (heavy.shape.input.height_m / s.height));
    const Fit fit = measure(g.positions, heavy.model), plain = measure(placed, heavy.model),
              byHeight = measure(scaled, heavy.model);
    std::printf("%-26s on the heavy body, > 2 cm inside: retargeted %4.1f %%, placed %4.1f %%, height-scaled "
                "%4.1f %%; P90 |d|: %4.1f / %4.1f / %4.1f cm\n", s.file, 100 * fit.deep, 100 * plain.deep,
                100 * byHeight.deep, 100 * fit.p90_abs, 100 * plain.p90_abs, 100 * byHeight.p90_abs);
    EXPECT_LT(fit.deep, 0.6f * std::min(plain.deep, byHeight.deep)) << s.file;
  }
}

TEST(GarmentObjFit, BlendedBindingKeepsNeighboursTogether) {
  // Neighbours bound to different chains (armpit, crotch) map to different places on a body of
  // another build unless the binding blends the nearly-nearest segments.
  LOAD_SUIT(m, "female_casualsuit02.obj");
  std::string err;
  ObjFitParams p;
  std::vector<Vec3> placed;
  ASSERT_TRUE(placeObjOnSourceBody(m, p, placed, err)) << err;
  GarmentMesh blended, nearest;
  ASSERT_TRUE(fitObjGarment(m, p, objHeavyBody().model, blended, err)) << err;
  p.blend_m = 0.0f;
  ASSERT_TRUE(fitObjGarment(m, p, objHeavyBody().model, nearest, err)) << err;
  const float worstBlended = edgeRatios(m, placed, blended.positions).back();
  const float worstNearest = edgeRatios(m, placed, nearest.positions).back();
  std::printf("heavy body, longest edge growth: %.2fx blended, %.2fx nearest segment only\n", worstBlended,
              worstNearest);
  EXPECT_LT(worstBlended, 2.5f);
  EXPECT_GT(worstNearest, 4.0f * worstBlended);
}

TEST(GarmentObjFit, SleevesFollowTheTargetArmAngle) {
  LOAD_SUIT(m, "female_elegantsuit01.obj");
  std::string err;
  std::vector<Vec3> placed;
  ASSERT_TRUE(placeObjOnSourceBody(m, ObjFitParams{}, placed, err)) << err;
  std::vector<uint32_t> sleeve;  // beyond the shoulders in the file (the torso is within 1.7 dm)
  for (uint32_t i = 0; i < m.positions.size(); ++i) if (std::fabs(m.positions[i].x()) > 2.0f) sleeve.push_back(i);
  ASSERT_GT(sleeve.size(), 300u);
  for (float arm : {15.0f, 35.0f, 70.0f}) {
    const ObjTestBody b(1.70f, 65.0f, arm);
    GarmentMesh g;
    ASSERT_TRUE(fitObjGarment(m, ObjFitParams{}, b.model, g, err)) << err;
    std::vector<Vec3> fitted, plain;
    for (uint32_t i : sleeve) fitted.push_back(g.positions[i]), plain.push_back(placed[i]);
    const Fit f = measure(fitted, b.model), q = measure(plain, b.model);
    std::printf("sleeves, arms %2.0f deg down: median |d| %4.1f cm, P90 |d| %4.1f cm (placed: %4.1f, %4.1f cm)\n",
                arm, 100 * f.median_abs, 100 * f.p90_abs, 100 * q.median_abs, 100 * q.p90_abs);
    EXPECT_LT(f.median_abs, 0.025f);
    EXPECT_LT(f.p90_abs, 0.06f);
    EXPECT_LT(f.median_abs, 0.5f * q.median_abs);
  }
}

TEST(GarmentObjFit, PinsAreWaistbandsAndCollarsAndFollowTheirRings) {
  for (const Suit& s : kSuits) {
    LOAD_SUIT(m, s.file);
    std::string err;
    const auto comps = components(m);
    for (const ObjTestBody* b : {&objLightBody(), &objHeavyBody()}) {
      GarmentMesh g;
      ASSERT_TRUE(fitObjGarment(m, paramsFor(s), b->model, g, err)) << err;
      expectSane(m, g);
      EXPECT_EQ(g.pinned.size(), s.pins) << s.file;
      const auto& R = b->model.rings();
      for (size_t i = 0; i < g.pinned.size(); ++i) {
        const RingPose& r = R[static_cast<size_t>(g.pin_ring[i])];
        EXPECT_LT((r.centre + r.frame * g.pin_local[i] - g.positions[g.pinned[i]]).norm(), 1e-5f);
      }
      // Each pinned component's loop: a waistband between the hip and waist rings, or a collar at
      // the neck-base ring N.
      const float hipY = R[b->model.chainFirstRing(Chain::Torso)].centre.y();
      float waistY = 0.0f;
      for (int r = 0; r < static_cast<int>(R.size()); ++r) {
        if (b->model.stations()[r].measure == static_cast<int>(Measure::Waist)) waistY = R[r].centre.y();
      }
      const float neckY = R[b->model.chainFirstRing(Chain::Head)].centre.y();
      std::vector<int> owner(m.positions.size(), -1);
      for (size_t c = 0; c < comps.size(); ++c) for (uint32_t v : comps[c]) owner[v] = static_cast<int>(c);
      for (size_t c = 0; c < comps.size(); ++c) {
        float sum = 0.0f;
        int n = 0;
        for (uint32_t v : g.pinned) if (owner[v] == static_cast<int>(c)) sum += g.positions[v].y(), ++n;
        if (n == 0) continue;
        const float y = sum / static_cast<float>(n);
        const bool waistband = y > hipY - 0.03f && y < waistY + 0.03f;
        const bool collar = std::fabs(y - neckY) < 0.05f;
        std::printf("%-26s %.2f m: component %zu pins %2d loop at %.3f m (hip ring %.3f, waist %.3f, neck base %.3f)\n",
                    s.file, b->shape.input.height_m, c, n, y, hipY, waistY, neckY);
        EXPECT_TRUE(waistband || collar) << s.file << " component " << c << " pinned at y " << y;
      }
    }
  }
}

TEST(GarmentObjFit, DenserRingLayoutsGiveTheSameFit) {
  LOAD_SUIT(m, "female_casualsuit02.obj");
  std::string err;
  BodyModelParams dense;
  dense.ring_points = 32;
  dense.rings_per_segment = 3;
  const ObjTestBody b(1.70f, 65.0f, 35.0f, dense);
  GarmentMesh g, g0;
  ASSERT_TRUE(fitObjGarment(m, ObjFitParams{}, b.model, g, err)) << err;
  ASSERT_TRUE(fitObjGarment(m, ObjFitParams{}, objDefaultBody().model, g0, err)) << err;
  expectSane(m, g);
  std::vector<float> moved;
  for (size_t i = 0; i < g.positions.size(); ++i) moved.push_back((g.positions[i] - g0.positions[i]).norm());
  std::sort(moved.begin(), moved.end());
  EXPECT_LT(moved[moved.size() / 2], 0.01f);  // ring interpolation differs, the fit barely does
  EXPECT_EQ(g.pinned.size(), g0.pinned.size());
}

TEST(GarmentObjFit, FrameUnitsAndWinding) {
  // A closed tetrahedron, counter-clockwise outward, 1.6 units tall.
  ObjMesh m;
  m.positions = {Vec3(0, -0.8f, 0), Vec3(0.3f, -0.8f, 0), Vec3(0, 0.8f, 0), Vec3(0, -0.8f, 0.3f)};
  m.indices = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  const double vol = signedVolume(m.positions, m.indices);
  ObjFitParams p;
  p.source_floor_y = -0.8f;
  p.source_axis_z = 0.0f;
  std::vector<Vec3> plusZ, minusZ, mm;
  std::string err;
  ASSERT_TRUE(placeObjOnSourceBody(m, p, plusZ, err)) << err;
  p.facing = ObjFacing::MinusZ;
  ASSERT_TRUE(placeObjOnSourceBody(m, p, minusZ, err)) << err;
  const float z0 = restPose(resolveShape(BodyShapeInput{})).position[idx(Joint::Pelvis)].z();
  EXPECT_LT((plusZ[1] - Vec3(-0.3f, 0.0f, z0)).norm(), 1e-6f);  // +X (their left) -> -X
  EXPECT_LT((plusZ[3] - Vec3(0.0f, 0.0f, z0 - 0.3f)).norm(), 1e-6f);  // +Z (their front) -> -Z
  EXPECT_LT((minusZ[3] - Vec3(0.0f, 0.0f, z0 + 0.3f)).norm(), 1e-6f);
  EXPECT_GT(signedVolume(plusZ, m.indices) * vol, 0.0);  // proper rotation: winding kept
  // Auto units: 1.6 units is metres; 1600 units millimetres.
  ObjMesh big = m;
  for (Vec3& v : big.positions) v *= 1000.0f;
  p.source_floor_y = -0.8f;
  ASSERT_TRUE(placeObjOnSourceBody(big, p, mm, err)) << err;
  EXPECT_LT((mm[2] - minusZ[2]).norm(), 1e-4f);
}

TEST(GarmentObjFit, RejectsBadInputLeavingOutputUntouched) {
  ObjMesh tri;
  tri.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  tri.indices = {0, 1, 2};
  GarmentMesh g;
  g.positions.assign(1, Vec3(7, 7, 7));
  const auto rejects = [&](const ObjMesh& m, const ObjFitParams& p, const char* expect) {
    std::string err;
    EXPECT_FALSE(fitObjGarment(m, p, objDefaultBody().model, g, err)) << expect;
    EXPECT_NE(err.find(expect), std::string::npos) << "got '" << err << "'";
    EXPECT_EQ(g.positions.size(), 1u);
  };
  ObjFitParams p;
  p.unit_scale = -1.0f;
  rejects(tri, p, "unit_scale");
  p = {};
  p.source_arm_down_deg = NAN;
  rejects(tri, p, "source pose");
  p = {};
  p.source_weight_kg = 5.0f;
  rejects(tri, p, "source body");
  p = {};
  p.blend_m = 1.0f;
  rejects(tri, p, "blend_m");
  ObjMesh bad = tri;
  bad.indices = {0, 1, 3};
  rejects(bad, {}, "indices in range");
  bad = tri;
  bad.positions[1].x() = INFINITY;
  rejects(bad, {}, "non-finite");
  bad = tri;
  for (Vec3& v : bad.positions) v = Vec3(1, 1, 1);
  rejects(bad, {}, "coincide");
  bad = tri;
  bad.positions[1].x() = 5000.0f;
  rejects(bad, {}, "no unit");
  bad = tri;
  bad.positions.push_back(Vec3(0, 0, 1));
  rejects(bad, {}, "vertex 3 is used by no triangle");
}

}  // namespace
}  // namespace drape
