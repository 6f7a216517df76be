// Procedural garment templates (garment_templates.h). Method: docs/cloth-solver.md,
// "Garment templates". Topology follows body/body_topology.cpp: tubes of equal rings stitched
// quad by quad, the shoulder yoke as front and back strips from the armpit ring to the neck-base
// ring, each armhole loop zipped to its sleeve's first ring, and for trousers the hip ring split
// in two halves closed by a crotch bridge. Ring point j sits at angle 2 pi j / K from the frame's
// x (forward) towards its z; for rings L -> U along a chain, (L_j, U_j, L_j+1) faces outwards.
#include "cloth/garment_templates.h"

#include "body/body_shape.h"
#include "body/loop_stitch.h"
#include "proxies/collision.h"
#include "proxies/proxy_builder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <map>

namespace drape {

namespace {

// The long-sleeve's sleeve is cut this much looser than the ease at the armhole, tapering to the
// plain ease at the cuff: cut to the ease alone, the sleeve root was stretched wherever the arm
// moved from the pose it was cut in (P99 stretch 13-21 % over the shared takes), and 2 cm there
// lowered it by 11-32 % on all eight with fewer or as many frames off. The T-shirt and the dress
// were tried with it and left as they are (docs/garments.md, "A looser long sleeve").
constexpr float kLongSleeveRootEaseM = 0.02f;
// Where the long-sleeve's cuff sits, as an arm station (elbow 1, wrist 2): a quarter of the forearm
// above the wrist. At 1.9 (a tenth) the cuff, cut to the body's ease and so about as wide as the
// hand, rode onto the hand whenever the arm hung or swung and stretched there; on a mocap
// skeleton's stub hand (CMU: the hand joint 3.5 cm past the wrist) its loop then crossed the hand
// and the sleeve counted off. Over 56 runs (eight takes, seven resolutions) the frames with an opening off fell
// from 1 022 to 507 and the P99 stretch by 4 % (docs/garments.md, "The long sleeve's cuff").
constexpr float kLongSleeveCuffU = 1.75f;
// The long-sleeve's ease at the cuff, as a fraction of the garment's ease (the sleeve tapers to it
// linearly from the root's): 0.6 of the default 2.5 cm is 1.5 cm. Cut to the full ease, on the CMU
// hop takes at 1 500 particles (16 cuff particles, 4-5 cm apart) the stub hand crossed the cuff's
// rim between two particles and the sleeve counted off until the linking came back (42 of 100
// measured frames on 131_03); a cuff of 32 particles did not stop it, a closer one did. Over 56
// runs (eight takes, seven resolutions) the frames with an opening off fell from 507 to 268; the
// price is a closer forearm that stretches more (P99 stretch 1.17 times; in the run looked at,
// the added edge-frames above it lie on the forearm and cuff): docs/garments.md, "A closer cuff".
constexpr float kLongSleeveCuffEaseScale = 0.6f;
// The long-sleeve's rings along the sleeve at most a tenth of the cuff's perimeter apart (about
// 2.9 cm on the default body), however coarse the rest of the garment, as long as a sleeve then
// takes at most kBentSleeveMostShare of the particles asked for. Why: where the elbow bends, the
// forearm's rounded end pushes at the sleeve between two rings; rings 4.6 cm apart (a 500-particle
// long sleeve) let it through the sleeve's wall and the sleeve stayed down on the hip while the
// arm rose, off in 423 of the quality matrix's 664 measured frames at 500 particles and 235 at 600
// (14 at 800, where rings were 3.3 cm apart); with this bound 18 and 4 (docs/cloth-solver.md,
// "Coarse garments come off"). A larger share (0.3) kept the 400-particle sleeve on too, but the
// 200-particle garment then landed 11.5 % under its count (the torso has a least size). At 2 000
// particles and up the rings are closer than the bound; it still moves the h search's first
// builds there, so those meshes differ a little (64 runs at 1 000-2 400: docs/cloth-solver.md).
constexpr float kBentSleeveRingsPerCuffPerimeter = 10.0f;
constexpr float kBentSleeveMostShare = 0.25f;
// Below 1 000 particles the rows along the tubes may come as close as 0.6 of the spacing round
// (0.8 from 1 000 up): there a step of h changes the count by a whole ring on every row, and within
// [0.8, 1] the count could not reach the target, so a 255-particle skirt came out with 208, a
// 310-particle pair of trousers with 251 (0.81 of the target, against the 10 % drape.h promises);
// with 0.6, 0.94-1.04 over 200-800 in steps of 7 for every kind on the default body. Over the
// quality matrix at 200-800 the two runs whose mesh changed (skirt 250: 208 -> 256 particles,
// trousers 300: 267 -> 299) moved no figure out of its spread (docs/cloth-solver.md, "Resolution").
constexpr float kLeastAlongBelow1000 = 0.6f;

struct Sec {
  Vec3 c = Vec3::Zero();
  Mat3 f = Mat3::Identity();
  float a = 0.0f, b = 0.0f;  // semi-axes along the frame's x and z (ease included)
};

Mat3 orthoFrame(const Vec3& x0, const Vec3& y0) {
  const Vec3 y = y0.normalized();
  Vec3 x = x0 - x0.dot(y) * y;
  x = x.norm() > 1e-6f ? Vec3(x.normalized()) : anyPerpendicular(y);
  Mat3 m;
  m.col(0) = x;
  m.col(1) = y;
  m.col(2) = x.cross(y);
  return m;
}

Sec lerpSec(const Sec& s0, const Sec& s1, float t) {
  Sec s;
  s.c = (1.0f - t) * s0.c + t * s1.c;
  s.f = orthoFrame((1.0f - t) * s0.f.col(0) + t * s1.f.col(0), (1.0f - t) * s0.f.col(1) + t * s1.f.col(1));
  s.a = (1.0f - t) * s0.a + t * s1.a;
  s.b = (1.0f - t) * s0.b + t * s1.b;
  return s;
}

Sec ringSec(const RingPose& r, float ease) {
  Sec s;
  s.c = r.centre;
  s.f = r.frame;
  s.a = r.forward_m + ease;
  s.b = r.side_m + ease;
  return s;
}

// How far the legs' first rings (the hip joints) sit below the hip ring (the pelvis), along its
// axis, averaged over the two legs.
float legRootDrop(const BodyModel& body) {
  const RingPose& hip = body.rings()[static_cast<size_t>(body.chainFirstRing(Chain::Torso))];
  float d = 0.0f;
  for (Chain leg : {Chain::LegL, Chain::LegR})
    d += (hip.centre - body.rings()[static_cast<size_t>(body.chainFirstRing(leg))].centre).dot(hip.frame.col(1));
  return 0.5f * d;
}

// How much lower than on the shape's standard proportions this body's hip joints sit below its
// pelvis, when that is more than 1 cm (else 0: a Kinect's hips sit level with its SpineBase or up
// to 1 cm above it, 2-3 cm higher than the standard's 1.7 cm below): a mocap skeleton's sit ~10 cm
// below its root (the CMU takes, 9.6 cm), and a top cut for that skeleton with its hem at the
// standard drop below the pelvis ring ends at the belly. Measured on the rest body the garment is
// cut on (docs/garments.md, "Tops on a mocap pelvis").
float extraHipDrop(const BodyModel& body) {
  BodyModelParams bp;
  bp.ring_points = body.ringPoints();
  BodyModel standard(body.shape(), bp);
  standard.updateRings(restPose(body.shape()));
  const float extra = legRootDrop(body) - legRootDrop(standard);
  return extra > 0.01f ? extra : 0.0f;
}

// The section of a chain at station parameter u (clamped to the chain's rings), ease added.
Sec chainSec(const BodyModel& body, Chain c, float u, float ease) {
  const int first = body.chainFirstRing(c), n = body.chainRingCount(c);
  const auto& st = body.stations();
  const auto& rings = body.rings();
  if (u <= st[first].u) return ringSec(rings[first], ease);
  for (int i = 0; i + 1 < n; ++i) {
    const float u0 = st[first + i].u, u1 = st[first + i + 1].u;
    if (u >= u0 && u <= u1 && u1 > u0) {
      return lerpSec(ringSec(rings[first + i], ease), ringSec(rings[first + i + 1], ease), (u - u0) / (u1 - u0));
    }
  }
  return ringSec(rings[first + n - 1], ease);
}

// The chain's ring whose station u is nearest `u`.
int nearestRing(const BodyModel& body, Chain c, float u) {
  const int first = body.chainFirstRing(c), n = body.chainRingCount(c);
  int best = first;
  for (int i = 0; i < n; ++i) {
    if (std::fabs(body.stations()[first + i].u - u) < std::fabs(body.stations()[best].u - u)) best = first + i;
  }
  return best;
}

Vec3 secPoint(const Sec& s, int j, int K) {
  const float th = 2.0f * kPi * static_cast<float>(j) / static_cast<float>(K);
  return s.c + std::cos(th) * s.a * s.f.col(0) + std::sin(th) * s.b * s.f.col(2);
}

float secPerimeter(const Sec& s) {  // Ramanujan
  const float a = s.a, b = s.b;
  return kPi * (3.0f * (a + b) - std::sqrt((3.0f * a + b) * (a + 3.0f * b)));
}

int roundTo(float v, int multiple, int minimum) {
  const int k = static_cast<int>(std::lround(v / static_cast<float>(multiple))) * multiple;
  return std::max(minimum, k);
}

// The arc length of a path s in [0, 1] from its start to s = i / fine, i in [0, fine], along the
// polyline through those fine + 1 sections' centres.
std::vector<float> arcLengths(const std::function<Sec(float)>& path, int fine) {
  std::vector<float> cum(static_cast<size_t>(fine) + 1, 0.0f);
  Vec3 prev = path(0.0f).c;
  for (int i = 1; i <= fine; ++i) {
    const Vec3 c = path(static_cast<float>(i) / static_cast<float>(fine)).c;
    cum[static_cast<size_t>(i)] = cum[static_cast<size_t>(i) - 1] + (c - prev).norm();
    prev = c;
  }
  return cum;
}

// Sections along a path s in [0, 1], evenly spaced in arc length by about h (at least 2); `count`
// may replace that number (Builder::count).
std::vector<Sec> samplePath(const std::function<Sec(float)>& path, float h, const std::function<int(int)>& count) {
  constexpr int kFine = 128;
  const std::vector<float> cum = arcLengths(path, kFine);
  const float L = cum[kFine];
  const int rings = std::max(2, count(std::max(2, static_cast<int>(std::lround(L / h)) + 1)));
  std::vector<Sec> out;
  for (int r = 0; r < rings; ++r) {
    const float target = L * static_cast<float>(r) / static_cast<float>(rings - 1);
    int i = 0;
    while (i < kFine - 1 && cum[i + 1] < target) ++i;
    const float seg = cum[i + 1] - cum[i];
    const float t = seg > 0.0f ? std::clamp((target - cum[i]) / seg, 0.0f, 1.0f) : 0.0f;
    out.push_back(path((static_cast<float>(i) + t) / kFine));
  }
  return out;
}

class Builder {
  struct Inflated;  // below: an ellipsoid grown by the clearance, with its box

 public:
  Builder(const BodyModel& body, const GarmentTemplateParams& p, const std::vector<Ellipsoid>& ell,
          const std::vector<ProxySource>& src)
      : body_(body), p_(p), ell_(ell), src_(src) {
    hip_ = chainSec(body, Chain::Torso, 0.0f, p.ease_m);
    // Knee drop below the hip ring, along the hip ring's axis.
    const Sec knee = chainSec(body, Chain::LegL, 1.0f, 0.0f);
    kneeDrop_ = std::max(0.1f, (hip_.c - knee.c).dot(hip_.f.col(1)));
    hipDrop_ = extraHipDrop(body);
    buildEnclosure();
  }

  // Record (into `out`) or replay (from `in`) the build's choices; replay() is false once the
  // replayed build asked for something the layout does not have.
  void setLayout(TemplateLayout* out, const TemplateLayout* in) {
    rec_ = out;
    play_ = in;
  }
  bool replayed() const {
    return !play_ || (ok_ && nextCount_ == play_->counts.size() && nextRotation_ == play_->rotations.size());
  }

  // h: the spacing round each tube (its point count a multiple of 4 or 8); along: the spacing
  // between rings along a tube (and the yoke's rows) as a multiple of h, the resolution's fine
  // control (makeGarmentTemplate).
  void build(float h, GarmentMesh& m, float along = 1.0f) {
    along_ = along;
    m = GarmentMesh{};
    nextCount_ = nextRotation_ = 0;
    ok_ = true;
    if (rec_) {
      rec_->counts.clear();
      rec_->rotations.clear();
      rec_->h = h;
    }
    switch (p_.kind) {
      case GarmentKind::TShirt:
        upper(h, 0.05f * p_.length_scale + hipDrop_, false, Sleeve{0.5f * p_.length_scale}, m);
        break;
      case GarmentKind::LongSleeve:
        upper(h, 0.05f * p_.length_scale + hipDrop_, false,
              Sleeve{std::min(2.0f, kLongSleeveCuffU * p_.length_scale), kLongSleeveRootEaseM, kLongSleeveCuffEaseScale,
                     true},
              m);
        break;
      case GarmentKind::Dress:
        upper(h, 0.9f * kneeDrop_ * p_.length_scale, true, Sleeve{0.35f * p_.length_scale}, m);
        break;
      case GarmentKind::Skirt: skirt(h, m); break;
      case GarmentKind::Trousers: trousers(h, m); break;
    }
  }

  // Moves every particle outside every ellipsoid inflated by `clear`, along the ellipsoid's
  // normal (Newton steps on the implicit), which keeps neighbours apart (a radial projection
  // from the centre would squeeze them together); a particle trapped where two ellipsoids overlap
  // (the crotch between the thighs) slides down the hip axis until outside all of them.
  //
  // Except where an arm meets the torso: a particle that the pushes send out of an arm's
  // ellipsoid and out of another takes the nearest way out of all of them, not upwards, instead
  // (nearestExit). Pushed out of each in turn, it went back and forth across the crease between
  // the two and walked down it to the crease's lowest point, where every such particle ended
  // together: on the pose garments are cut on (arms 65 degrees down) the strip of the sleeve's
  // underside that is built inside the torso piled up at one point under each arm,
  // weldShortEdges merged the pile, and the T-shirt had an underarm vertex of 12 neighbours
  // (1 802 particles; 36 at 32 168) with edges of 7 to 115 mm (docs/garments.md, "The underarm
  // fan").
  void pushOut(GarmentMesh& m, float clear) const {
    const std::vector<Inflated> inflated = inflate(clear);
    for (Vec3& x : m.positions) {
      const Vec3 start = x;
      if (pushOutAlongNormals(inflated, x)) {
        x = start;
        nearestExit(inflated, x);
      }
    }
  }

  void finishPins(GarmentMesh& m) const { pinOffsetsFromPositions(body_, m); }

 private:
  // Whether the pushes moved x out of an arm's ellipsoid and out of another ellipsoid.
  bool pushOutAlongNormals(const std::vector<Inflated>& inflated, Vec3& x) const {
    bool outOfArm = false, outOfOther = false;
    for (int pass = 0; pass < 16; ++pass) {
      bool moved = false;
      for (size_t k = 0; k < inflated.size(); ++k) {
        if (!inflated[k].mayContain(x)) continue;  // outside the box: f >= 0 below, nothing to do
        if (!projectOut(inflated[k].e, x)) continue;
        moved = true;
        (isArm(k) ? outOfArm : outOfOther) = true;
      }
      if (!moved) break;
    }
    const Vec3 down = -hip_.f.col(1);
    for (int step = 0; step < 100 && insideAny(inflated, x); ++step) x += 0.002f * down;
    return outOfArm && outOfOther;
  }
  // Newton steps on the implicit of one ellipsoid, to just outside it; whether x moved.
  static bool projectOut(const Ellipsoid& e, Vec3& x) {
    bool moved = false;
    for (int it = 0; it < 20; ++it) {
      const Vec3 q = e.toUnit(x);
      const float f = q.squaredNorm() - 1.001f;
      if (f >= 0.0f) break;
      const Vec3 g = 2.0f * (e.to_unit.transpose() * q);
      const float g2 = g.squaredNorm();
      if (g2 < 1e-12f) {
        x += e.rotation.col(0) * 1e-3f;
        continue;
      }
      x -= (f - 1e-4f) / g2 * g;
      moved = true;
    }
    return moved;
  }
  bool isArm(size_t k) const {
    return k < src_.size() && (src_[k].chain == Chain::ArmL || src_[k].chain == Chain::ArmR);
  }
  // The nearest way out of every ellipsoid that does not go upwards: the shortest of the rays of
  // kExitDirections spread over the sphere (a Fibonacci lattice) that point level or down, each
  // followed in kExitStep steps to where it first leaves them all, then bisected to below 0.1 mm.
  // Not upwards: cloth caught between arm and torso hangs below the armpit, and the body mesh
  // fills the armpit's crease, which the ellipsoids leave open. With rays in every direction the
  // pooled body penetration on Ges01 (drape-bench) rose from 5.07 to 6.11 mm; with these it stays
  // 5.07 (docs/garments.md, "The underarm fan"). Particles next to each other mostly leave the
  // same way; where two leave on opposite sides of the arm the edge between them is long (the
  // fan's edges were as long, and all met at one vertex).
  void nearestExit(const std::vector<Inflated>& inflated, Vec3& x) const {
    const Vec3 up = hip_.f.col(1);
    Vec3 best = x;
    float bestT = kMaxExit;
    for (int k = 0; k < kExitDirections; ++k) {
      const float z = 1.0f - 2.0f * (static_cast<float>(k) + 0.5f) / static_cast<float>(kExitDirections);
      const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
      const float phi = static_cast<float>(k) * 2.39996323f;  // the golden angle
      const Vec3 d(r * std::cos(phi), r * std::sin(phi), z);
      if (d.dot(up) > 0.0f) continue;  // not upwards, into the armpit
      float inT = 0.0f, t = kExitStep;
      while (t < bestT && insideAny(inflated, x + t * d)) {
        inT = t;
        t += kExitStep;
      }
      if (t >= bestT) continue;
      for (int it = 0; it < 6; ++it) {  // 5 mm / 2^6 < 0.1 mm
        const float mid = 0.5f * (inT + t);
        if (insideAny(inflated, x + mid * d)) inT = mid;
        else t = mid;
      }
      bestT = t;
      best = x + t * d;
    }
    if (bestT < kMaxExit) {
      x = best;
      return;
    }
    pushOutAlongNormals(inflated, x);  // deeper than kMaxExit: the pushes after all
  }
  static constexpr int kExitDirections = 96;
  static constexpr float kExitStep = 0.005f, kMaxExit = 0.15f;

  TemplateLayout* rec_ = nullptr;
  const TemplateLayout* play_ = nullptr;
  size_t nextCount_ = 0, nextRotation_ = 0;
  bool ok_ = true;
  // Every count the build derives from the body goes through here: recorded, or replayed.
  int count(int computed) {
    if (play_) {
      if (nextCount_ >= play_->counts.size() || play_->counts[nextCount_] < 1) {
        ok_ = false;
        return computed;
      }
      return play_->counts[nextCount_++];
    }
    if (rec_) rec_->counts.push_back(computed);
    return computed;
  }
  std::function<int(int)> counter() {
    return [this](int v) { return count(v); };
  }
  void stitch(const Loop& L, const Loop& U, GarmentMesh& m) {
    int rotation = -1;
    if (play_) {
      if (nextRotation_ < play_->rotations.size()) rotation = play_->rotations[nextRotation_++];
      else ok_ = false;
    }
    stitchLoops(L, U, m.positions, m.indices, &rotation);
    if (rec_) rec_->rotations.push_back(rotation);
  }

  // An ellipsoid inflated by the clearance (refresh() gives its to_unit and bounds), computed once
  // per call: per particle and pass they were most of a template's build time. The box is the
  // bounds scaled by 1.01 about the centre: outside it |q|^2 > 1.0201, so the Newton loop (which
  // acts below 1.001) and insideAny have nothing to do there, whatever the rounding.
  struct Inflated {
    Ellipsoid e;
    Vec3 box_min, box_max;
    bool mayContain(const Vec3& x) const {
      return (x.array() >= box_min.array()).all() && (x.array() <= box_max.array()).all();
    }
  };
  std::vector<Inflated> inflate(float clear) const {
    std::vector<Inflated> out(ell_.size());
    for (size_t k = 0; k < ell_.size(); ++k) {
      Inflated& f = out[k];
      f.e = ell_[k];
      f.e.radii += Vec3::Constant(clear);
      f.e.refresh();
      const Vec3 half = 1.01f * (f.e.bounds_max - f.e.centre);
      f.box_min = f.e.centre - half;
      f.box_max = f.e.centre + half;
    }
    return out;
  }
  static bool insideAny(const std::vector<Inflated>& inflated, const Vec3& x) {
    for (const Inflated& f : inflated)
      if (f.mayContain(x) && f.e.toUnit(x).squaredNorm() < 1.0f) return true;
    return false;
  }

  uint32_t add(GarmentMesh& m, const Vec3& x) {
    m.positions.push_back(x);
    return static_cast<uint32_t>(m.positions.size() - 1);
  }
  Loop addRing(GarmentMesh& m, const Sec& s, int K) {
    Loop l(static_cast<size_t>(K));
    for (int j = 0; j < K; ++j) l[static_cast<size_t>(j)] = add(m, secPoint(s, j, K));
    return l;
  }
  // A tube through the sections (in chain order); returns its rings.
  std::vector<Loop> tube(GarmentMesh& m, const std::vector<Sec>& secs, int K) {
    std::vector<Loop> rings;
    for (const Sec& s : secs) {
      rings.push_back(addRing(m, s, K));
      if (rings.size() > 1) {
        stitchEqual(rings[rings.size() - 2].data(), rings.back().data(), K, true, m.indices);
      }
    }
    return rings;
  }
  void pinLoop(GarmentMesh& m, const Loop& l, int ring) {
    for (uint32_t v : l) {
      m.pinned.push_back(v);
      m.pin_ring.push_back(ring);
    }
  }

  // Required scale of the hip section (ease included) at drop d so that it encloses the legs
  // and torso ellipsoids (grown by the ease) in a band around d; A-line flare and running max.
  void buildEnclosure() {
    constexpr float kStep = 0.01f, kBand = 0.03f;
    const int n = static_cast<int>(std::ceil(1.6f * kneeDrop_ / kStep)) + 2;
    std::vector<float> need(static_cast<size_t>(n), 1.0f);
    const Vec3 X = hip_.f.col(0), Y = hip_.f.col(1), Z = hip_.f.col(2);
    for (size_t k = 0; k < ell_.size(); ++k) {
      // Only what a skirt must hang around: torso and legs (not the hands beside the hips).
      const Chain c = k < src_.size() ? src_[k].chain : Chain::Torso;
      if (c != Chain::Torso && c != Chain::LegL && c != Chain::LegR) continue;
      const Ellipsoid& e = ell_[k];
      const Vec3 r = e.radii + Vec3::Constant(p_.ease_m);
      for (int a = 0; a <= 12; ++a) {
        const float phi = kPi * static_cast<float>(a) / 12.0f;
        for (int b = 0; b < 24; ++b) {
          const float th = 2.0f * kPi * static_cast<float>(b) / 24.0f;
          const Vec3 q(std::sin(phi) * std::cos(th), std::cos(phi), std::sin(phi) * std::sin(th));
          const Vec3 x = e.centre + e.rotation * r.cwiseProduct(q) - hip_.c;
          const float drop = -x.dot(Y);
          if (drop < -kBand) continue;
          const float s = std::sqrt(sq(x.dot(X) / hip_.a) + sq(x.dot(Z) / hip_.b));
          const int lo = std::max(0, static_cast<int>(std::floor((drop - kBand) / kStep)));
          const int hi = std::min(n - 1, static_cast<int>(std::ceil((drop + kBand) / kStep)));
          for (int i = lo; i <= hi; ++i) need[static_cast<size_t>(i)] = std::max(need[static_cast<size_t>(i)], s);
        }
      }
    }
    scale_.assign(static_cast<size_t>(n), 1.0f);
    float run = 1.0f;
    for (int i = 0; i < n; ++i) {
      run = std::max(run, need[static_cast<size_t>(i)]);
      scale_[static_cast<size_t>(i)] = run;
    }
  }
  static float sq(float v) { return v * v; }

  // Hip section moved down by `drop` (>= 0); A-line (enclosing, flared) when `aline`.
  Sec below(float drop, bool aline) const {
    Sec s = hip_;
    s.c = hip_.c - drop * hip_.f.col(1);
    if (aline) {
      const float fi = drop / 0.01f;
      const int i = std::clamp(static_cast<int>(fi), 0, static_cast<int>(scale_.size()) - 1);
      const float k = scale_[static_cast<size_t>(i)] * (1.0f + 0.25f * drop);
      s.a *= k;
      s.b *= k;
    }
    return s;
  }

  // An upper garment's sleeve: to arm station `u`, `root_ease_m` looser than the ease at the
  // armhole and `cuff_ease_scale` times the ease at the cuff, linearly in between.
  struct Sleeve {
    float u;
    float root_ease_m = 0.0f;
    float cuff_ease_scale = 1.0f;
    bool past_elbow = false;  // rings along it bounded by the cuff (kBentSleeveRingsPerCuffPerimeter)
  };

  // The spacing between a sleeve's rings along the arm: the garment's (h * along_), and for a
  // sleeve past the elbow at most its cuff's perimeter / kBentSleeveRingsPerCuffPerimeter, unless
  // that would give the sleeve more than kBentSleeveMostShare of the target's particles (K per ring),
  // where it is as close as that share allows.
  float sleeveSpacing(float h, const std::function<Sec(float)>& path, int K, const Sleeve& sl) const {
    const float plain = h * along_;
    if (!sl.past_elbow) return plain;
    const float bound = secPerimeter(path(1.0f)) / kBentSleeveRingsPerCuffPerimeter;
    if (plain <= bound) return plain;
    const float rings = kBentSleeveMostShare * static_cast<float>(p_.target_particles) / static_cast<float>(K);
    if (rings < 2.0f) return plain;
    const float length = arcLengths(path, 64).back();
    return std::min(plain, std::max(bound, length / (rings - 1.0f)));
  }

  // Torso tube (hem below the hip -> armpit ring T), yoke strips to the neck base ring N, and
  // the sleeves. Pins: collar ring, shoulder-seam tops (and waist for dresses).
  void upper(float h, float hemDrop, bool aline, const Sleeve& sl, GarmentMesh& m) {
    const float e = p_.ease_m;
    const int torsoN = body_.chainRingCount(Chain::Torso);
    const int ringT = body_.chainFirstRing(Chain::Torso) + torsoN - 1;
    const float uTop = body_.stations()[static_cast<size_t>(ringT)].u;
    const Sec T = chainSec(body_, Chain::Torso, uTop, e);
    const int ringN = body_.chainFirstRing(Chain::Head);
    const Sec N = ringSec(body_.rings()[static_cast<size_t>(ringN)], e);
    const int K = count(roundTo(secPerimeter(T) / h, 8, 16));
    // v in [0, 1]: first the part below the hip (by length), then the torso by station u.
    const float below_len = hemDrop, above_len = (T.c - hip_.c).norm();
    const float split = below_len / (below_len + above_len);
    auto path = [&](float v) {
      if (v < split) return below(hemDrop * (1.0f - v / split), aline);
      return chainSec(body_, Chain::Torso, uTop * (v - split) / (1.0f - split), e);
    };
    const std::vector<Loop> torso = tube(m, samplePath(path, h * along_, counter()), K);
    const Loop& Tl = torso.back();
    // Yoke rows between T and N (front and back arcs only).
    const int hq = K / 8;
    const float yokeLen = (N.c - T.c).norm() + 0.5f * (T.a - N.a);
    const int R = count(std::max(1, static_cast<int>(std::lround(yokeLen / (h * along_)))));
    auto wrap = [K](int j) { return ((j % K) + K) % K; };
    std::vector<std::vector<uint32_t>> rows(static_cast<size_t>(R + 1), std::vector<uint32_t>(static_cast<size_t>(K), UINT32_MAX));
    for (int j = 0; j < K; ++j) rows[0][static_cast<size_t>(j)] = Tl[static_cast<size_t>(j)];
    const Loop Nl = addRing(m, N, K);
    for (int j = 0; j < K; ++j) rows[static_cast<size_t>(R)][static_cast<size_t>(j)] = Nl[static_cast<size_t>(j)];
    auto inArc = [&](int j) {
      const int a = wrap(j);
      return a <= hq || a >= K - hq || std::abs(a - K / 2) <= hq;
    };
    for (int r = 1; r < R; ++r) {
      const float t = static_cast<float>(r) / static_cast<float>(R);
      for (int j = 0; j < K; ++j) {
        if (!inArc(j)) continue;
        const Vec3 pT = m.positions[Tl[static_cast<size_t>(j)]], pN = m.positions[Nl[static_cast<size_t>(j)]];
        // Lerp, bulged outward a little (a shoulder is convex).
        const Vec3 mid = (1.0f - t) * pT + t * pN;
        const Sec s = lerpSec(T, N, t);
        Vec3 out = mid - s.c;
        out -= out.dot(s.f.col(1)) * s.f.col(1);
        const float bulge = 0.15f * (T.a - N.a) * std::sin(kPi * t);
        rows[static_cast<size_t>(r)][static_cast<size_t>(j)] =
            add(m, mid + (out.norm() > 1e-6f ? Vec3(out.normalized() * bulge) : Vec3::Zero()));
      }
    }
    auto arcOf = [&](int r, int from, int to) {
      Loop a;
      for (int j = from;; ++j) {
        a.push_back(rows[static_cast<size_t>(r)][static_cast<size_t>(wrap(j))]);
        if (wrap(j - to) == 0) break;
      }
      return a;
    };
    for (int r = 0; r < R; ++r) {
      const Loop f0 = arcOf(r, -hq, hq), f1 = arcOf(r + 1, -hq, hq);
      stitchEqual(f0.data(), f1.data(), static_cast<int>(f0.size()), false, m.indices);
      const Loop b0 = arcOf(r, K / 2 - hq, K / 2 + hq), b1 = arcOf(r + 1, K / 2 - hq, K / 2 + hq);
      stitchEqual(b0.data(), b1.data(), static_cast<int>(b0.size()), false, m.indices);
    }
    pinLoop(m, Nl, ringN);
    // Sleeves.
    for (bool left : {false, true}) {
      const int from = left ? K / 2 + hq : hq, to = left ? K - hq : K / 2 - hq;
      Loop loop = arcOf(0, from, to);
      for (int r = 1; r < R; ++r) loop.push_back(rows[static_cast<size_t>(r)][static_cast<size_t>(wrap(to))]);
      const Loop up = arcOf(R, from, to);
      loop.insert(loop.end(), up.rbegin(), up.rend());
      for (int r = R - 1; r >= 1; --r) loop.push_back(rows[static_cast<size_t>(r)][static_cast<size_t>(wrap(from))]);
      const Chain arm = left ? Chain::ArmL : Chain::ArmR;
      // Ring points from the perimeter at the plain ease: counted at the looser cut (root_ease_m), the
      // long-sleeve's stretch went up again (matrix gm 1.094: docs/garments.md, "A looser long sleeve").
      const Sec s0 = chainSec(body_, arm, 0.0f, e);
      const int Ka = count(roundTo(secPerimeter(s0) / h, 4, 8));
      // The cuff's term is exactly 0 at a scale of 1 (T-shirt, dress): their cut as before, to the bit.
      auto apath = [&](float v) {
        return chainSec(body_, arm, v * sl.u, e + sl.root_ease_m * (1.0f - v) + (sl.cuff_ease_scale - 1.0f) * e * v);
      };
      const std::vector<Loop> sleeve = tube(m, samplePath(apath, sleeveSpacing(h, apath, Ka, sl), counter()), Ka);
      stitch(loop, sleeve.front(), m);
      // Shoulder-seam top: the sleeve's first-ring points highest along the torso's up axis.
      const Vec3 up_axis = T.f.col(1);
      std::vector<std::pair<float, uint32_t>> byHeight;
      for (uint32_t v : sleeve.front()) byHeight.push_back({-m.positions[v].dot(up_axis), v});
      std::sort(byHeight.begin(), byHeight.end());
      const int count = std::max(1, Ka / 6);
      for (int i = 0; i < count; ++i) {
        m.pinned.push_back(byHeight[static_cast<size_t>(i)].second);
        m.pin_ring.push_back(ringT);
      }
    }
    if (aline) {
      // Dress: also pin the ring nearest the waist station to the waist ring.
      const int ringW = nearestRing(body_, Chain::Torso, 0.55f);
      const Vec3 cw = body_.rings()[static_cast<size_t>(ringW)].centre;
      size_t best = 0;
      float bestD = std::numeric_limits<float>::max();
      for (size_t i = 0; i < torso.size(); ++i) {
        const float d = std::fabs((m.positions[torso[i][0]] - cw).dot(T.f.col(1)));
        if (d < bestD) {
          bestD = d;
          best = i;
        }
      }
      pinLoop(m, torso[best], ringW);
    }
  }

  void skirt(float h, GarmentMesh& m) {
    const float e = p_.ease_m;
    const float hem = kneeDrop_ * p_.length_scale;
    const float uW = body_.stations()[static_cast<size_t>(nearestRing(body_, Chain::Torso, 0.55f))].u;
    const Sec W = chainSec(body_, Chain::Torso, uW, e);
    const float above = (W.c - hip_.c).norm();
    const float split = hem / (hem + above);
    auto path = [&](float v) {
      if (v < split) return below(hem * (1.0f - v / split), true);
      return chainSec(body_, Chain::Torso, uW * (v - split) / (1.0f - split), e);
    };
    const float perim = 0.5f * (secPerimeter(W) + secPerimeter(below(hem, true)));
    const int K = count(roundTo(perim / h, 8, 16));
    const std::vector<Loop> rings = tube(m, samplePath(path, h * along_, counter()), K);
    pinLoop(m, rings.back(), nearestRing(body_, Chain::Torso, 0.55f));
  }

  void trousers(float h, GarmentMesh& m) {
    const float e = p_.ease_m;
    const int ringW = nearestRing(body_, Chain::Torso, 0.55f);
    const float uW = body_.stations()[static_cast<size_t>(ringW)].u;
    const int K = count(roundTo(secPerimeter(hip_) / h, 8, 16));
    auto tpath = [&](float v) { return chainSec(body_, Chain::Torso, uW * v, e); };
    const std::vector<Loop> torso = tube(m, samplePath(tpath, h * along_, counter()), K);
    pinLoop(m, torso.back(), ringW);
    const Loop& P = torso.front();
    // Crotch bridge from the hip ring's front centre to its back centre, sagging between the legs.
    const Vec3 front = m.positions[P[0]], back = m.positions[P[static_cast<size_t>(K / 2)]];
    const float drop = body_.stations()[static_cast<size_t>(body_.chainFirstRing(Chain::LegL))].offset_m + e;
    const int nb = count(std::max(1, static_cast<int>(std::lround((back - front).norm() / h)) - 1));
    Loop bridge;
    for (int b = 0; b < nb; ++b) {
      const float u = static_cast<float>(b + 1) / static_cast<float>(nb + 1);
      bridge.push_back(add(m, front + u * (back - front) - hip_.f.col(1) * (drop * std::sqrt(std::sin(kPi * u)))));
    }
    const float uEnd = std::min(2.0f, 2.0f * p_.length_scale);
    for (bool left : {false, true}) {
      const Chain leg = left ? Chain::LegL : Chain::LegR;
      const Sec s0 = chainSec(body_, leg, 0.0f, e);
      const int Kl = count(roundTo(secPerimeter(s0) / h, 4, 8));
      auto lpath = [&](float v) { return chainSec(body_, leg, v * uEnd, e); };
      const std::vector<Loop> tubeRings = tube(m, samplePath(lpath, h * along_, counter()), Kl);
      Loop half;
      if (!left) {
        half.assign(P.begin(), P.begin() + K / 2 + 1);
        half.insert(half.end(), bridge.rbegin(), bridge.rend());
      } else {
        half.assign(P.begin() + K / 2, P.end());
        half.push_back(P[0]);
        half.insert(half.end(), bridge.begin(), bridge.end());
      }
      std::reverse(half.begin(), half.end());
      stitch(half, tubeRings.front(), m);
    }
  }

  const BodyModel& body_;
  GarmentTemplateParams p_;
  const std::vector<Ellipsoid>& ell_;
  const std::vector<ProxySource>& src_;
  Sec hip_;
  float kneeDrop_ = 0.5f;
  float hipDrop_ = 0.0f;  // extraHipDrop: tops' hems go as much lower
  float along_ = 1.0f;    // build(): ring spacing along the tubes / h
  std::vector<float> scale_;
};

// Where two stitched loops meet (armhole zips, the crotch bridge) the stitch can leave edges far
// shorter than the mesh spacing (0.1 mm next to 2 cm ones). Such an edge has no say in the shape,
// but measured as stretch over its rest length it dominates every maximum, and its tiny mass
// stiffens the solve. Merge the ends of every edge shorter than `tol` (union-find, the lower
// index survives; a pinned end stays pinned) and drop triangles that collapse. `record` (optional)
// receives each vertex's survivor; `replay` (optional) gives them instead of `tol` (a cut for
// another body welds what the first cut welded; false when they do not fit this mesh).
bool weldShortEdges(GarmentMesh& m, float tol, std::vector<uint32_t>* record = nullptr,
                    const std::vector<uint32_t>* replay = nullptr) {
  const size_t n = m.positions.size();
  std::vector<uint32_t> parent(n);
  for (uint32_t i = 0; i < n; ++i) parent[i] = i;
  auto root = [&](uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  bool any = false;
  if (replay) {
    if (replay->size() != n) return false;
    for (uint32_t i = 0; i < n; ++i) {
      const uint32_t r = (*replay)[i];
      if (r > i || (*replay)[r] != r) return false;  // survivors are the lowest index of their group
      parent[i] = r;
      any = any || r != i;
    }
  } else {
    const float tol2 = tol * tol;
    for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
      for (size_t e = 0; e < 3; ++e) {
        const uint32_t a = m.indices[t + e], b = m.indices[t + (e + 1) % 3];
        if ((m.positions[a] - m.positions[b]).squaredNorm() >= tol2) continue;
        const uint32_t ra = root(a), rb = root(b);
        if (ra == rb) continue;
        parent[std::max(ra, rb)] = std::min(ra, rb);
        any = true;
      }
    }
    if (record) {
      record->resize(n);
      for (uint32_t i = 0; i < n; ++i) (*record)[i] = root(i);
    }
  }
  if (!any) return true;
  // Survivors that still have a triangle, renumbered in order.
  std::vector<uint32_t> tris;
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const uint32_t a = root(m.indices[t]), b = root(m.indices[t + 1]), c = root(m.indices[t + 2]);
    if (a == b || b == c || c == a) continue;
    tris.insert(tris.end(), {a, b, c});
  }
  // A weld can also fold a fan onto itself: where a limb tube's first ring passes within the
  // tolerance of the seam it is stitched to (the trousers' crotch bridge on a heavy body, whose
  // thighs meet), the two legs' triangles over one bridge segment become the same triangle wound
  // both ways, a zero-area fin on an edge of four triangles. Both copies go (the vertex only they
  // used goes with them below), which leaves the surface round them a manifold.
  {
    std::vector<std::array<uint32_t, 3>> keys(tris.size() / 3);
    std::map<std::array<uint32_t, 3>, int> seen;
    for (size_t t = 0; t < keys.size(); ++t) {
      keys[t] = {tris[3 * t], tris[3 * t + 1], tris[3 * t + 2]};
      std::sort(keys[t].begin(), keys[t].end());
      ++seen[keys[t]];
    }
    size_t kept = 0;
    for (size_t t = 0; t < keys.size(); ++t) {
      if (seen[keys[t]] > 1) continue;
      for (size_t j = 0; j < 3; ++j) tris[kept + j] = tris[3 * t + j];
      kept += 3;
    }
    tris.resize(kept);
  }
  std::vector<uint32_t> remap(n, UINT32_MAX);
  GarmentMesh out;
  for (uint32_t v : tris) {
    if (remap[v] != UINT32_MAX) continue;
    remap[v] = 0;  // mark used
  }
  for (uint32_t i = 0; i < n; ++i) {
    if (remap[i] == UINT32_MAX) continue;
    remap[i] = static_cast<uint32_t>(out.positions.size());
    out.positions.push_back(m.positions[i]);
  }
  for (uint32_t v : tris) out.indices.push_back(remap[v]);
  std::vector<char> pinned(out.positions.size(), 0);
  for (size_t k = 0; k < m.pinned.size(); ++k) {
    const uint32_t r = root(m.pinned[k]);
    if (remap[r] == UINT32_MAX || pinned[remap[r]]) continue;
    pinned[remap[r]] = 1;
    out.pinned.push_back(remap[r]);
    out.pin_ring.push_back(m.pin_ring[k]);
  }
  m = std::move(out);
  return true;
}

// A template made again with a recorded layout keeps its triangles, so a seam vertex that lands on
// a neighbour on the new body cannot be welded as the first build would: such an edge (20 um on
// Ges01's calibrated skeleton) would be a needle-stiff constraint and a stretch ratio of thousands.
// Its ends are moved apart, along the edge, to `min_len` (a few passes: moving one edge can shorten
// another; those left are rarer still).
void separateShortEdges(GarmentMesh& m, float min_len) {
  for (int pass = 0; pass < 4; ++pass) {
    bool moved = false;
    for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
      for (size_t e = 0; e < 3; ++e) {
        Vec3& a = m.positions[m.indices[t + e]];
        Vec3& b = m.positions[m.indices[t + (e + 1) % 3]];
        const Vec3 d = b - a;
        const float len = d.norm();
        if (len >= min_len) continue;
        // Along the edge, or (coincident ends) along the triangle's third vertex's direction.
        Vec3 dir = len > 1e-7f ? Vec3(d / len) : Vec3(m.positions[m.indices[t + (e + 2) % 3]] - a);
        if (!(dir.norm() > 1e-7f)) dir = Vec3::UnitX();
        dir.normalize();
        const Vec3 mid = 0.5f * (a + b);
        a = mid - 0.5f * min_len * dir;
        b = mid + 0.5f * min_len * dir;
        moved = true;
      }
    }
    if (!moved) return;
  }
}

}  // namespace

void pinOffsetsFromPositions(const BodyModel& body, GarmentMesh& m) {
  m.pin_local.resize(m.pinned.size());
  for (size_t i = 0; i < m.pinned.size(); ++i) {
    const RingPose& r = body.rings()[static_cast<size_t>(m.pin_ring[i])];
    m.pin_local[i] = r.frame.transpose() * (m.positions[m.pinned[i]] - r.centre);
  }
}

const char* garmentKindName(GarmentKind kind) {
  switch (kind) {
    case GarmentKind::TShirt: return "t-shirt";
    case GarmentKind::LongSleeve: return "long-sleeve";
    case GarmentKind::Skirt: return "skirt";
    case GarmentKind::Dress: return "dress";
    case GarmentKind::Trousers: return "trousers";
  }
  return "unknown";
}

bool makeGarmentTemplate(const BodyModel& body, const GarmentTemplateParams& p, GarmentMesh& out,
                         std::string& err, TemplateLayout* record, const TemplateLayout* replay) {
  const int kind = static_cast<int>(p.kind);
  if (kind < 0 || kind > 4) {
    err = "garment template: unknown garment kind";
    return false;
  }
  if (p.target_particles < 200 || p.target_particles > 200000) {
    err = "garment template: target_particles must be in [200, 200000]";
    return false;
  }
  if (!std::isfinite(p.ease_m) || p.ease_m < 0.002f || p.ease_m > 0.1f) {
    err = "garment template: ease_m must be in [0.002, 0.1] m";
    return false;
  }
  if (!std::isfinite(p.length_scale) || p.length_scale < 0.5f || p.length_scale > 1.5f) {
    err = "garment template: length_scale must be in [0.5, 1.5]";
    return false;
  }
  for (Chain c : {Chain::Torso, Chain::Head, Chain::ArmL, Chain::ArmR, Chain::LegL, Chain::LegR}) {
    if (body.chainRingCount(c) < 2) {
      err = "garment template: body has too few rings";
      return false;
    }
  }
  for (const RingPose& r : body.rings()) {
    if (!r.centre.allFinite() || !r.frame.allFinite() || !(r.forward_m > 0.0f) || !(r.side_m > 0.0f)) {
      err = "garment template: body rings are not finite / not posed";
      return false;
    }
  }
  ProxyBuilder proxies(ProxyRule::Drape);
  proxies.build(body, restPose(body.shape()));
  Builder builder(body, p, proxies.ellipsoids(), proxies.sources());

  GarmentMesh mesh;
  TemplateLayout layout;
  const bool replaying = replay != nullptr && !replay->empty();
  if (replaying) {
    // The first cut's choices, on this body.
    builder.setLayout(nullptr, replay);
    builder.build(replay->h, mesh);
    builder.pushOut(mesh, EllipsoidCollider::kDefaultMargin + 0.002f);
    const bool fits = builder.replayed() && weldShortEdges(mesh, 0.0f, nullptr, &replay->weld_root) &&
                      replay->pinned.size() == replay->pin_ring.size() &&
                      std::all_of(replay->pinned.begin(), replay->pinned.end(),
                                  [&](uint32_t v) { return v < mesh.positions.size(); });
    if (!fits) {
      err = "garment template: this body does not fit the recorded layout";
      return false;
    }
    mesh.pinned = replay->pinned;
    mesh.pin_ring = replay->pin_ring;
    separateShortEdges(mesh, 0.25f * replay->h);
  } else {
    // Resolution, in two steps. The spacing round the tubes, h, goes in steps: a tube's point count
    // is a multiple of 8 (4 on limbs), and one step of the torso's adds a ring's worth of points on
    // every row (the 2 000-particle T-shirt: 1 810 or 2 094 particles, nothing between). So first
    // h, adjusted until the count is within 4 % of the target or, after 12 builds, the closest
    // count seen; then, where that is more than 1 % off, the spacing between rings along the tubes
    // (`along` x h, in [0.8, 1], or [0.6, 1] below 1 000 particles: kLeastAlongBelow1000; the count
    // falls as it grows) bisected to within 1 % (the closest seen after 10-11 builds), from below
    // the target (below). The layout is recorded only for a caller that keeps it; the last build
    // is the one recorded.
    builder.setLayout(record ? &layout : nullptr, nullptr);
    const float target = static_cast<float>(p.target_particles);
    float built_h = 0.0f, built_along = 0.0f;  // the last build's
    auto buildAt = [&](float h_try, float along_try) {
      builder.build(h_try, mesh, along_try);
      built_h = h_try, built_along = along_try;
      return std::fabs(static_cast<float>(mesh.positions.size()) - target) / target;
    };
    float h = 0.03f, best_h = h, best_off = std::numeric_limits<float>::infinity();
    size_t best_n = 0;
    for (int it = 0; it < 12; ++it) {
      const float off = buildAt(h, 1.0f);
      if (off < best_off) best_off = off, best_h = h, best_n = mesh.positions.size();
      if (off <= 0.04f) break;
      h *= std::clamp(std::sqrt(static_cast<float>(mesh.positions.size()) / target), 0.7f, 1.4f);
    }
    h = best_h;
    // Rows closer than the spacing round, never further: quads up to a fifth shorter than wide. With
    // rows up to a quarter further apart (the first version of this search) the dress on the CMU
    // takes stretched 15-18 % at the P99 where rows 5-11 % further apart than wide ended it, against
    // 11-13 % with rows at or closer than the spacing (docs/cloth-solver.md, "Resolution"). So a
    // count above the target is first taken below it by a coarser spacing round.
    if (best_off > 0.01f && static_cast<float>(best_n) > target) {
      for (int it = 0; it < 10; ++it) {
        h *= 1.02f;
        const float off = buildAt(h, 1.0f);
        if (static_cast<float>(mesh.positions.size()) <= target) {
          best_h = h, best_off = off;
          break;
        }
      }
      h = best_h;
    }
    float best_along = 1.0f;
    for (float lo = target < 1000.0f ? kLeastAlongBelow1000 : 0.8f, hi = 1.0f; best_off > 0.01f && hi - lo > 0.2f / 1024.0f;) {
      const float along = 0.5f * (lo + hi);
      const float off = buildAt(h, along);
      if (off < best_off) best_off = off, best_along = along;
      (static_cast<float>(mesh.positions.size()) > target ? lo : hi) = along;
    }
    if (built_h != h || built_along != best_along) buildAt(h, best_along);
    builder.pushOut(mesh, EllipsoidCollider::kDefaultMargin + 0.002f);
    weldShortEdges(mesh, 0.25f * h, record ? &layout.weld_root : nullptr);
    if (record) {
      layout.pinned = mesh.pinned;
      layout.pin_ring = mesh.pin_ring;
    }
  }
  builder.finishPins(mesh);
  for (const Vec3& x : mesh.positions) {
    if (!x.allFinite()) {
      err = "garment template: non-finite position";
      return false;
    }
  }
  out = std::move(mesh);
  if (record && !replaying) *record = std::move(layout);
  return true;
}

}  // namespace drape
