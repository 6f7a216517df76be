#include "skeleton/layouts.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace drape {
namespace {

using namespace layout_constants;

// The union of every point any layout (or the canonical skeleton) names. A frame is first spread
// into this set, missing points are synthesised, and the target order is read back out of it.
enum U : int {
  uPelvis, uSpineMid, uSpineChest, uSpineShoulder, uNeck, uHead,
  uClavL, uShL, uElL, uWrL, uHaL, uTipL, uThL,
  uClavR, uShR, uElR, uWrR, uHaR, uTipR, uThR,
  uHipL, uKnL, uAnL, uFoL, uHipR, uKnR, uAnR, uFoR,
  uNose, uEyeL, uEarL, uEyeR, uEarR,
  uCount
};

// Sensor index -> union point, per layout (the docs/skeleton.md tables).
constexpr std::array<int, 20> kKinect1 = {
    uPelvis, uSpineMid, uSpineShoulder, uHead,  // HipCenter, Spine, ShoulderCenter, Head
    uShL, uElL, uWrL, uHaL, uShR, uElR, uWrR, uHaR,
    uHipL, uKnL, uAnL, uFoL, uHipR, uKnR, uAnR, uFoR};
constexpr std::array<int, 25> kKinect2 = {
    uPelvis, uSpineMid, uNeck, uHead,  // SpineBase, SpineMid, Neck, Head
    uShL, uElL, uWrL, uHaL, uShR, uElR, uWrR, uHaR,
    uHipL, uKnL, uAnL, uFoL, uHipR, uKnR, uAnR, uFoR,
    uSpineShoulder, uTipL, uThL, uTipR, uThR};
constexpr std::array<int, 32> kAzure = {
    uPelvis, uSpineMid, uSpineChest, uNeck,  // PELVIS, SPINE_NAVEL, SPINE_CHEST, NECK
    uClavL, uShL, uElL, uWrL, uHaL, uTipL, uThL,
    uClavR, uShR, uElR, uWrR, uHaR, uTipR, uThR,
    uHipL, uKnL, uAnL, uFoL, uHipR, uKnR, uAnR, uFoR,
    uHead, uNose, uEyeL, uEarL, uEyeR, uEarR};
// Canonical joint -> union point.
constexpr std::array<int, kJointCount> kCanonical = {
    uPelvis, uSpineMid, uSpineShoulder, uNeck, uHead,
    uShL, uElL, uWrL, uHaL, uShR, uElR, uWrR, uHaR,
    uHipL, uKnL, uAnL, uFoL, uHipR, uKnR, uAnR, uFoR};

const int* layoutTable(Layout layout) {
  switch (layout) {
    case Layout::Kinect1: return kKinect1.data();
    case Layout::Kinect2: return kKinect2.data();
    case Layout::Azure: return kAzure.data();
  }
  return nullptr;
}

const char* layoutName(Layout layout) {
  switch (layout) {
    case Layout::Kinect1: return "Kinect1";
    case Layout::Kinect2: return "Kinect2";
    case Layout::Azure: return "Azure";
  }
  return "?";
}

TrackingState minState(TrackingState a, TrackingState b) {
  return static_cast<unsigned>(a) < static_cast<unsigned>(b) ? a : b;
}
// State of a point guessed from others: NotTracked if any source is, else Inferred.
TrackingState guessedState(TrackingState a, TrackingState b) {
  return minState(minState(a, b), TrackingState::Inferred);
}

// Unit vector of v, or `fallback` when v is (near) zero or not finite.
Vec3 dirOr(const Vec3& v, const Vec3& fallback) {
  const float n = v.norm();
  return (n > 1e-6f && std::isfinite(n)) ? Vec3(v / n) : fallback;
}

struct Frame {
  std::array<JointSample, uCount> p{};
  std::array<bool, uCount> has{};

  void set(int u, const Vec3& pos, TrackingState s) {
    p[u].position = pos;
    p[u].state = s;
    has[u] = true;
  }
  const Vec3& pos(int u) const { return p[u].position; }
  TrackingState st(int u) const { return p[u].state; }
};

// Body axes from the torso: up = neck->head, left = right->left shoulder, front = left x up
// (geometric, so it holds in any right-handed camera space whatever way its Y axis points).
struct BodyAxes {
  Vec3 up, left, front;
};
BodyAxes bodyAxes(const Frame& f) {
  BodyAxes a;
  Vec3 upv = f.pos(uHead) - f.pos(uNeck);
  if (!(upv.norm() > 1e-4f)) upv = f.pos(uHead) - f.pos(uSpineShoulder);
  if (!(upv.norm() > 1e-4f)) upv = f.pos(uSpineShoulder) - f.pos(uPelvis);
  a.up = dirOr(upv, Vec3::UnitY());
  Vec3 lv = f.pos(uShL) - f.pos(uShR);
  lv -= a.up * a.up.dot(lv);
  if (!(lv.norm() > 1e-4f)) {
    lv = f.pos(uHipL) - f.pos(uHipR);
    lv -= a.up * a.up.dot(lv);
  }
  a.left = lv.norm() > 1e-4f && isFinite(lv) ? Vec3(lv.normalized()) : anyPerpendicular(a.up);
  a.front = a.left.cross(a.up);
  return a;
}

// `outward` is +1 for the left hand (body's left axis points away from the body), -1 for the right.
void synthesiseHand(Frame& f, const BodyAxes& axes, float outward, int el, int wr, int ha, int tip,
                    int th) {
  Vec3 hd = f.pos(ha) - f.pos(wr);
  if (!(hd.norm() > 1e-4f)) hd = f.pos(wr) - f.pos(el);
  const Vec3 handDir = dirOr(hd, -axes.up);
  const TrackingState s = guessedState(f.st(wr), f.st(ha));
  if (!f.has[tip]) f.set(tip, f.pos(ha) + handDir * kHandTipLengthM, s);
  if (!f.has[th]) {
    // Thumb: the median Kinect v2 offset from the hand in a frame built on the hand axis, the
    // body's front and the outward side (see kThumbOffset*).
    const Vec3 front = dirOr(axes.front - handDir * handDir.dot(axes.front), Vec3::Zero());
    const Vec3 side = dirOr(handDir.cross(front), Vec3::Zero());
    const float sideSign = side.dot(axes.left) * outward >= 0.0f ? 1.0f : -1.0f;
    f.set(th, f.pos(ha) + handDir * kThumbOffsetAlongM + front * kThumbOffsetFrontM +
                  side * (sideSign * kThumbOffsetOutM), s);
  }
}

// Fills every point the source layout lacks. Order matters: later rules use earlier results.
void synthesise(Frame& f) {
  // Canonical SpineShoulder (absent in Azure).
  if (!f.has[uSpineShoulder]) {
    // Clavicle midpoint, unless a clavicle is NotTracked while SPINE_CHEST and NECK are not.
    const bool clavLost = f.st(uClavL) == TrackingState::NotTracked ||
                          f.st(uClavR) == TrackingState::NotTracked;
    const bool chestNeckSeen = f.st(uSpineChest) != TrackingState::NotTracked &&
                               f.st(uNeck) != TrackingState::NotTracked;
    if (!(clavLost && chestNeckSeen)) {
      f.set(uSpineShoulder, 0.5f * (f.pos(uClavL) + f.pos(uClavR)),
            minState(f.st(uClavL), f.st(uClavR)));
    } else {
      f.set(uSpineShoulder, 0.5f * (f.pos(uSpineChest) + f.pos(uNeck)),
            guessedState(f.st(uSpineChest), f.st(uNeck)));
    }
  }
  // Neck (absent in Kinect v1).
  if (!f.has[uNeck]) {
    const Vec3& ss = f.pos(uSpineShoulder);
    f.set(uNeck, ss + kNeckFraction * (f.pos(uHead) - ss),
          guessedState(f.st(uSpineShoulder), f.st(uHead)));
  }
  // Azure SPINE_CHEST.
  if (!f.has[uSpineChest]) {
    const Vec3& sm = f.pos(uSpineMid);
    f.set(uSpineChest, sm + kSpineChestFraction * (f.pos(uSpineShoulder) - sm),
          guessedState(f.st(uSpineMid), f.st(uSpineShoulder)));
  }
  // Azure clavicles, symmetric about SpineShoulder so that their midpoint maps back exactly.
  if (!f.has[uClavL] || !f.has[uClavR]) {
    const Vec3 half = 0.5f * kClavicleFraction * (f.pos(uShL) - f.pos(uShR));
    const TrackingState s = guessedState(f.st(uSpineShoulder), minState(f.st(uShL), f.st(uShR)));
    f.set(uClavL, f.pos(uSpineShoulder) + half, s);
    f.set(uClavR, f.pos(uSpineShoulder) - half, s);
  }
  const BodyAxes axes = bodyAxes(f);
  synthesiseHand(f, axes, 1.0f, uElL, uWrL, uHaL, uTipL, uThL);
  synthesiseHand(f, axes, -1.0f, uElR, uWrR, uHaR, uTipR, uThR);
  // Face points around the head joint (a head centre): typical adult offsets in metres.
  if (!f.has[uNose]) {
    const Vec3& h = f.pos(uHead);
    const TrackingState s = guessedState(f.st(uHead), f.st(uNeck));
    f.set(uNose, h + 0.09f * axes.front - 0.01f * axes.up, s);
    f.set(uEyeL, h + 0.07f * axes.front + 0.03f * axes.up + 0.032f * axes.left, s);
    f.set(uEyeR, h + 0.07f * axes.front + 0.03f * axes.up - 0.032f * axes.left, s);
    f.set(uEarL, h - 0.01f * axes.front + 0.075f * axes.left, s);
    f.set(uEarR, h - 0.01f * axes.front - 0.075f * axes.left, s);
  }
}

bool checkInput(Layout layout, const JointSample* joints, int count, const char* what,
                std::string& err) {
  if (!isValidLayout(static_cast<int>(layout))) {
    err = std::string(what) + ": invalid layout value " + std::to_string(static_cast<int>(layout)) +
          " (expected 1 = Kinect1, 2 = Kinect2, 3 = Azure)";
    return false;
  }
  const int expected = layoutJointCount(layout);
  if (count != expected) {
    err = std::string(what) + ": layout " + layoutName(layout) + " has " +
          std::to_string(expected) + " joints, got " + std::to_string(count);
    return false;
  }
  if (joints == nullptr) {
    err = std::string(what) + ": joints pointer is null";
    return false;
  }
  return true;
}

void load(Layout layout, const JointSample* joints, int count, Frame& f) {
  const int* table = layoutTable(layout);
  for (int i = 0; i < count; ++i) {
    f.set(table[i], joints[i].position, sanitizeState(joints[i].state));
  }
  synthesise(f);
}

}  // namespace

bool mapToCanonical(Layout layout, const JointSample* joints, int count, SkeletonPose& out,
                    std::string& err) {
  if (!checkInput(layout, joints, count, "mapToCanonical", err)) return false;
  Frame f;
  load(layout, joints, count, f);
  for (int j = 0; j < kJointCount; ++j) {
    out.position[j] = f.pos(kCanonical[j]);
    out.state[j] = f.st(kCanonical[j]);
  }
  return true;
}

bool convertLayout(Layout from, const JointSample* in, int inCount, Layout to,
                   std::vector<JointSample>& out, std::string& err) {
  if (!checkInput(from, in, inCount, "convertLayout (source)", err)) return false;
  if (!isValidLayout(static_cast<int>(to))) {
    err = "convertLayout: invalid target layout value " + std::to_string(static_cast<int>(to)) +
          " (expected 1 = Kinect1, 2 = Kinect2, 3 = Azure)";
    return false;
  }
  Frame f;
  load(from, in, inCount, f);
  const int n = layoutJointCount(to);
  const int* table = layoutTable(to);
  out.resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) out[static_cast<size_t>(i)] = f.p[table[i]];
  return true;
}

}  // namespace drape
