#include "proxies/proxy_builder.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace drape {

namespace {

// Drape rule: an ellipsoid per ring reaching kOverlap x the ring spacing along the chain. Between
// two rings d apart, each ellipsoid's cross-section at d/2 is sqrt(1 - 1/(4 kOverlap^2)) of its
// ring (0.968 for 2); the cross-section is scaled so that half-way it still reaches 0.995 of the
// ring, just outside the body mesh's straight segment there (a K-gon's chord sits at cos(pi/K)),
// at the cost of a 2.8 % bulge at the ring itself (docs/proxies.md says why 1.5 x with a balanced
// +-2.9 % scale was not enough).
constexpr float kOverlap = 2.0f;
const float kMidFactor = std::sqrt(1.0f - 1.0f / (4.0f * kOverlap * kOverlap));
const float kSectionScale = 0.995f / kMidFactor;
// Sub-rings keep ellipsoids no further apart than this times the local radius, which bounds how
// far an ellipsoid reaches past a bend or a chain end.
constexpr float kMaxSpacingOverRadius = 1.0f;
const float kCosBend = std::cos(25.0f * kPi / 180.0f);
// Shoulder fills (ProxyBuilder::shoulderFill): the ellipsoid inscribed in the box of the stitch's
// points is scaled by this, so that it fills the hollow without bulging out of the body where the
// stitch is concave. docs/proxies.md, "Shoulder fills", has the sweep it was chosen from.
constexpr float kShoulderFillScale = 0.75f;
// Hip fills (ProxyBuilder::hipFill): the box's cross-section (forward, sideways) is scaled by this,
// its length (from the thigh ring up to the hip ring) is kept whole. Scaled 1.0 across, the fills
// bulged out of the hips of the Kinect bodies and the skirt's and dress's worst frames sank deeper
// there; 0.75 leaves the Kinect takes as they were (docs/proxies.md, "Hip fills").
constexpr float kHipFillSection = 0.75f;

float ringSpacing(const BodyModel& body, int first, int count, int i) {
  const auto& rings = body.rings();
  float h = 0.0f;
  if (i > 0) h = std::max(h, (rings[first + i].centre - rings[first + i - 1].centre).norm());
  if (i + 1 < count) h = std::max(h, (rings[first + i + 1].centre - rings[first + i].centre).norm());
  return std::max(h, 1e-3f);  // a collapsed chain still gets a finite, valid ellipsoid
}

}  // namespace

uint8_t collisionGroups(const ProxySource& source) {
  if (source.only_groups != 0) return source.only_groups;
  const auto bit = [](int chain) { return chainGroup(static_cast<Chain>(std::clamp(chain, 0, kChainCount - 1))); };
  uint8_t groups = bit(static_cast<int>(source.chain));
  if (source.also_chain >= 0) groups = static_cast<uint8_t>(groups | bit(source.also_chain));
  return groups;
}

void ProxyBuilder::planShoulderFills(const BodyModel& body) {
  const int K = body.ringPoints();
  const int neck = body.chainFirstRing(Chain::Head);
  for (int side = 0; side < 2; ++side) {
    const bool left = side == 1;
    ShoulderStitch& s = shoulders_[side];
    s.junction_ring = body.chainFirstRing(left ? Chain::ArmL : Chain::ArmR);
    std::vector<uint32_t> v(body.shoulderTriangles(left));
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    s.neck.clear();
    s.junction.clear();
    for (uint32_t i : v) {
      // Ring vertex i = ring * K + j, at angle 2 pi j / K (BodyModel::writeVertices).
      const int ring = static_cast<int>(i) / K;
      const float theta = 2.0f * kPi * static_cast<float>(static_cast<int>(i) % K) / static_cast<float>(K);
      const StitchPoint p{ring, std::cos(theta), std::sin(theta)};
      if (ring == s.junction_ring) s.junction.push_back(p);
      if (ring == neck) s.neck.push_back(p);
    }
  }
}

// The stitch between a shoulder's torso loop (the top torso ring's side arc, at the armpit, going
// up into the neck ring's side arc) and the arm's junction ring is a tent of triangles that no
// ring ellipsoid covers: the top of the shoulder, from the base of the neck out to the shoulder
// joint. Cloth lying on the ring ellipsoids sank up to 2 cm into the body mesh there, in still
// frames too (the T-shirt's yoke beside its seam pins). The fill is the ellipsoid inscribed in the
// box of the points of the neck ring's arc and of the junction ring, scaled by
// kShoulderFillScale, in a frame that follows the body (y from the arc's centroid to the
// shoulder joint, x the top torso ring's forward). The armpit half of the stitch is left out: a
// fill over the whole stitch raised the stretch (as we read it, it reaches down into the armpit,
// where cloth caught between arm and torso hangs); a frame from the points' principal axes (which
// can swap when two spreads cross) stretched the T-shirt far more (docs/proxies.md, "Shoulder
// fills").
Ellipsoid ProxyBuilder::shoulderFill(const BodyModel& body, const ShoulderStitch& s) const {
  const auto& rings = body.rings();
  const RingPose& junction = rings[static_cast<size_t>(s.junction_ring)];
  const RingPose& top = rings[static_cast<size_t>(body.chainFirstRing(Chain::Torso) +
                                                  body.chainRingCount(Chain::Torso) - 1)];
  const Vec3 c = centroid(body, s.neck);
  Vec3 y = junction.centre - c;
  y = y.norm() > 1e-6f ? Vec3(y.normalized()) : Vec3(junction.frame.col(1));
  return fillInBox(body, c, y, top.frame, s.neck, s.junction, Vec3::Constant(kShoulderFillScale));
}

Vec3 ProxyBuilder::centroid(const BodyModel& body, const std::vector<StitchPoint>& points) {
  // From the rings, not the mesh, which may not be updated this frame (capi/adaptive.h).
  const auto& rings = body.rings();
  Vec3 c = Vec3::Zero();
  for (const StitchPoint& p : points) c += ringPointAt(rings[static_cast<size_t>(p.ring)], p.c, p.s);
  return c / static_cast<float>(std::max<size_t>(points.size(), 1));
}

Ellipsoid ProxyBuilder::fillInBox(const BodyModel& body, const Vec3& c, const Vec3& y, const Mat3& frame,
                                  const std::vector<StitchPoint>& a, const std::vector<StitchPoint>& b,
                                  const Vec3& scale) {
  const auto& rings = body.rings();
  const auto point = [&](const StitchPoint& p) { return ringPointAt(rings[static_cast<size_t>(p.ring)], p.c, p.s); };
  Vec3 x = frame.col(0) - frame.col(0).dot(y) * y;
  if (x.norm() < 1e-6f) x = frame.col(2) - frame.col(2).dot(y) * y;
  x.normalize();
  Mat3 R;
  R.col(0) = x;
  R.col(1) = y;
  R.col(2) = x.cross(y);
  Vec3 lo = Vec3::Constant(std::numeric_limits<float>::infinity()), hi = -lo;
  for (const std::vector<StitchPoint>* part : {&a, &b}) {
    for (const StitchPoint& p : *part) {
      const Vec3 q = R.transpose() * (point(p) - c);
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
    }
  }
  if (!(lo.array() <= hi.array()).all()) lo = hi = Vec3::Zero();  // no points (not for a valid body)
  Ellipsoid e;
  e.centre = c + R * (0.5f * (lo + hi));
  e.rotation = R;
  e.radii = (0.5f * (hi - lo)).cwiseProduct(scale).cwiseMax(Vec3::Constant(1e-3f));
  return e;
}

std::vector<ProxyBuilder::StitchPoint> ProxyBuilder::ringStitchPoints(const BodyModel& body, int ring) {
  const int K = body.ringPoints();
  std::vector<StitchPoint> points;
  points.reserve(static_cast<size_t>(K));
  for (int j = 0; j < K; ++j) {
    const float theta = 2.0f * kPi * static_cast<float>(j) / static_cast<float>(K);
    points.push_back({ring, std::cos(theta), std::sin(theta)});
  }
  return points;
}

void ProxyBuilder::planHipFills(const BodyModel& body) {
  const std::vector<StitchPoint> hip = ringStitchPoints(body, body.chainFirstRing(Chain::Torso));
  for (int side = 0; side < 2; ++side) {
    HipStitch& s = hips_[side];
    s.thigh_ring = body.chainFirstRing(side == 1 ? Chain::LegL : Chain::LegR);
    s.thigh = ringStitchPoints(body, s.thigh_ring);
    // The hip ring's half on this thigh's side: its points whose sideways coordinate (the ring
    // frame's z, ringPointAt) has the thigh's sign. A torso ring's z is the body's right (hip to
    // hip, BodyModel::placeRings), whatever the pose.
    const float side_sign = side == 1 ? -1.0f : 1.0f;
    s.hip.clear();
    for (const StitchPoint& p : hip)
      if (p.s * side_sign > 1e-4f) s.hip.push_back(p);
  }
}

// The crotch stitch between the hip ring (the torso's first) and the thighs' first rings is, on
// each side, a band of triangles that the ring ellipsoids cover only near its ends: the thigh ring
// hangs below the hip joint by the crotch drop, and how far the hip joints sit below the pelvis
// depends on the skeleton: the stitch is 5 cm long on the Kinect takes, 16 cm on the CMU takes,
// whose hip joints are the femur heads, 9-10 cm below the pelvis joint. Cloth over the hips sank
// up to 5 cm into the body mesh there. The fill spans the band: the box of the hip ring's half on
// that side and of the thigh ring, in a frame with y from the thigh ring's centre to the half's
// centroid and x the hip ring's forward; its cross-section scaled by kHipFillSection, its length
// whole (docs/proxies.md, "Hip fills").
Ellipsoid ProxyBuilder::hipFill(const BodyModel& body, const HipStitch& s) const {
  const auto& rings = body.rings();
  const RingPose& thigh = rings[static_cast<size_t>(s.thigh_ring)];
  const RingPose& hip = rings[static_cast<size_t>(body.chainFirstRing(Chain::Torso))];
  const Vec3 c = centroid(body, s.hip);
  Vec3 y = c - thigh.centre;
  y = y.norm() > 1e-6f ? Vec3(y.normalized()) : Vec3(thigh.frame.col(1));
  return fillInBox(body, c, y, hip.frame, s.hip, s.thigh, Vec3(kHipFillSection, 1.0f, kHipFillSection));
}

void ProxyBuilder::planPelvisFill(const BodyModel& body) {
  pelvis_hip_ = ringStitchPoints(body, body.chainFirstRing(Chain::Torso));
  pelvis_thighs_ = hips_[0].thigh;  // planned first (buildAll)
  pelvis_thighs_.insert(pelvis_thighs_.end(), hips_[1].thigh.begin(), hips_[1].thigh.end());
}

// The hip stitch's front and back, and the crotch between the thighs, which the hip fills (one
// side each, 0.75 across) leave open: on the CMU takes, whose hip stitch is 16 cm long (hip
// joints 9-10 cm below the pelvis joint), the body mesh there stood up to 65 mm outside every
// ellipsoid and the T-shirt's hem sank into the lower belly. The fill is the ellipsoid inscribed
// in the box of the whole hip ring and both thigh rings, in a frame with y from the thighs'
// mid-point to the hip ring's centre and x the hip ring's forward (docs/proxies.md, "Pelvis
// fill"). It follows the thighs, as the body mesh's stitch does, so cloth meets it only while both
// legs are trusted (GarmentSim::applyLegGroups).
Ellipsoid ProxyBuilder::pelvisFill(const BodyModel& body) const {
  const auto& rings = body.rings();
  const RingPose& hip = rings[static_cast<size_t>(body.chainFirstRing(Chain::Torso))];
  const Vec3& l = rings[static_cast<size_t>(body.chainFirstRing(Chain::LegL))].centre;
  const Vec3& r = rings[static_cast<size_t>(body.chainFirstRing(Chain::LegR))].centre;
  Vec3 y = hip.centre - 0.5f * (l + r);
  y = y.norm() > 1e-6f ? Vec3(y.normalized()) : Vec3(hip.frame.col(1));
  return fillInBox(body, hip.centre, y, hip.frame, pelvis_hip_, pelvis_thighs_, Vec3::Ones());
}

void ProxyBuilder::planSubRings(const BodyModel& body) {
  // Decided once, on the rings as first built, so the ellipsoid count never changes.
  const auto& rings = body.rings();
  subRings_.assign(rings.size(), 0);
  for (int c = 0; c < kChainCount; ++c) {
    const int first = body.chainFirstRing(static_cast<Chain>(c)), n = body.chainRingCount(static_cast<Chain>(c));
    for (int i = 0; i + 1 < n; ++i) {
      const RingPose& a = rings[first + i];
      const RingPose& b = rings[first + i + 1];
      const float radius = std::min(std::min(a.forward_m, a.side_m), std::min(b.forward_m, b.side_m));
      const float d = (b.centre - a.centre).norm();
      const int subs = static_cast<int>(std::ceil(d / (kMaxSpacingOverRadius * std::max(radius, 1e-3f)))) - 1;
      subRings_[static_cast<size_t>(first + i)] = std::clamp(subs, 0, 8);
    }
  }
  size_t total = 0;
  for (int s : subRings_) total += static_cast<size_t>(s) + 1;
  scratch_.resize(total);
  scratchRing_.resize(total);
}

void ProxyBuilder::add(const Ellipsoid& e, const ProxySource& s) {
  if (count_ < ellipsoids_.size()) {
    ellipsoids_[count_] = e;
    sources_[count_] = s;
  } else {
    ellipsoids_.push_back(e);
    sources_.push_back(s);
  }
  ellipsoids_[count_].refresh();
  ++count_;
  ++built_;
}

bool ProxyBuilder::skipNext(const ProxySource& s) {
  if (!active_ || (*active_)[count_]) return false;
  sources_[count_] = s;
  ++count_;
  return true;
}

bool ProxyBuilder::anyActive(size_t first, size_t count) const {
  if (!active_) return true;
  for (size_t k = first; k < first + count; ++k)
    if ((*active_)[k]) return true;
  return false;
}

void ProxyBuilder::build(const BodyModel& body, const SkeletonPose& pose) {
  active_ = nullptr;
  buildAll(body, pose);
}

void ProxyBuilder::build(const BodyModel& body, const SkeletonPose& pose, const std::vector<uint8_t>& active) {
  // A first build sizes the arrays and records the chains' ranges: it cannot be culled.
  active_ = ellipsoids_.empty() || active.size() != ellipsoids_.size() ? nullptr : &active;
  buildAll(body, pose);
  active_ = nullptr;
}

void ProxyBuilder::buildAll(const BodyModel& body, const SkeletonPose& pose) {
  count_ = 0;
  built_ = 0;
  if (subRings_.empty()) planSubRings(body);
  if (shoulders_[0].junction.empty()) planShoulderFills(body);
  if (hips_[0].thigh.empty()) planHipFills(body);
  if (pelvis_hip_.empty()) planPelvisFill(body);
  const auto& rings = body.rings();
  const bool paper = rule_ == ProxyRule::Paper;

  for (int c = 0; c < kChainCount; ++c) {
    const Chain chain = static_cast<Chain>(c);
    const int first = body.chainFirstRing(chain), n = body.chainRingCount(chain);
    const bool limb = chain != Chain::Torso && chain != Chain::Head;
    if (paper && limb) {
      // One ellipsoid per bone (paper): centred at the bone's midpoint along it.
      for (int k = 0; k + 1 < chainJointCount(chain); ++k) {
        const Vec3& a = pose.position[idx(chainJoint(chain, k))];
        const Vec3& b = pose.position[idx(chainJoint(chain, k + 1))];
        float radius = 0.0f;
        int ringOnBone = -1;
        for (int i = 0; i < n; ++i) {
          const float u = body.stations()[first + i].u;
          if (u >= static_cast<float>(k) && u <= static_cast<float>(k + 1)) {
            radius = std::max(radius, 0.5f * (rings[first + i].forward_m + rings[first + i].side_m));
            if (ringOnBone < 0) ringOnBone = first + i;
          }
        }
        if (ringOnBone < 0) ringOnBone = first;
        if (skipNext({chain, ringOnBone, k})) continue;
        Ellipsoid e;
        e.centre = 0.5f * (a + b);
        e.rotation = rings[ringOnBone].frame;
        const Vec3 dir = b - a;
        if (dir.norm() > 1e-6f) {
          // Align the frame's y with this bone exactly (the ring may sit at the bone's end).
          const Quat q = rotationBetween(e.rotation.col(1), dir.normalized());
          e.rotation = (q.toRotationMatrix() * e.rotation).eval();
        }
        e.radii = Vec3(std::max(radius, 1e-3f), std::max(0.5f * dir.norm(), 1e-3f), std::max(radius, 1e-3f));
        add(e, {chain, ringOnBone, k});
      }
      continue;
    }
    if (paper) {
      // One ellipsoid per ring (paper eq. 5): (L_l, H, L_s), H = the larger neighbour spacing.
      for (int i = 0; i < n; ++i) {
        if (skipNext({chain, first + i, -1})) continue;
        const RingPose& r = rings[first + i];
        Ellipsoid e;
        e.centre = r.centre;
        e.rotation = r.frame;
        e.radii = Vec3(r.forward_m, ringSpacing(body, first, n, i), r.side_m);
        add(e, {chain, first + i, -1});
      }
      continue;
    }
    // Drape rule: ellipsoids at the rings and at sub-rings interpolated between them, so that no
    // two are further apart than kMaxSpacingOverRadius x the smaller radius; each reaches
    // kOverlap x its spacing along the chain (chain ends: 1 x, so they do not overshoot).
    if (active_ && !anyActive(chainFirst_[c], chainCount_[c])) {
      // Culled chain: none of its ellipsoids is wanted, so its sub-rings are not even placed.
      for (size_t k = 0; k < chainCount_[c]; ++k) ++count_;
      continue;
    }
    if (!active_) chainFirst_[c] = count_;
    int emitted = 0;
    for (int i = 0; i < n; ++i) {
      const RingPose& r = rings[first + i];
      const int subs = i + 1 < n ? subRings_[static_cast<size_t>(first + i)] : 0;
      for (int k = 0; k <= subs; ++k) {
        const float f = static_cast<float>(k) / static_cast<float>(subs + 1);
        RingPose v = r;
        if (k > 0) {
          const RingPose& r2 = rings[first + i + 1];
          v.centre = (1.0f - f) * r.centre + f * r2.centre;
          const Quat qa(r.frame), qb(r2.frame);
          v.frame = qa.slerp(f, qb).toRotationMatrix();
          v.forward_m = (1.0f - f) * r.forward_m + f * r2.forward_m;
          v.side_m = (1.0f - f) * r.side_m + f * r2.side_m;
        }
        scratchRing_[static_cast<size_t>(emitted)] = first + i;
        scratch_[static_cast<size_t>(emitted++)] = v;
      }
    }
    if (!active_) chainCount_[c] = static_cast<size_t>(emitted);
    for (int i = 0; i < emitted; ++i) {
      if (skipNext({chain, scratchRing_[static_cast<size_t>(i)], -1})) continue;
      const RingPose& v = scratch_[static_cast<size_t>(i)];
      float spacing = 0.0f;
      if (i > 0) spacing = std::max(spacing, (v.centre - scratch_[static_cast<size_t>(i - 1)].centre).norm());
      if (i + 1 < emitted) spacing = std::max(spacing, (scratch_[static_cast<size_t>(i + 1)].centre - v.centre).norm());
      spacing = std::max(spacing, 1e-3f);
      // Chain ends and bends (a neighbour more than kBendDeg off this ring's axis) reach only to
      // their neighbour: a longer reach would stick out past the end or the corner.
      bool end = i == 0 || i + 1 == emitted;
      const Vec3 axis = v.frame.col(1);
      for (int nb : {i - 1, i + 1}) {
        if (nb < 0 || nb >= emitted) continue;
        const Vec3 toNb = scratch_[static_cast<size_t>(nb)].centre - v.centre;
        const float len = toNb.norm();
        if (len > 1e-6f && std::fabs(axis.dot(toNb)) < kCosBend * len) end = true;
      }
      const float reach = end ? spacing : kOverlap * spacing;
      const float section = end ? 1.0f : kSectionScale;
      Ellipsoid e;
      e.centre = v.centre;
      e.rotation = v.frame;
      e.radii = Vec3(section * v.forward_m, reach, section * v.side_m);
      add(e, {chain, scratchRing_[static_cast<size_t>(i)], -1});
    }
  }
  if (!paper) {
    // Caps: head, fingertips and toes end in a fan to an apex vertex beyond the last ring; one
    // slim ellipsoid from that ring to the apex covers it (section 0.45 of the ring, so it does
    // not bulge out of the cone by more than a few percent of the ring radius).
    const Chain ends[5] = {Chain::Head, Chain::ArmL, Chain::ArmR, Chain::LegL, Chain::LegR};
    for (int a = 0; a < 5; ++a) {
      const int last = body.chainFirstRing(ends[a]) + body.chainRingCount(ends[a]) - 1;
      if (skipNext({ends[a], last, -1})) continue;
      const RingPose& r = rings[last];
      const Vec3 apex = body.apex(ends[a]);
      const Vec3 span = apex - r.centre;
      const float len = span.norm();
      Ellipsoid e;
      e.centre = r.centre + 0.5f * span;
      e.rotation = r.frame;
      if (len > 1e-6f) {
        const Quat q = rotationBetween(r.frame.col(1), span / len);
        e.rotation = (q.toRotationMatrix() * r.frame).eval();
      }
      e.radii = Vec3(std::max(0.45f * r.forward_m, 1e-3f), std::max(0.52f * len, 1e-3f),
                     std::max(0.45f * r.side_m, 1e-3f));
      add(e, {ends[a], last, -1});
    }
    // The pelvis fill (pelvisFill above): met by the torso cloth of the garments whose torso may
    // lie over the legs (GarmentSim::maskFor), not by other torso cloth.
    {
      ProxySource src{Chain::Torso, body.chainFirstRing(Chain::Torso), -1, -1};
      src.only_groups = kPelvisFillGroups;
      if (!skipNext(src)) add(pelvisFill(body), src);
    }
    // Shoulder fills (shoulderFill above), right then left.
    for (int side = 0; side < 2; ++side) {
      const ShoulderStitch& s = shoulders_[side];
      const ProxySource src{side == 1 ? Chain::ArmL : Chain::ArmR, s.junction_ring, -1,
                            static_cast<int>(Chain::Torso)};
      if (skipNext(src)) continue;
      add(shoulderFill(body, s), src);
    }
    // Hip fills (hipFill above), right then left. Only the cloth of their own leg, and the torso's
    // on that side (GarmentSim::maskFor), meets them: the other trouser leg would be caught
    // between the two.
    for (int side = 0; side < 2; ++side) {
      const HipStitch& s = hips_[side];
      const ProxySource src{side == 1 ? Chain::LegL : Chain::LegR, s.thigh_ring, -1, -1};
      if (skipNext(src)) continue;
      add(hipFill(body, s), src);
    }
  }
  // ellipsoids_ never shrinks (no allocation per frame); the live count is count_.
  ellipsoids_.resize(count_);
  sources_.resize(count_);
}

}  // namespace drape
