// Sensor layouts <-> canonical skeleton (native/src/skeleton/layouts.h).
#include "recording/recording.h"
#include "skeleton/layouts.h"

#include "test_data.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace drape {
namespace {

constexpr float kMm = 1e-3f;

// Kinect v2 indices used below.
enum K2Index : int {
  kSpineBase = 0, kSpineMid = 1, kNeck = 2, kHead = 3, kShoulderL = 4, kHandL = 7, kShoulderR = 8,
  kHandR = 11, kSpineShoulder = 20, kHandTipL = 21, kThumbL = 22, kHandTipR = 23, kThumbR = 24
};
// Azure indices used below.
enum Az : int {
  kAzSpineChest = 2, kAzNeck = 3, kAzClavL = 4, kAzShL = 5, kAzClavR = 11, kAzShR = 12,
  kAzHead = 26, kAzNose = 27, kAzEyeL = 28, kAzEarL = 29, kAzEyeR = 30, kAzEarR = 31
};

// One real Kinect v2 frame (first line of Ges04_comehere.csv, all joints Tracked).
const char* const kFrameLine =
    "95833559566,-0.0491691,-0.34826,2.72472,2,-0.0899697,-0.0479029,2.71026,2,-0.129732,0.245593,"
    "2.68296,2,-0.0985159,0.384162,2.68353,2,-0.241244,0.123115,2.58833,2,-0.270125,-0.105105,"
    "2.52706,2,-0.205702,-0.320051,2.48741,2,-0.163518,-0.392301,2.52206,2,0.0354137,0.140839,"
    "2.78629,2,0.101988,-0.1282,2.82768,2,0.134049,-0.339775,2.77444,2,0.133429,-0.376188,2.76633,"
    "2,-0.112478,-0.347252,2.65076,2,-0.178317,-0.663711,2.6745,2,-0.203528,-1.00306,2.74466,2,"
    "-0.170536,-1.0851,2.70155,2,0.0152496,-0.34024,2.72763,2,-0.0276893,-0.686212,2.81214,2,"
    "-0.0472867,-0.997727,2.85574,2,-0.0231787,-1.07861,2.79478,2,-0.119963,0.173181,2.69204,2,"
    "-0.154176,-0.48576,2.54217,2,-0.196339,-0.428466,2.47433,2,0.133836,-0.438312,2.74992,2,"
    "0.158887,-0.391175,2.74938,2,";

// Frames of a Kinect v2 CSV, read by the project's reader.
std::vector<std::vector<JointSample>> loadCsv(const std::string& path) {
  std::vector<std::vector<JointSample>> frames;
  Recording rec;
  std::string err;
  if (!readRecordingFile(path, static_cast<int>(Layout::Kinect2), rec, err)) {
    ADD_FAILURE() << err;
    return frames;
  }
  for (const RecordingFrame& f : rec.frames) frames.push_back(f.joints);
  return frames;
}

std::vector<JointSample> embeddedFrame() {
  Recording rec;
  std::string err;
  EXPECT_TRUE(parseRecording(kFrameLine, static_cast<int>(Layout::Kinect2), rec, err)) << err;
  return rec.frames.empty() ? std::vector<JointSample>{} : rec.frames[0].joints;
}

const char* const kRecordings[] = {
    "kinect_v2_msft_labanotation/Ges01_wavehand.csv",
    "kinect_v2_msft_labanotation/Ges02_balancinghands.csv",
    "kinect_v2_msft_labanotation/Ges04_comehere.csv",
    "kinect_v2_msft_labanotation/KinectReader_joints_closerange.csv",
};

SkeletonPose mapOk(Layout layout, const std::vector<JointSample>& f) {
  SkeletonPose p;
  std::string err;
  EXPECT_TRUE(mapToCanonical(layout, f.data(), static_cast<int>(f.size()), p, err)) << err;
  return p;
}

std::vector<JointSample> convertOk(Layout from, const std::vector<JointSample>& f, Layout to) {
  std::vector<JointSample> out;
  std::string err;
  EXPECT_TRUE(convertLayout(from, f.data(), static_cast<int>(f.size()), to, out, err)) << err;
  EXPECT_EQ(static_cast<int>(out.size()), layoutJointCount(to));
  return out;
}

TrackingState synthState(TrackingState a, TrackingState b) {
  if (a == TrackingState::NotTracked || b == TrackingState::NotTracked) return TrackingState::NotTracked;
  return TrackingState::Inferred;
}

// Checks one Kinect v2 frame through Kinect1 and Azure and back.
void checkRoundTrip(const std::vector<JointSample>& v2) {
  const SkeletonPose a = mapOk(Layout::Kinect2, v2);

  // Kinect v1: every canonical joint but the Neck is a real v1 joint.
  const std::vector<JointSample> v1 = convertOk(Layout::Kinect2, v2, Layout::Kinect1);
  const SkeletonPose b = mapOk(Layout::Kinect1, v1);
  for (int j = 0; j < kJointCount; ++j) {
    if (j == idx(Joint::Neck)) continue;
    EXPECT_LT((a.position[j] - b.position[j]).norm(), kMm) << "v1 " << jointName(static_cast<Joint>(j));
    EXPECT_EQ(a.state[j], b.state[j]) << "v1 " << jointName(static_cast<Joint>(j));
  }
  // The synthesised neck: Inferred, on the SpineShoulder->Head segment, near the real v2 neck.
  const int ss = idx(Joint::SpineShoulder), nk = idx(Joint::Neck), hd = idx(Joint::Head);
  EXPECT_EQ(b.state[nk], synthState(a.state[ss], a.state[hd]));
  const Vec3 seg = a.position[hd] - a.position[ss];
  const float tn = (b.position[nk] - a.position[ss]).dot(seg) / seg.squaredNorm();
  EXPECT_GT(tn, 0.2f);
  EXPECT_LT(tn, 0.5f);
  EXPECT_LT((b.position[nk] - a.position[nk]).norm(), 0.05f);  // measured max ~2 cm

  // Azure: every canonical joint is mapped from a real Azure joint except SpineShoulder (the
  // clavicle midpoint), which the symmetric clavicle synthesis makes exact as well.
  const std::vector<JointSample> az = convertOk(Layout::Kinect2, v2, Layout::Azure);
  const SkeletonPose c = mapOk(Layout::Azure, az);
  for (int j = 0; j < kJointCount; ++j) {
    EXPECT_LT((a.position[j] - c.position[j]).norm(), kMm) << "Azure " << jointName(static_cast<Joint>(j));
    if (j != ss) {
      EXPECT_EQ(a.state[j], c.state[j]) << "Azure " << jointName(static_cast<Joint>(j));
    }
  }
  // Synthesised Azure joints are Inferred (NotTracked where a source joint is) and plausible.
  const TrackingState shoulders = a.state[idx(Joint::ShoulderL)] < a.state[idx(Joint::ShoulderR)]
                                      ? a.state[idx(Joint::ShoulderL)] : a.state[idx(Joint::ShoulderR)];
  EXPECT_EQ(az[kAzClavL].state, synthState(a.state[ss], shoulders));
  EXPECT_EQ(az[kAzClavR].state, synthState(a.state[ss], shoulders));
  EXPECT_EQ(az[kAzSpineChest].state, synthState(a.state[idx(Joint::SpineMid)], a.state[ss]));
  for (int f : {kAzNose, kAzEyeL, kAzEarL, kAzEyeR, kAzEarR}) {
    EXPECT_EQ(az[static_cast<size_t>(f)].state, synthState(a.state[hd], a.state[nk])) << f;
    const float d = (az[static_cast<size_t>(f)].position - az[kAzHead].position).norm();
    EXPECT_GT(d, 0.04f) << f;
    EXPECT_LT(d, 0.15f) << f;
  }
  // The subject faces the sensor (-Z toward it in Kinect camera space): nose and eyes in front of
  // the head centre, eyes above the nose (+Y up), each ear and eye on its own side of the body.
  EXPECT_LT(az[kAzNose].position.z(), az[kAzHead].position.z());
  EXPECT_LT(az[kAzEyeL].position.z(), az[kAzHead].position.z());
  EXPECT_GT(az[kAzEyeL].position.y(), az[kAzNose].position.y());
  const Vec3 toLeft = az[kAzShL].position - az[kAzShR].position;
  EXPECT_GT((az[kAzEarL].position - az[kAzHead].position).dot(toLeft), 0.0f);
  EXPECT_LT((az[kAzEarR].position - az[kAzHead].position).dot(toLeft), 0.0f);
  EXPECT_GT((az[kAzEyeL].position - az[kAzEyeR].position).dot(toLeft), 0.0f);
  // Clavicles lie between SpineShoulder and their shoulder.
  const float halfWidth = 0.5f * (az[kAzShL].position - az[kAzShR].position).norm();
  EXPECT_LT((az[kAzClavL].position - a.position[ss]).norm(), halfWidth);
  EXPECT_LT((az[kAzClavL].position - az[kAzShL].position).norm(),
            (az[kAzClavR].position - az[kAzShL].position).norm());
  // SPINE_CHEST between SpineMid and SpineShoulder; NECK is the v2 neck.
  EXPECT_LT((az[kAzSpineChest].position - a.position[idx(Joint::SpineMid)]).norm(),
            (a.position[ss] - a.position[idx(Joint::SpineMid)]).norm());
  EXPECT_LT((az[kAzNeck].position - v2[kNeck].position).norm(), kMm);

  // Kinect v2 -> Azure -> Kinect v2 keeps all 25 joints (hand tips, thumbs, SpineShoulder too).
  const std::vector<JointSample> back = convertOk(Layout::Azure, az, Layout::Kinect2);
  for (size_t j = 0; j < 25; ++j) {
    EXPECT_LT((back[j].position - v2[j].position).norm(), kMm) << "v2->Azure->v2 joint " << j;
  }
  // Kinect v2 -> v1 -> v2: hand tips and thumbs synthesised near the hand, Inferred.
  const std::vector<JointSample> v2b = convertOk(Layout::Kinect1, v1, Layout::Kinect2);
  for (int j : {kHandTipL, kThumbL, kHandTipR, kThumbR}) {
    const int hand = (j == kHandTipL || j == kThumbL) ? kHandL : kHandR;
    const float d = (v2b[static_cast<size_t>(j)].position - v2[static_cast<size_t>(hand)].position).norm();
    EXPECT_GT(d, 0.02f) << j;
    EXPECT_LT(d, 0.12f) << j;
    EXPECT_NE(v2b[static_cast<size_t>(j)].state, TrackingState::Tracked) << j;
  }
  EXPECT_LT((v2b[kSpineShoulder].position - v2[kSpineShoulder].position).norm(), kMm);
  EXPECT_EQ(v2b[kNeck].state, synthState(v2[kSpineShoulder].state, v2[kHead].state));
}

TEST(Layouts, Kinect2RoundTripsThroughKinect1AndAzure) {
  const std::vector<JointSample> v2 = embeddedFrame();
  ASSERT_EQ(v2.size(), 25u);
  checkRoundTrip(v2);
}

TEST(Layouts, RoundTripOnEveryRecordedFrame) {
  for (const char* rel : kRecordings) {
    DRAPE_REQUIRE_SHARED(path, rel);
    SCOPED_TRACE(rel);
    const auto frames = loadCsv(path);
    ASSERT_GT(frames.size(), 100u);
    for (const auto& f : frames) {
      checkRoundTrip(f);
      if (HasFailure()) return;  // one frame's report is enough
    }
  }
}

TEST(Layouts, Kinect2MapsByName) {
  const std::vector<JointSample> v2 = embeddedFrame();
  const SkeletonPose p = mapOk(Layout::Kinect2, v2);
  EXPECT_EQ(p.position[idx(Joint::Pelvis)], v2[kSpineBase].position);
  EXPECT_EQ(p.position[idx(Joint::SpineMid)], v2[kSpineMid].position);
  EXPECT_EQ(p.position[idx(Joint::SpineShoulder)], v2[kSpineShoulder].position);
  EXPECT_EQ(p.position[idx(Joint::Neck)], v2[kNeck].position);
  EXPECT_EQ(p.position[idx(Joint::HandR)], v2[kHandR].position);
  EXPECT_EQ(p.position[idx(Joint::FootR)], v2[19].position);
  EXPECT_EQ(p.position[idx(Joint::HipL)], v2[12].position);
}

TEST(Layouts, Kinect1NeckSynthesisedFromShoulderCenterAndHead) {
  std::vector<JointSample> v1(20);
  for (size_t j = 0; j < 20; ++j) {
    v1[j].position = Vec3(0.01f * static_cast<float>(j), 0.0f, 2.0f);
    v1[j].state = TrackingState::Tracked;
  }
  v1[2].position = Vec3(0.0f, 0.5f, 2.0f);  // ShoulderCenter
  v1[3].position = Vec3(0.0f, 0.8f, 2.1f);  // Head
  SkeletonPose p = mapOk(Layout::Kinect1, v1);
  const Vec3 expected = v1[2].position + layout_constants::kNeckFraction * (v1[3].position - v1[2].position);
  EXPECT_LT((p.position[idx(Joint::Neck)] - expected).norm(), 1e-6f);
  EXPECT_EQ(p.state[idx(Joint::Neck)], TrackingState::Inferred);
  EXPECT_EQ(p.position[idx(Joint::SpineShoulder)], v1[2].position);
  EXPECT_EQ(p.state[idx(Joint::SpineShoulder)], TrackingState::Tracked);
  v1[3].state = TrackingState::NotTracked;
  p = mapOk(Layout::Kinect1, v1);
  EXPECT_EQ(p.state[idx(Joint::Neck)], TrackingState::NotTracked);
}

TEST(Layouts, AzureSpineShoulderFallsBackToChestNeckMidpoint) {
  std::vector<JointSample> az = convertOk(Layout::Kinect2, embeddedFrame(), Layout::Azure);
  for (auto& j : az) j.state = TrackingState::Tracked;
  SkeletonPose p = mapOk(Layout::Azure, az);
  EXPECT_LT((p.position[idx(Joint::SpineShoulder)] -
             0.5f * (az[kAzClavL].position + az[kAzClavR].position)).norm(), 1e-6f);
  EXPECT_EQ(p.state[idx(Joint::SpineShoulder)], TrackingState::Tracked);
  az[kAzClavR].state = TrackingState::NotTracked;
  p = mapOk(Layout::Azure, az);
  EXPECT_LT((p.position[idx(Joint::SpineShoulder)] -
             0.5f * (az[kAzSpineChest].position + az[kAzNeck].position)).norm(), 1e-6f);
  EXPECT_EQ(p.state[idx(Joint::SpineShoulder)], TrackingState::Inferred);
}

// Nothing assumes "up" is +Y: rotating the input (e.g. into Azure's +Y-down camera) rotates the
// synthesised joints with it.
TEST(Layouts, SynthesisIsIndependentOfTheCameraAxes) {
  const std::vector<JointSample> v2 = embeddedFrame();
  const Mat3 r = Eigen::AngleAxisf(kPi, Vec3::UnitX()).toRotationMatrix() *
                 Eigen::AngleAxisf(0.3f, Vec3::UnitY()).toRotationMatrix();
  std::vector<JointSample> rotated = v2;
  for (auto& j : rotated) j.position = r * j.position;
  const auto az = convertOk(Layout::Kinect2, v2, Layout::Azure);
  const auto azr = convertOk(Layout::Kinect2, rotated, Layout::Azure);
  for (size_t j = 0; j < az.size(); ++j) {
    EXPECT_LT((r * az[j].position - azr[j].position).norm(), 1e-5f) << j;
  }
  const auto v1r = convertOk(Layout::Kinect2, rotated, Layout::Kinect1);
  const SkeletonPose pr = mapOk(Layout::Kinect1, v1r);
  const SkeletonPose p = mapOk(Layout::Kinect1, convertOk(Layout::Kinect2, v2, Layout::Kinect1));
  for (int j = 0; j < kJointCount; ++j) EXPECT_LT((r * p.position[j] - pr.position[j]).norm(), 1e-5f);
}

TEST(Layouts, WrongCountRejectedWithMessage) {
  const std::vector<JointSample> v2 = embeddedFrame();
  SkeletonPose p;
  p.position.fill(Vec3(7, 7, 7));
  std::string err;
  EXPECT_FALSE(mapToCanonical(Layout::Kinect2, v2.data(), 20, p, err));
  EXPECT_NE(err.find("25"), std::string::npos) << err;
  EXPECT_NE(err.find("20"), std::string::npos) << err;
  EXPECT_EQ(p.position[0], Vec3(7, 7, 7)) << "out must be untouched on failure";
  err.clear();
  EXPECT_FALSE(mapToCanonical(Layout::Azure, v2.data(), 25, p, err));
  EXPECT_NE(err.find("32"), std::string::npos) << err;
  err.clear();
  EXPECT_FALSE(mapToCanonical(Layout::Kinect1, v2.data(), -1, p, err));
  EXPECT_FALSE(err.empty());

  std::vector<JointSample> out(3);
  err.clear();
  EXPECT_FALSE(convertLayout(Layout::Kinect2, v2.data(), 24, Layout::Azure, out, err));
  EXPECT_NE(err.find("24"), std::string::npos) << err;
  EXPECT_EQ(out.size(), 3u) << "out must be untouched on failure";
}

TEST(Layouts, InvalidLayoutRejected) {
  const std::vector<JointSample> v2 = embeddedFrame();
  SkeletonPose p;
  std::vector<JointSample> out;
  for (int bad : {0, 4, -1, 1000}) {
    std::string err;
    EXPECT_FALSE(mapToCanonical(static_cast<Layout>(bad), v2.data(), 25, p, err)) << bad;
    EXPECT_NE(err.find("invalid layout"), std::string::npos) << err;
    err.clear();
    EXPECT_FALSE(convertLayout(static_cast<Layout>(bad), v2.data(), 25, Layout::Kinect2, out, err));
    EXPECT_NE(err.find("invalid"), std::string::npos) << err;
    err.clear();
    EXPECT_FALSE(convertLayout(Layout::Kinect2, v2.data(), 25, static_cast<Layout>(bad), out, err));
    EXPECT_NE(err.find("invalid"), std::string::npos) << err;
  }
  std::string err;
  EXPECT_FALSE(mapToCanonical(Layout::Kinect2, nullptr, 25, p, err));
  EXPECT_NE(err.find("null"), std::string::npos) << err;
}

TEST(Layouts, NanAndBadStatesDoNotMisbehave) {
  std::vector<JointSample> v2 = embeddedFrame();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  v2[kHead].position = Vec3(nan, nan, nan);
  v2[kHandL].state = static_cast<TrackingState>(7);
  SkeletonPose p;
  std::string err;
  ASSERT_TRUE(mapToCanonical(Layout::Kinect2, v2.data(), 25, p, err));
  EXPECT_EQ(p.state[idx(Joint::HandL)], TrackingState::NotTracked);
  EXPECT_TRUE(isFinite(p.position[idx(Joint::Pelvis)]));
  for (Layout to : {Layout::Kinect1, Layout::Azure}) {
    std::vector<JointSample> out;
    ASSERT_TRUE(convertLayout(Layout::Kinect2, v2.data(), 25, to, out, err)) << err;
    ASSERT_TRUE(mapToCanonical(to, out.data(), static_cast<int>(out.size()), p, err)) << err;
    EXPECT_TRUE(isFinite(p.position[idx(Joint::Pelvis)]));
    EXPECT_TRUE(isFinite(p.position[idx(Joint::KneeL)]));
  }
  // Every joint NaN: still no crash.
  for (auto& j : v2) j.position = Vec3(nan, nan, nan);
  std::vector<JointSample> out;
  EXPECT_TRUE(convertLayout(Layout::Kinect2, v2.data(), 25, Layout::Azure, out, err));
  EXPECT_TRUE(mapToCanonical(Layout::Azure, out.data(), 32, p, err));
}

}  // namespace
}  // namespace drape
