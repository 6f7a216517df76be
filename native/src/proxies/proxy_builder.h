// Tracking ellipsoids built from the body's feature rings every frame (paper §3.2, eq. 5-6).
//
// Two construction rules, selectable so their fidelity and cost can be compared:
//  - Paper: one ellipsoid per torso/neck/head ring with semi-axes (L_l, H, L_s), H = the larger
//    distance to the neighbouring ring centres; one ellipsoid per limb bone, centred at the bone's
//    midpoint, long semi-axis = half the bone, the other two = the largest mean ring radius on
//    that bone.
//  - Drape (default): one ellipsoid per ring and per sub-ring interpolated where rings are
//    further apart than the local radius; long semi-axis = kOverlap x the larger neighbour
//    spacing and cross-section scaled so the union neither dips between rings nor bulges at them
//    by more than ~3 %; chain ends and bends reach only to their neighbour; after the ring
//    ellipsoids, a slim cap per chain end, a fill under the pelvis, one per shoulder and one per
//    hip (docs/proxies.md has the derivation and the measured before/after).
#pragma once

#include "body/body_model.h"
#include "proxies/ellipsoid.h"

#include <cstdint>
#include <vector>

namespace drape {

enum class ProxyRule : int { Paper = 0, Drape = 1 };  // ABI-visible values

struct ProxySource {
  Chain chain = Chain::Torso;
  int first_ring = 0;  // ring (or first ring of the bone) it was built from
  int bone = -1;       // bone of the chain for per-bone ellipsoids, else -1
  // A second chain whose cloth collides with it too, or -1. The shoulder fills (chain = the arm,
  // first_ring = its junction ring) cover the stitch between the torso and the arm, which lies
  // under the yoke as much as under the sleeve, so they also count as the torso's.
  int also_chain = -1;
  // When not 0, the ellipsoid's collision groups instead of its chains': the pelvis fill belongs to
  // the torso cloth that may lie over the legs (kTorsoOverLegL | kTorsoOverLegR), not to the torso.
  uint8_t only_groups = 0;
};

// The collision groups of an ellipsoid (bit 1 << chain per chain it belongs to): what cloth
// collision groups (GarmentSim) and the garments' reach (cloth/garment_reach.h) test against.
uint8_t collisionGroups(const ProxySource& source);
// The collision group bit of a body chain.
inline constexpr uint8_t chainGroup(Chain c) { return static_cast<uint8_t>(1u << static_cast<int>(c)); }
// Two group bits above the chains' (GarmentSim::maskFor, setLegsTrusted): the torso cloth of a
// template garment over the left / right leg. A leg's ellipsoids carry them while the leg is
// trusted; collisionGroups() sets them only for the pelvis fill (kPelvisFillGroups below).
inline constexpr uint8_t kTorsoOverLegL = 1u << 6, kTorsoOverLegR = 1u << 7;
static_assert(kChainCount <= 6, "the chain bits must stay below kTorsoOverLegL");
// The pelvis fill's groups, and only its (ProxySource::only_groups): the torso cloth that may lie
// over the legs meets it, on both sides, while both legs are trusted (GarmentSim::applyLegGroups).
inline constexpr uint8_t kPelvisFillGroups = kTorsoOverLegL | kTorsoOverLegR;

class ProxyBuilder {
 public:
  explicit ProxyBuilder(ProxyRule rule = ProxyRule::Drape) : rule_(rule) {}
  ProxyRule rule() const { return rule_; }

  // Rebuilds every ellipsoid from the body's current rings and the pose. The count and order
  // depend only on the rule and the body's topology, so they are stable from frame to frame.
  // No allocation after the first call.
  void build(const BodyModel& body, const SkeletonPose& pose);
  // The same for only the ellipsoids k with active[k] != 0 (proxy culling, capi/adaptive.h): the
  // others keep the values of the last build that included them, indices stay stable. An
  // active ellipsoid gets exactly the value a full build gives it. The first build of a builder is
  // always full (it sizes the arrays); active must have one entry per ellipsoid.
  void build(const BodyModel& body, const SkeletonPose& pose, const std::vector<uint8_t>& active);
  // Ellipsoids written by the last build (all, or the active ones).
  size_t lastBuilt() const { return built_; }

  const std::vector<Ellipsoid>& ellipsoids() const { return ellipsoids_; }
  const std::vector<ProxySource>& sources() const { return sources_; }

 private:
  void add(const Ellipsoid& e, const ProxySource& s);
  // Whether the next ellipsoid (index count_) is culled from this build; if so, counts it.
  bool skipNext(const ProxySource& s);
  bool anyActive(size_t first, size_t count) const;
  void buildAll(const BodyModel& body, const SkeletonPose& pose);
  const std::vector<uint8_t>* active_ = nullptr;  // during a culled build
  size_t built_ = 0;
  // Ellipsoid index range of each chain's ring ellipsoids (Drape rule), from the first build.
  size_t chainFirst_[kChainCount] = {}, chainCount_[kChainCount] = {};
  void planSubRings(const BodyModel& body);
  // Shoulder fills (Drape rule): the ring points of each shoulder's stitch (body_topology.cpp) on
  // the neck ring and on the arm's junction ring, as their ring and the cosine and sine of their
  // angle (ringPointAt); found once, from the body's fixed topology, so a frame allocates nothing
  // and computes no angle.
  struct StitchPoint {
    int ring = 0;
    float c = 1.0f, s = 0.0f;
  };
  struct ShoulderStitch {
    std::vector<StitchPoint> neck, junction;
    int junction_ring = 0;
  };
  // Ring `ring`'s K points, at the angles the body mesh puts its ring vertices (ringPointAt).
  static std::vector<StitchPoint> ringStitchPoints(const BodyModel& body, int ring);
  // The centroid of `points` (from the rings, ringPointAt).
  static Vec3 centroid(const BodyModel& body, const std::vector<StitchPoint>& points);
  // A fill: the ellipsoid inscribed in the box of the points of `a` and `b` in the frame with y
  // (unit) given and x the part of frame's x orthogonal to it (else of its z), measured from c;
  // its semi-axes scaled per axis by `scale`.
  static Ellipsoid fillInBox(const BodyModel& body, const Vec3& c, const Vec3& y, const Mat3& frame,
                             const std::vector<StitchPoint>& a, const std::vector<StitchPoint>& b,
                             const Vec3& scale);
  void planShoulderFills(const BodyModel& body);
  Ellipsoid shoulderFill(const BodyModel& body, const ShoulderStitch& stitch) const;
  ShoulderStitch shoulders_[2];  // right, left; empty until the first build
  // Hip fills (Drape rule): per thigh, the hip ring's points on its side and the thigh ring's
  // points, found once like the shoulders'.
  struct HipStitch {
    std::vector<StitchPoint> hip, thigh;
    int thigh_ring = 0;
  };
  void planHipFills(const BodyModel& body);
  Ellipsoid hipFill(const BodyModel& body, const HipStitch& stitch) const;
  HipStitch hips_[2];  // right, left; empty until the first build
  // Pelvis fill (Drape rule): the hip ring's points and both thigh rings' (the hip fills'), found once.
  std::vector<StitchPoint> pelvis_hip_, pelvis_thighs_;
  void planPelvisFill(const BodyModel& body);
  Ellipsoid pelvisFill(const BodyModel& body) const;
  std::vector<int> subRings_;        // per ring: sub-rings inserted before the next ring
  std::vector<RingPose> scratch_;    // one chain's rings and sub-rings
  std::vector<int> scratchRing_;     // the ring each of them belongs to
  ProxyRule rule_;
  std::vector<Ellipsoid> ellipsoids_;
  std::vector<ProxySource> sources_;
  size_t count_ = 0;
};

}  // namespace drape
