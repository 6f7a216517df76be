// Procedural garment templates (native/src/cloth/garment_templates.h): for every kind and for a
// thin and a heavy body, the particle count is near the target, the mesh is a consistently wound
// 2-manifold with boundary, it starts outside the tracking ellipsoids, its pins follow their rings,
// the topology builder accepts it, and one second of XPBD with collision keeps it sane; on the
// arms-down pose garments are cut on, no vertex under the arms gathers a fan of neighbours.
#include "body/body_model.h"
#include "body/body_shape.h"
#include "cloth/cloth_stats.h"
#include "cloth/garment_templates.h"
#include "cloth/xpbd_solver.h"
#include "proxies/collision.h"
#include "proxies/proxy_builder.h"
#include "sanitizer_scale.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace drape {
namespace {

struct Body {
  ResolvedShape shape;
  BodyModel model;
  std::vector<Ellipsoid> ellipsoids;
  Body(float height, float weight) : shape(resolve(height, weight)), model(shape, BodyModelParams{}) {
    const SkeletonPose pose = restPose(shape);
    model.update(pose);
    ProxyBuilder pb(ProxyRule::Drape);
    pb.build(model, pose);
    ellipsoids = pb.ellipsoids();
  }
  static ResolvedShape resolve(float height, float weight) {
    BodyShapeInput in;
    in.height_m = height;
    in.weight_kg = weight;
    return resolveShape(in);
  }
};

const Body& thinBody() {
  static const Body b(1.60f, 48.0f);
  return b;
}
const Body& heavyBody() {
  static const Body b(1.80f, 110.0f);
  return b;
}

struct Case {
  GarmentKind kind;
  bool heavy;
  int target;
};

std::string caseName(const testing::TestParamInfo<Case>& info) {
  std::string n = garmentKindName(info.param.kind);
  for (char& c : n) if (c == '-') c = '_';
  return n + (info.param.heavy ? "_heavy_" : "_thin_") + std::to_string(info.param.target);
}

class GarmentTemplate : public testing::TestWithParam<Case> {
 protected:
  void SetUp() override {
    body_ = GetParam().heavy ? &heavyBody() : &thinBody();
    GarmentTemplateParams p;
    p.kind = GetParam().kind;
    p.target_particles = GetParam().target;
    // The geometry bounds below were measured with the 1.5 cm ease of the first templates; the
    // default is 2.5 cm now (docs/garments.md), which lets a dress sag a little more unattached.
    p.ease_m = 0.015f;
    std::string err;
    ok_ = makeGarmentTemplate(body_->model, p, mesh_, err);
    ASSERT_TRUE(ok_) << err;
  }
  const Body* body_ = nullptr;
  GarmentMesh mesh_;
  bool ok_ = false;
};

TEST_P(GarmentTemplate, ParticleCountNearTarget) {
  // Within 1 % before the weld, which takes a few seam vertices (up to 1.6 % seen on trousers).
  const double n = static_cast<double>(mesh_.positions.size()), t = GetParam().target;
  EXPECT_GE(n, 0.975 * t);
  EXPECT_LE(n, 1.02 * t);
}

TEST_P(GarmentTemplate, ValidManifoldWithBoundary) {
  const auto& x = mesh_.positions;
  const auto& idx = mesh_.indices;
  ASSERT_EQ(idx.size() % 3, 0u);
  ASSERT_FALSE(idx.empty());
  std::map<std::pair<uint32_t, uint32_t>, int> directed, undirected;
  std::vector<int> used(x.size(), 0);
  for (size_t t = 0; t < idx.size(); t += 3) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_LT(idx[t + k], x.size());
      used[idx[t + k]] = 1;
    }
    const Vec3 a = x[idx[t]], b = x[idx[t + 1]], c = x[idx[t + 2]];
    EXPECT_GE(0.5f * (b - a).cross(c - a).norm(), 1e-8f) << "triangle " << t / 3;
    for (int k = 0; k < 3; ++k) {
      const uint32_t u = idx[t + k], v = idx[t + (k + 1) % 3];
      ++directed[{u, v}];
      ++undirected[{std::min(u, v), std::max(u, v)}];
    }
  }
  int bad = 0, boundary = 0;
  for (const auto& [e, n] : undirected) {
    if (n < 1 || n > 2) ++bad;
    if (n == 1) ++boundary;
  }
  EXPECT_EQ(bad, 0) << "edges in more than two triangles";
  EXPECT_GT(boundary, 0) << "a garment has open hem / neck / cuffs";
  int twice = 0;
  for (const auto& [e, n] : directed) if (n != 1) ++twice;
  EXPECT_EQ(twice, 0) << "inconsistent winding: a directed edge used twice";
  for (size_t i = 0; i < used.size(); ++i) EXPECT_TRUE(used[i]) << "vertex " << i << " unused";
}

TEST_P(GarmentTemplate, StartsOutsideEveryEllipsoid) {
  int inside = 0;
  for (const Vec3& p : mesh_.positions) {
    for (const Ellipsoid& e : body_->ellipsoids) {
      if (!(e.implicit(p) > 0.0f)) ++inside;
    }
  }
  EXPECT_EQ(inside, 0);
}

TEST_P(GarmentTemplate, PinsFollowTheirRings) {
  ASSERT_FALSE(mesh_.pinned.empty());
  ASSERT_EQ(mesh_.pin_ring.size(), mesh_.pinned.size());
  ASSERT_EQ(mesh_.pin_local.size(), mesh_.pinned.size());
  const auto& rings = body_->model.rings();
  for (size_t i = 0; i < mesh_.pinned.size(); ++i) {
    ASSERT_LT(mesh_.pinned[i], mesh_.positions.size());
    ASSERT_GE(mesh_.pin_ring[i], 0);
    ASSERT_LT(static_cast<size_t>(mesh_.pin_ring[i]), rings.size());
    const RingPose& r = rings[static_cast<size_t>(mesh_.pin_ring[i])];
    const Vec3 world = r.centre + r.frame * mesh_.pin_local[i];
    EXPECT_LT((world - mesh_.positions[mesh_.pinned[i]]).norm(), 1e-5f);
    // A pin sits near its ring (within 30 cm), not anywhere.
    EXPECT_LT(mesh_.pin_local[i].norm(), 0.3f);
  }
}

TEST_P(GarmentTemplate, SimulatesOneSecondSanely) {
  TopologyParams tp;
  tp.pinned = mesh_.pinned;
  GarmentTopology topo;
  std::string err;
  ASSERT_TRUE(buildGarmentTopology(mesh_.positions.data()->data(), mesh_.positions.size(),
                                   mesh_.indices.data(), mesh_.indices.size(), tp, topo, err))
      << err;
  XpbdSolver solver(std::move(topo));
  EllipsoidCollider collider;
  const auto& ell = body_->ellipsoids;
  collider.setEllipsoids(ell.data(), ell.data(), static_cast<int>(ell.size()));
  solver.setCollider(&collider);
  // Pins held where they are (the body does not move).
  std::vector<Vec3> targets;
  for (uint32_t v : solver.topology().pinned) targets.push_back(mesh_.positions[v]);
  for (int f = 0; f < 30; ++f) {
    ASSERT_TRUE(solver.setPinTargets(targets.data(), targets.size(), err)) << err;
    ASSERT_TRUE(solver.step(1.0f / 30.0f));
  }
  const Eigen::Vector4f* x = solver.positions();
  int nonfinite = 0, deep = 0;
  for (size_t i = 0; i < solver.particleCount(); ++i) {
    if (!x[i].allFinite() || !solver.velocities()[i].allFinite()) ++nonfinite;
    for (Ellipsoid e : ell) {
      e.radii -= Vec3::Constant(0.001f);
      e.refresh();
      if (e.implicit(x[i].head<3>()) < 0.0f) ++deep;
    }
  }
  EXPECT_EQ(nonfinite, 0);
  EXPECT_EQ(deep, 0) << "particles inside an ellipsoid by more than 1 mm";
  std::vector<float> scratch;
  const StretchStats st = stretchStats(solver.topology(), x, scratch);
  // 10 % for every kind but the long-sleeve top, whose heavy-body 8 000-particle build stretched
  // 10.3 % at the armpit (sleeve squeezed between arm and torso ellipsoids): a known gap of the
  // cloth issue, recorded in docs/cloth-solver.md. 7.5-8.1 % at 8 000 particles on 2026-11-29
  // (2.6-3.3 % at 2 000), 7.9-8.8 % (3.0-3.7 %) with the closer cuff; the bound was left at 11 %.
  const float bound = GetParam().kind == GarmentKind::LongSleeve ? 0.11f : 0.10f;
  EXPECT_LT(st.p99, bound) << "max " << st.max << " mean " << st.mean;
}

std::vector<Case> allCases() {
  std::vector<Case> c;
  for (GarmentKind k : {GarmentKind::TShirt, GarmentKind::Skirt, GarmentKind::Trousers,
                        GarmentKind::LongSleeve, GarmentKind::Dress}) {
    for (bool heavy : {false, true}) {
      for (int t : {2000, 8000}) c.push_back({k, heavy, t});
    }
  }
  return c;
}

INSTANTIATE_TEST_SUITE_P(Kinds, GarmentTemplate, testing::ValuesIn(allCases()), caseName);

// How a mesh uses its edges: undirected edges in more than two triangles, directed edges used other
// than once (inconsistent winding), vertices in no triangle, and triangles of an area the topology
// refuses (below 1e-12 m^2).
struct MeshEdgeUse {
  int shared = 0, twice = 0, unused = 0, slivers = 0;
};
MeshEdgeUse meshEdgeUse(const GarmentMesh& m) {
  MeshEdgeUse u;
  std::map<std::pair<uint32_t, uint32_t>, int> directed, undirected;
  std::vector<char> used(m.positions.size(), 0);
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const Vec3 &a = m.positions[m.indices[t]], &b = m.positions[m.indices[t + 1]], &c = m.positions[m.indices[t + 2]];
    u.slivers += !(0.5f * (b - a).cross(c - a).norm() >= 1e-12f);
    for (size_t k = 0; k < 3; ++k) {
      const uint32_t p = m.indices[t + k], q = m.indices[t + (k + 1) % 3];
      used[p] = 1;
      ++directed[{p, q}];
      ++undirected[{std::min(p, q), std::max(p, q)}];
    }
  }
  for (const auto& [e, n] : undirected) u.shared += n > 2;
  for (const auto& [e, n] : directed) u.twice += n != 1;
  u.unused = static_cast<int>(std::count(used.begin(), used.end(), 0));
  return u;
}

// The template of `kind` at `target` on `body` is a consistent manifold (no edge in more than two
// triangles, none used twice the same way) with the count drape.h promises: within 1 % before the
// weld where a ring's worth of points allows it (a skirt's ring is 56-72 points: 7-9 % of 800), the
// weld then taking up to 4 % (the trousers' crotch): -4.5 / +2.5 % from 1 000 particles up, 10 %
// below.
void expectConsistentNearTarget(const Body& body, const char* body_name, GarmentKind kind, int target) {
  GarmentTemplateParams p;
  p.kind = kind;
  p.target_particles = target;
  GarmentMesh m;
  std::string err;
  const std::string name = std::string(garmentKindName(kind)) + " " + body_name + " " + std::to_string(target);
  ASSERT_TRUE(makeGarmentTemplate(body.model, p, m, err)) << name << ": " << err;
  const MeshEdgeUse use = meshEdgeUse(m);
  EXPECT_EQ(use.shared, 0) << name << ": edges in more than two triangles";
  EXPECT_EQ(use.twice, 0) << name << ": a directed edge used twice";
  const double n = static_cast<double>(m.positions.size());
  const double below = target < 1000 ? 0.9 : 0.955, above = target < 1000 ? 1.1 : 1.025;
  EXPECT_GE(n, below * target) << name;
  EXPECT_LE(n, above * target) << name;
}

constexpr GarmentKind kAllKinds[] = {GarmentKind::TShirt, GarmentKind::Skirt, GarmentKind::Trousers,
                                     GarmentKind::LongSleeve, GarmentKind::Dress};

// Every resolution, not only the two above: on the heavy body the trousers' leg tubes pass within
// the weld's tolerance of the crotch bridge at some counts (1 244-1 540, 2 021-2 058, 3 094-3 168
// of a sweep in steps of 37), and the weld folded the two legs' triangles over a bridge segment
// into one triangle wound both ways: an edge of four triangles (weldShortEdges). The count is
// also checked here, over the range where the resolution can reach it.
TEST(GarmentTemplateResolution, EveryCountIsAConsistentManifoldNearTheTarget) {
  const int step = drape::test::kSanitizedBuild ? 421 : 37;  // 8 counts a kind and body there (7 s -> 4 s)
  int cases = 0;
  for (GarmentKind kind : kAllKinds) {
    for (bool heavy : {false, true}) {
      for (int target = 800; target <= 4000; target += step) {
        ASSERT_NO_FATAL_FAILURE(
            expectConsistentNearTarget(heavy ? heavyBody() : thinBody(), heavy ? "heavy" : "thin", kind, target));
        ++cases;
      }
    }
  }
  EXPECT_GT(cases, 40);
}

// The coarse end, 200-800 particles, where the contract is 10 %. Until the rows along the tubes
// could come as close as 0.6 of the spacing round there (kLeastAlongBelow1000), a ring's step left
// counts 11-19 % short (on the default body: a 255-particle skirt 208, 310-particle trousers 251;
// 20 of this test's builds fail with 0.8). A long sleeve's rings along the forearm are bounded there
// (kBentSleeveRingsPerCuffPerimeter) while a sleeve takes at most a quarter of the count; a larger
// share (0.3) left the 200-particle long sleeve at 0.885 of it.
TEST(GarmentTemplateResolution, CoarseCountsAreConsistentManifoldsWithinTenPercent) {
  const int step = drape::test::kSanitizedBuild ? 97 : 11;
  static const Body standard(1.70f, 65.0f);  // the C ABI's default shape
  const std::pair<const Body*, const char*> bodies[] = {
      {&thinBody(), "thin"}, {&standard, "standard"}, {&heavyBody(), "heavy"}};
  int cases = 0;
  for (GarmentKind kind : kAllKinds) {
    for (const auto& [body, body_name] : bodies) {
      for (int target = 200; target < 800; target += step) {
        ASSERT_NO_FATAL_FAILURE(expectConsistentNearTarget(*body, body_name, kind, target));
        ++cases;
      }
    }
  }
  EXPECT_GT(cases, 80);
}

// Bodies and parameters at the ends of their ranges: short and tall, thin and heavy, the least and
// most ease, short and long cuts, small and large counts. Before the weld dropped folded fins
// (weldShortEdges) a sweep of 2 700 such builds found edges of more than two triangles on some of
// them, a T-shirt among them (1.75 m, 92 kg, 2 mm of ease, 5 000 particles); four of those are in
// this subset (run on the code before that change, it fails on exactly those four).
TEST(GarmentTemplateResolution, ExtremeBodiesAndParametersGiveConsistentManifolds) {
  int cases = 0;
  for (float height : {1.45f, 1.75f, 2.05f}) {
    for (float bmi : {16.0f, 30.0f, 40.0f}) {
      // Under the sanitizers the two bodies of the four that failed before (7.8 s -> 5 s there).
      if (drape::test::kSanitizedBuild && (bmi != 30.0f || height < 1.7f)) continue;
      const Body body(height, bmi * height * height);
      for (GarmentKind kind : kAllKinds) {
        for (float ease : {0.002f, 0.1f}) {
          for (float length : {0.5f, 1.0f}) {
            for (int target : {700, 5000}) {
              GarmentTemplateParams p;
              p.kind = kind;
              p.target_particles = target;
              p.ease_m = ease;
              p.length_scale = length;
              GarmentMesh m;
              std::string err;
              char name[128];
              std::snprintf(name, sizeof name, "%s on %.2f m, BMI %.0f, ease %.3f, length %.1f, %d particles",
                            garmentKindName(kind), height, bmi, ease, length, target);
              ASSERT_TRUE(makeGarmentTemplate(body.model, p, m, err)) << name << ": " << err;
              const MeshEdgeUse use = meshEdgeUse(m);
              int finite = 0;
              for (const Vec3& x : m.positions) finite += x.allFinite();
              EXPECT_EQ(use.shared, 0) << name << ": edges in more than two triangles";
              EXPECT_EQ(use.twice, 0) << name << ": a directed edge used twice";
              EXPECT_EQ(use.slivers, 0) << name;
              EXPECT_EQ(finite, static_cast<int>(m.positions.size())) << name;
              EXPECT_EQ(use.unused, 0) << name << ": vertices in no triangle";
              EXPECT_FALSE(m.pinned.empty()) << name;
              ++cases;
            }
          }
        }
      }
    }
  }
  EXPECT_EQ(cases, drape::test::kSanitizedBuild ? 80 : 360);
}

TEST(GarmentTemplateInput, BadParamsRejectedAndOutputUntouched) {
  const Body& b = thinBody();
  GarmentMesh mesh;
  mesh.pinned = {7};
  std::string err;
  GarmentTemplateParams p;
  p.target_particles = 10;
  EXPECT_FALSE(makeGarmentTemplate(b.model, p, mesh, err));
  EXPECT_FALSE(err.empty());
  p = GarmentTemplateParams{};
  p.ease_m = std::nanf("");
  EXPECT_FALSE(makeGarmentTemplate(b.model, p, mesh, err));
  p = GarmentTemplateParams{};
  p.kind = static_cast<GarmentKind>(9);
  EXPECT_FALSE(makeGarmentTemplate(b.model, p, mesh, err));
  p = GarmentTemplateParams{};
  p.length_scale = 3.0f;
  EXPECT_FALSE(makeGarmentTemplate(b.model, p, mesh, err));
  ASSERT_EQ(mesh.pinned.size(), 1u);
  EXPECT_EQ(mesh.pinned[0], 7u);
}

// Garments are cut with the arms 65 degrees down (capi/context.cpp, kGarmentRestArmDownDeg), where
// the sleeve's underside is built partly inside the torso's ellipsoids. Pushed out of the torso's
// and the arm's ellipsoids in turn, that strip of particles walked down the crease between them
// to one point under each arm and was welded into one vertex: the T-shirt had an underarm vertex
// of 12 neighbours at 1 802 particles and 36 at 32 168 (docs/garments.md, "The underarm fan").
// A tube of rings has vertices of 6 neighbours, the zips between rings of other counts 7-8; the
// nearest way out of the overlap (garment_templates.cpp, nearestExit) leaves at most 10 up to
// 8 000 particles and 12 at 32 000, on the default body and on a thin and a heavy one.
// Under the sanitizers the default body only (the same code for every body).
TEST(GarmentTemplateMesh, NoFanUnderTheArmsOnTheArmsDownCut) {
  const std::pair<float, float> bodies[] = {{1.70f, 65.0f}, {1.60f, 48.0f}, {1.80f, 110.0f}};
  for (int b = 0; b < test::repeatsUnderSanitizers(3, 3); ++b) {
    const auto [height, weight] = bodies[b];
    const ResolvedShape shape = Body::resolve(height, weight);
    BodyModel model(shape, BodyModelParams{});
    model.update(restPose(shape, 65.0f));
    for (GarmentKind kind : {GarmentKind::TShirt, GarmentKind::LongSleeve, GarmentKind::Dress}) {
      for (int target : {1000, 2000, 8000, 32000}) {
        GarmentTemplateParams p;
        p.kind = kind;
        p.target_particles = target;
        GarmentMesh mesh;
        std::string err;
        ASSERT_TRUE(makeGarmentTemplate(model, p, mesh, err)) << err;
        std::vector<std::vector<uint32_t>> neighbours(mesh.positions.size());
        for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
          for (size_t k = 0; k < 3; ++k) {
            const uint32_t a = mesh.indices[t + k], b = mesh.indices[t + (k + 1) % 3];
            neighbours[a].push_back(b);
            neighbours[b].push_back(a);
          }
        }
        size_t most = 0;
        for (std::vector<uint32_t>& n : neighbours) {
          std::sort(n.begin(), n.end());
          most = std::max(most, static_cast<size_t>(std::unique(n.begin(), n.end()) - n.begin()));
        }
        EXPECT_LE(most, target > 8000 ? 12u : 10u)
            << garmentKindName(kind) << ", " << target << " particles requested, body " << height << " m "
            << weight << " kg";
      }
    }
  }
}

// A top's hem goes as much lower as the person's hip joints sit lower below the pelvis than on the
// shape's standard proportions, past 1 cm (a mocap skeleton's hips sit ~10 cm below its root: the
// CMU takes, where a top cut for the skeleton ended at the belly), and no lower for hips that sit
// as the standard's or higher (a Kinect's): docs/garments.md, "Tops on a mocap pelvis".
TEST(GarmentTemplateMesh, TopsReachAsFarDownAsTheHipJoints) {
  const ResolvedShape shape = Body::resolve(1.70f, 65.0f);
  const SkeletonPose standard = restPose(shape, 65.0f);
  auto hemBelowPelvis = [&](float hips_down, GarmentKind kind) {
    SkeletonPose p = standard;
    for (Joint j : {Joint::HipL, Joint::KneeL, Joint::AnkleL, Joint::FootL, Joint::HipR, Joint::KneeR,
                    Joint::AnkleR, Joint::FootR})
      p.position[static_cast<size_t>(idx(j))].y() -= hips_down;
    BodyModel model(shape, BodyModelParams{});
    model.update(p);
    GarmentTemplateParams tp;
    tp.kind = kind;
    tp.target_particles = 1000;
    GarmentMesh mesh;
    std::string err;
    EXPECT_TRUE(makeGarmentTemplate(model, tp, mesh, err)) << err;
    float lowest = std::numeric_limits<float>::infinity();
    for (const Vec3& x : mesh.positions) lowest = std::min(lowest, x.y());
    return p.position[static_cast<size_t>(idx(Joint::Pelvis))].y() - lowest;
  };
  for (GarmentKind kind : {GarmentKind::TShirt, GarmentKind::LongSleeve}) {
    const float base = hemBelowPelvis(0.0f, kind);
    const float higher = hemBelowPelvis(-0.02f, kind), slight = hemBelowPelvis(0.008f, kind);
    const float mocap = hemBelowPelvis(0.08f, kind);
    std::printf("[ figures  ] %s: hem %.4f m below the pelvis; hips 2 cm higher %.4f, 0.8 cm lower %.4f, 8 cm lower %.4f\n",
                garmentKindName(kind), base, higher, slight, mocap);
    EXPECT_NEAR(higher, base, 0.005f) << garmentKindName(kind);
    EXPECT_NEAR(slight, base, 0.005f) << garmentKindName(kind);
    EXPECT_NEAR(mocap - base, 0.08f, 0.015f) << garmentKindName(kind);
  }
}

// The same template fits both bodies: the heavy body's T-shirt is wider at the chest.
TEST(GarmentTemplateInput, SizedToTheBody) {
  GarmentTemplateParams p;
  GarmentMesh thin, heavy;
  std::string err;
  ASSERT_TRUE(makeGarmentTemplate(thinBody().model, p, thin, err)) << err;
  ASSERT_TRUE(makeGarmentTemplate(heavyBody().model, p, heavy, err)) << err;
  auto width = [](const GarmentMesh& m) {
    float lo = 1e9f, hi = -1e9f;
    for (const Vec3& x : m.positions) {
      lo = std::min(lo, x.z());
      hi = std::max(hi, x.z());
    }
    return hi - lo;  // front-back depth (the body faces -Z)
  };
  EXPECT_GT(width(heavy), width(thin) + 0.03f);
}

}  // namespace
}  // namespace drape
