#include "body/body_model.h"

#include "body/arm_clearance.h"
#include "body/mesh_metrics.h"

#include <algorithm>
#include <cmath>

namespace drape {

namespace {

// The joints each chain runs through (bone k of a chain = joints[k] -> joints[k+1]).
struct ChainJoints {
  int count;
  Joint joints[4];
};
constexpr ChainJoints kChains[kChainCount] = {
    {3, {Joint::Pelvis, Joint::SpineMid, Joint::SpineShoulder, Joint::SpineShoulder}},
    {3, {Joint::SpineShoulder, Joint::Neck, Joint::Head, Joint::Head}},
    {4, {Joint::ShoulderL, Joint::ElbowL, Joint::WristL, Joint::HandL}},
    {4, {Joint::ShoulderR, Joint::ElbowR, Joint::WristR, Joint::HandR}},
    {4, {Joint::HipL, Joint::KneeL, Joint::AnkleL, Joint::FootL}},
    {4, {Joint::HipR, Joint::KneeR, Joint::AnkleR, Joint::FootR}},
};

constexpr int idx2(Chain c) { return static_cast<int>(c); }

int boneCountOf(Chain c) { return kChains[static_cast<int>(c)].count - 1; }

// Perimeter of the K-gon inscribed in an ellipse with semi-axes (forward, side): the girth a ring
// actually has, so measured sites match exactly instead of within the K-gon's shortfall.
float ringPolygonPerimeter(int K, float forward, float side) {
  float p = 0.0f;
  for (int j = 0; j < K; ++j) {
    const float a0 = 2.0f * kPi * static_cast<float>(j) / static_cast<float>(K);
    const float a1 = 2.0f * kPi * static_cast<float>(j + 1) / static_cast<float>(K);
    const float dx = forward * (std::cos(a1) - std::cos(a0));
    const float dz = side * (std::sin(a1) - std::sin(a0));
    p += std::sqrt(dx * dx + dz * dz);
  }
  return p;
}

// Semi-axes of the ring whose K-gon perimeter equals `girth`, with forward:side = ratio.
void axesForGirth(int K, float girth, float ratio, float& forward, float& side) {
  const float unit = ringPolygonPerimeter(K, ratio, 1.0f);
  side = girth / unit;
  forward = side * ratio;
}

Vec3 safeNormalized(const Vec3& v, const Vec3& fallback) {
  const float n = v.norm();
  return n > 1e-6f ? Vec3(v / n) : fallback;
}

}  // namespace

int chainJointCount(Chain c) { return kChains[static_cast<int>(c)].count; }
Joint chainJoint(Chain c, int k) { return kChains[static_cast<int>(c)].joints[k]; }

const char* chainName(Chain c) {
  static const char* const kNames[kChainCount] = {"torso", "head", "arm_l", "arm_r", "leg_l", "leg_r"};
  const int i = static_cast<int>(c);
  return (i >= 0 && i < kChainCount) ? kNames[i] : "?";
}

BodyModel::BodyModel(const ResolvedShape& shape, const BodyModelParams& params)
    : shape_(shape), params_(params), K_(params.ring_points) {
  buildStations();
  // Topology needs the rest pose only to align the seams of the junction stitches.
  const int ringCount = static_cast<int>(stations_.size());
  rings_.resize(ringCount);
  bridgeFirst_ = ringCount * K_;
  bridgeCount_ = std::max(1, K_ / 4 - 1);
  apexFirst_ = bridgeFirst_ + bridgeCount_;
  positions_.assign(static_cast<size_t>(apexFirst_ + 5), Vec3::Zero());
  normals_.assign(positions_.size(), Vec3::UnitY());
  const SkeletonPose rest = restPose(shape_);
  placeRings(rest);
  writeVertices();
  writeApexes(rest);
  buildTopology();
  computeNormals();
}

void BodyModel::setShape(const ResolvedShape& shape) {
  // The stations' count and order do not depend on the shape, only their sizes: rebuild them.
  shape_ = shape;
  buildStations();
}

// ---------------------------------------------------------------------------------------------
// Ring stations: where each ring sits along its chain and how big it is, from the shape.
// Positions along the bones follow Kinect v2 joint placement (see docs/body-model.md).
// ---------------------------------------------------------------------------------------------
void BodyModel::buildStations() {
  const ResolvedShape& s = shape_;
  const float H = s.input.height_m;
  const int K = K_;
  std::vector<RingStation> key;  // the defining stations, chain by chain
  auto add = [&](Chain c, float u, float offset, float girth, float ratio, int measure = -1,
                 bool junction = false) {
    RingStation st;
    st.chain = c;
    st.u = u;
    st.offset_m = offset;
    axesForGirth(K, girth, ratio, st.forward_m, st.side_m);
    st.measure = measure;
    st.junction = junction;
    key.push_back(st);
  };
  auto ratioOf = [](float depth, float breadth) {
    return breadth > 0.0f ? std::clamp(depth / breadth, 0.45f, 1.2f) : 0.75f;
  };
  const float neck = s[Measure::Neck], chest = s[Measure::Chest], waist = s[Measure::Waist];
  const float hip = s[Measure::Hip], thigh = s[Measure::Thigh], calf = s[Measure::Calf];
  const float upperArm = s[Measure::UpperArm], forearm = s[Measure::Forearm];
  const float wrist = s[Measure::Wrist], ankle = s[Measure::Ankle], head = s[Measure::Head];
  const float chestRatio = ratioOf(s[Measure::ChestDepth], s[Measure::ChestBreadth]);
  const float waistRatio = ratioOf(s[Measure::WaistDepth], s[Measure::WaistBreadth]);
  const float hipRatio = ratioOf(s[Measure::ButtockDepth], s[Measure::HipBreadth]);

  // Torso: Pelvis (u=0) -> SpineMid (u=1) -> SpineShoulder (u=2).
  add(Chain::Torso, 0.00f, 0.0f, hip, hipRatio, static_cast<int>(Measure::Hip));
  add(Chain::Torso, 0.55f, 0.0f, waist, waistRatio, static_cast<int>(Measure::Waist));
  add(Chain::Torso, 1.00f, 0.0f, 0.5f * (waist + chest), 0.5f * (waistRatio + chestRatio));
  add(Chain::Torso, 1.45f, 0.0f, chest, chestRatio, static_cast<int>(Measure::Chest));
  add(Chain::Torso, 1.80f, 0.0f, 0.95f * chest, 0.9f * chestRatio);  // armpit level: ring T

  // Neck and head: SpineShoulder (u=0) -> Neck (u=1) -> Head (u=2, centre of the head).
  const float headR = head / (2.0f * kPi);
  // ANSUR's neck girth is taken mid-neck (below the larynx); the base of the neck is ~12 % larger.
  add(Chain::Head, 0.30f, 0.0f, 1.12f * neck, 0.9f);  // ring N
  add(Chain::Head, 1.00f, 0.0f, neck, 0.95f, static_cast<int>(Measure::Neck));
  add(Chain::Head, 2.00f, -0.70f * headR, 0.78f * head, 1.1f);
  add(Chain::Head, 2.00f, -0.35f * headR, 0.95f * head, 1.2f);
  add(Chain::Head, 2.00f, 0.00f, head, 1.2f);
  add(Chain::Head, 2.00f, 0.50f * headR, 0.90f * head, 1.2f);
  add(Chain::Head, 2.00f, 0.90f * headR, 0.60f * head, 1.15f);

  // Arms: Shoulder (u=0) -> Elbow (1) -> Wrist (2) -> Hand (3). The first ring is the dynamic
  // shoulder junction; its radius is set from the ring after it every frame.
  for (Chain arm : {Chain::ArmL, Chain::ArmR}) {
    add(arm, 0.00f, 0.0f, 1.08f * upperArm, 1.0f, -1, /*junction=*/true);
    add(arm, 0.15f, 0.0f, 1.08f * upperArm, 1.0f);
    add(arm, 0.50f, 0.0f, upperArm, 1.0f, static_cast<int>(Measure::UpperArm));
    add(arm, 1.00f, 0.0f, 0.46f * (upperArm + forearm), 1.0f);
    add(arm, 1.25f, 0.0f, forearm, 1.0f, static_cast<int>(Measure::Forearm));
    add(arm, 2.00f, 0.0f, wrist, 1.1f);
    add(arm, 2.50f, 0.0f, 1.30f * wrist, 1.6f);
    add(arm, 3.00f, 0.0f, 1.20f * wrist, 1.6f);
  }

  // Legs: Hip (u=0) -> Knee (1) -> Ankle (2) -> Foot (3). The thigh ring hangs below the hip
  // joint by the crotch drop, where ANSUR measures the thigh girth.
  const float crotchDrop = std::max(0.03f * H, 0.530f * H - s[Measure::CrotchHeight]) * 0.8f;
  const float footScale = H / 1.70f;
  for (Chain leg : {Chain::LegL, Chain::LegR}) {
    add(leg, 0.00f, crotchDrop, thigh, 1.0f, static_cast<int>(Measure::Thigh));
    add(leg, 0.50f, 0.0f, 0.5f * (thigh + 0.5f * (0.62f * thigh + calf)), 1.0f);
    add(leg, 0.95f, 0.0f, 0.5f * (0.62f * thigh + calf), 1.0f);
    add(leg, 1.35f, 0.0f, calf, 1.0f, static_cast<int>(Measure::Calf));
    add(leg, 2.00f, 0.0f, ankle, 1.0f);
    add(leg, 2.50f, 0.0f, ringPolygonPerimeter(K, 0.035f, 0.045f) * footScale, 0.035f / 0.045f);
    add(leg, 3.00f, 0.0f, ringPolygonPerimeter(K, 0.020f, 0.040f) * footScale, 0.5f);
  }

  // Interpolate `rings_per_segment` rings between consecutive stations of a chain.
  const int extra = params_.rings_per_segment;
  stations_.clear();
  for (int c = 0; c < kChainCount; ++c) {
    chainFirst_[c] = static_cast<int>(stations_.size());
    const RingStation* prev = nullptr;
    for (const RingStation& st : key) {
      if (static_cast<int>(st.chain) != c) continue;
      if (prev) {
        for (int e = 1; e <= extra; ++e) {
          const float f = static_cast<float>(e) / static_cast<float>(extra + 1);
          RingStation mid;
          mid.chain = st.chain;
          mid.u = prev->u + f * (st.u - prev->u);
          mid.offset_m = prev->offset_m + f * (st.offset_m - prev->offset_m);
          mid.forward_m = prev->forward_m + f * (st.forward_m - prev->forward_m);
          mid.side_m = prev->side_m + f * (st.side_m - prev->side_m);
          stations_.push_back(mid);
        }
      }
      stations_.push_back(st);
      prev = &st;
    }
    chainCount_[c] = static_cast<int>(stations_.size()) - chainFirst_[c];
  }
  // The junction ring takes the mean radius of the upper-arm ring nearest the shoulder
  // (paper eq. 3): the first non-junction ring of the chain.
  for (Chain arm : {Chain::ArmL, Chain::ArmR}) {
    RingStation& j = stations_[chainFirst_[static_cast<int>(arm)]];
    const RingStation& next = stations_[chainFirst_[static_cast<int>(arm)] + 1];
    const float r = 0.5f * (next.forward_m + next.side_m);
    j.forward_m = j.side_m = r;
  }
}

// ---------------------------------------------------------------------------------------------
// Ring placement (every frame)
// ---------------------------------------------------------------------------------------------
void BodyModel::placeRings(const SkeletonPose& pose) {
  const auto P = [&](Joint j) -> const Vec3& { return pose.position[idx(j)]; };
  const Vec3 worldUp = safeNormalized(P(Joint::SpineShoulder) - P(Joint::Pelvis), Vec3::UnitY());
  const Vec3 hipsRight = safeNormalized(P(Joint::HipR) - P(Joint::HipL), Vec3::UnitX());
  const Vec3 shouldersRight = safeNormalized(P(Joint::ShoulderR) - P(Joint::ShoulderL), hipsRight);

  // Position and direction along a chain at (u, offset).
  auto along = [&](Chain c, float u, float offset, Vec3& centre, Vec3& dir, const Vec3& fallbackDir) {
    const ChainJoints& cj = kChains[static_cast<int>(c)];
    const int bones = boneCountOf(c);
    const int k = std::clamp(static_cast<int>(std::floor(u)), 0, bones - 1);
    const float t = u - static_cast<float>(k);
    const Vec3& a = P(cj.joints[k]);
    const Vec3& b = P(cj.joints[k + 1]);
    dir = safeNormalized(b - a, fallbackDir);
    centre = a + t * (b - a) + offset * dir;
  };

  // Torso and head: frames from the bone and the body's left-right axis (hips blending into
  // shoulders going up), so front and back stay where the person faces.
  for (Chain c : {Chain::Torso, Chain::Head}) {
    Vec3 prevY = worldUp;
    Vec3 prevX = safeNormalized(worldUp.cross(shouldersRight), Vec3::UnitZ());
    for (int i = 0; i < chainCount_[static_cast<int>(c)]; ++i) {
      const int r = chainFirst_[static_cast<int>(c)] + i;
      const RingStation& st = stations_[r];
      Vec3 centre, y;
      along(c, st.u, st.offset_m, centre, y, prevY);
      const float w = c == Chain::Torso ? std::clamp(st.u / 2.0f, 0.0f, 1.0f) : 1.0f;
      const Vec3 right = safeNormalized((1.0f - w) * hipsRight + w * shouldersRight, shouldersRight);
      const Vec3 x = safeNormalized(y.cross(right), prevX);
      RingPose& rp = rings_[r];
      rp.centre = centre;
      rp.frame.col(0) = x;
      rp.frame.col(1) = y;
      rp.frame.col(2) = x.cross(y);
      rp.forward_m = st.forward_m;
      rp.side_m = st.side_m;
      prevX = x;
      prevY = y;
    }
  }

  // Limbs: each ring's frame is the previous one carried by the smallest rotation onto the new
  // bone direction (parallel transport), so rings never twist against each other. Chains start
  // from a reference frame pointing the way the limb rests: sideways for arms, down for legs.
  const RingPose& T = rings_[chainFirst_[idx2(Chain::Torso)] + chainCount_[idx2(Chain::Torso)] - 1];
  const RingPose& Pr = rings_[chainFirst_[idx2(Chain::Torso)]];
  for (Chain c : {Chain::ArmL, Chain::ArmR, Chain::LegL, Chain::LegR}) {
    Vec3 x, y;
    switch (c) {
      case Chain::ArmL: x = T.frame.col(0); y = -T.frame.col(2); break;
      case Chain::ArmR: x = T.frame.col(0); y = T.frame.col(2); break;
      default: x = Pr.frame.col(0); y = -Pr.frame.col(1); break;
    }
    const Vec3 restY = y, restX = x;
    for (int i = 0; i < chainCount_[static_cast<int>(c)]; ++i) {
      const int r = chainFirst_[static_cast<int>(c)] + i;
      const RingStation& st = stations_[r];
      Vec3 centre, dir;
      along(c, st.u, st.offset_m, centre, dir, y);
      const Quat q = rotationBetween(y, dir);
      x = q * x;
      y = dir;
      x = safeNormalized(x - x.dot(y) * y, anyPerpendicular(y));
      RingPose& rp = rings_[r];
      rp.centre = centre;
      if (st.junction && params_.fixed_shoulder_junction) {
        // The paper's fixed connection ring: its plane never turns with the arm.
        rp.frame.col(0) = restX;
        rp.frame.col(1) = restY;
        rp.frame.col(2) = restX.cross(restY);
      } else {
        rp.frame.col(0) = x;
        rp.frame.col(1) = y;
        rp.frame.col(2) = x.cross(y);
      }
      rp.forward_m = st.forward_m;
      rp.side_m = st.side_m;
    }
  }
  armShift_[0] = armShift_[1] = Vec3::Zero();
  if (params_.arms_clear_torso) {
    ArmClearance c;
    c.clearance_m = params_.arm_torso_clearance_m;
    c.weight = armWeight_;
    keepArmsOutOfTorso(*this, rings_, c, armShift_);
  }
}

// ---------------------------------------------------------------------------------------------
// Vertices: ring points (paper eq. 1-2 with the corrected order: scale, rotate, translate),
// crotch bridge and the apexes that close head, hands and feet.
// ---------------------------------------------------------------------------------------------
void BodyModel::writeVertices() {
  const int K = K_;
  for (size_t r = 0; r < rings_.size(); ++r) {
    const RingPose& rp = rings_[r];
    Vec3* out = &positions_[r * static_cast<size_t>(K)];
    for (int j = 0; j < K; ++j) {
      const float theta = 2.0f * kPi * static_cast<float>(j) / static_cast<float>(K);
      out[j] = ringPointAt(rp, std::cos(theta), std::sin(theta));
    }
  }
  // Crotch bridge: from the front-centre point of the hip ring to its back-centre point, sagging
  // down to the crotch between the thighs.
  const int P0 = chainFirst_[idx2(Chain::Torso)] * K;
  const Vec3& front = positions_[P0];
  const Vec3& back = positions_[P0 + K / 2];
  const Vec3 down = -rings_[chainFirst_[idx2(Chain::Torso)]].frame.col(1);
  const float drop = stations_[chainFirst_[idx2(Chain::LegL)]].offset_m;
  for (int b = 0; b < bridgeCount_; ++b) {
    const float u = static_cast<float>(b + 1) / static_cast<float>(bridgeCount_ + 1);
    positions_[bridgeFirst_ + b] = front + u * (back - front) + down * (drop * std::sqrt(std::sin(kPi * u)));
  }
}

void BodyModel::writeApexes(const SkeletonPose& pose) {
  // Apexes: beyond the last ring of each open chain, along that ring's axis.
  const float H = shape_.input.height_m;
  const float headR = shape_[Measure::Head] / (2.0f * kPi);
  const auto endRing = [&](Chain c) -> const RingPose& {
    return rings_[chainFirst_[idx2(c)] + chainCount_[idx2(c)] - 1];
  };
  const Vec3& head = pose.position[idx(Joint::Head)];
  positions_[apexFirst_ + 0] = head + endRing(Chain::Head).frame.col(1) * (1.2f * headR);
  // A hand moved out of the torso with its arm (arms_clear_torso) keeps its apex beyond its ring.
  positions_[apexFirst_ + 1] =
      pose.position[idx(Joint::HandL)] + endRing(Chain::ArmL).frame.col(1) * (0.045f * H) + armShift_[0];
  positions_[apexFirst_ + 2] =
      pose.position[idx(Joint::HandR)] + endRing(Chain::ArmR).frame.col(1) * (0.045f * H) + armShift_[1];
  positions_[apexFirst_ + 3] = pose.position[idx(Joint::FootL)] + endRing(Chain::LegL).frame.col(1) * (0.030f * H);
  positions_[apexFirst_ + 4] = pose.position[idx(Joint::FootR)] + endRing(Chain::LegR).frame.col(1) * (0.030f * H);
}

Vec3 BodyModel::apex(Chain c) const {
  if (c == Chain::Torso) return rings_[static_cast<size_t>(chainFirst_[idx2(c)] + chainCount_[idx2(c)] - 1)].centre;
  return positions_[static_cast<size_t>(apexFirst_ + idx2(c) - 1)];
}

void BodyModel::computeNormals() { vertexNormals(positions_, indices_, normals_); }

void BodyModel::update(const SkeletonPose& pose) {
  updateRings(pose);
  updateMesh();
  updateNormals();
}

void BodyModel::updateRings(const SkeletonPose& pose) {
  placeRings(pose);
  writeApexes(pose);
}

void BodyModel::updateMesh() { writeVertices(); }

void BodyModel::updateNormals() { computeNormals(); }

}  // namespace drape
