// Recording readers: Kinect v2 CSV, CMU BVH (mapped onto Kinect v2), our .drec format, and
// the error paths (these readers sit behind the C ABI and get fuzzed).
#include "recording/recording.h"

#include "test_data.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace drape {
namespace {

// Kinect v2 JointType indices used below.
enum K2 : int {
  SpineBase = 0, SpineMid = 1, Neck = 2, Head = 3,
  ShoulderLeft = 4, ElbowLeft = 5, WristLeft = 6, HandLeft = 7,
  ShoulderRight = 8, ElbowRight = 9, WristRight = 10, HandRight = 11,
  HipLeft = 12, KneeLeft = 13, AnkleLeft = 14, FootLeft = 15,
  HipRight = 16, KneeRight = 17, AnkleRight = 18, FootRight = 19,
  SpineShoulder = 20, HandTipLeft = 21, ThumbLeft = 22, HandTipRight = 23, ThumbRight = 24,
};

const Vec3& P(const RecordingFrame& f, int j) { return f.joints[static_cast<std::size_t>(j)].position; }
float dist(const RecordingFrame& f, int a, int b) { return (P(f, a) - P(f, b)).norm(); }

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// ------------------------------------------------------------------------------------------
// Synthetic CMU-named skeleton in metres (independent of the shared data).
// Root channels are substituted for @ROOTCH@; every other joint has Zrotation Yrotation Xrotation.
const char* const kSyntheticHierarchy = R"(HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 @ROOTCH@
  JOINT LeftHip
  {
    OFFSET 0.1 -0.1 0
    CHANNELS 3 Zrotation Yrotation Xrotation
    JOINT LeftKnee
    {
      OFFSET 0 -0.4 0
      CHANNELS 3 Zrotation Yrotation Xrotation
      JOINT LeftAnkle
      {
        OFFSET 0 -0.4 0
        CHANNELS 3 Zrotation Yrotation Xrotation
        JOINT LeftToe
        {
          OFFSET 0 -0.05 0.1
          CHANNELS 3 Zrotation Yrotation Xrotation
          End Site
          {
            OFFSET 0 0 0.05
          }
        }
      }
    }
  }
  JOINT RightHip
  {
    OFFSET -0.1 -0.1 0
    CHANNELS 3 Zrotation Yrotation Xrotation
    JOINT RightKnee
    {
      OFFSET 0 -0.4 0
      CHANNELS 3 Zrotation Yrotation Xrotation
      JOINT RightAnkle
      {
        OFFSET 0 -0.4 0
        CHANNELS 3 Zrotation Yrotation Xrotation
        JOINT RightToe
        {
          OFFSET 0 -0.05 0.1
          CHANNELS 3 Zrotation Yrotation Xrotation
          End Site
          {
            OFFSET 0 0 0.05
          }
        }
      }
    }
  }
  JOINT Chest
  {
    OFFSET 0 0.25 0
    CHANNELS 3 Zrotation Yrotation Xrotation
    JOINT Chest2
    {
      OFFSET 0 0.25 0
      CHANNELS 3 Zrotation Yrotation Xrotation
      JOINT Neck
      {
        OFFSET 0 0.1 0
        CHANNELS 3 Zrotation Yrotation Xrotation
        JOINT Head
        {
          OFFSET 0 0.1 0
          CHANNELS 3 Zrotation Yrotation Xrotation
          End Site
          {
            OFFSET 0 0.1 0
          }
        }
      }
      JOINT LeftShoulder
      {
        OFFSET 0.18 0.08 0
        CHANNELS 3 Zrotation Yrotation Xrotation
        JOINT LeftElbow
        {
          OFFSET 0 -0.28 0
          CHANNELS 3 Zrotation Yrotation Xrotation
          JOINT LeftWrist
          {
            OFFSET 0 -0.25 0
            CHANNELS 3 Zrotation Yrotation Xrotation
            JOINT LFingers
            {
              OFFSET 0 -0.05 0
              CHANNELS 3 Zrotation Yrotation Xrotation
              End Site
              {
                OFFSET 0 -0.05 0
              }
            }
            JOINT LThumb
            {
              OFFSET 0 0 0
              CHANNELS 3 Zrotation Yrotation Xrotation
              End Site
              {
                OFFSET 0 -0.03 0.03
              }
            }
          }
        }
      }
      JOINT RightShoulder
      {
        OFFSET -0.18 0.08 0
        CHANNELS 3 Zrotation Yrotation Xrotation
        JOINT RightElbow
        {
          OFFSET 0 -0.28 0
          CHANNELS 3 Zrotation Yrotation Xrotation
          JOINT RightWrist
          {
            OFFSET 0 -0.25 0
            CHANNELS 3 Zrotation Yrotation Xrotation
            JOINT RFingers
            {
              OFFSET 0 -0.05 0
              CHANNELS 3 Zrotation Yrotation Xrotation
              End Site
              {
                OFFSET 0 -0.05 0
              }
            }
            JOINT RThumb
            {
              OFFSET 0 0 0
              CHANNELS 3 Zrotation Yrotation Xrotation
              End Site
              {
                OFFSET 0 -0.03 0.03
              }
            }
          }
        }
      }
    }
  }
}
)";
constexpr int kSyntheticChannels = 6 + 22 * 3;

// A frame line: root position + root rotation (in the root's channel order), then one rotation
// triple for LeftHip (Z Y X) and zeros elsewhere.
std::string frameLine(const double root[6], const double leftHipZYX[3] = nullptr) {
  std::string s;
  char buf[64];
  for (int i = 0; i < kSyntheticChannels; ++i) {
    double v = 0;
    if (i < 6) v = root[i];
    else if (i < 9 && leftHipZYX) v = leftHipZYX[i - 6];
    std::snprintf(buf, sizeof buf, "%s%.17g", i ? " " : "", v);
    s += buf;
  }
  return s + "\n";
}

std::string syntheticBvh(const std::vector<std::string>& frameLines,
                         const std::string& rootChannels = "Xposition Yposition Zposition Zrotation Yrotation Xrotation",
                         double frameTime = 1.0 / 30) {
  std::string h = kSyntheticHierarchy;
  h.replace(h.find("@ROOTCH@"), 8, rootChannels);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", frameTime);
  h += "MOTION\nFrames: " + std::to_string(frameLines.size()) + "\nFrame Time: " + buf + "\n";
  for (const auto& l : frameLines) h += l;
  return h;
}

Eigen::Matrix3d rot(char axis, double deg) {
  const double r = deg * 3.14159265358979323846 / 180;
  const Eigen::Vector3d a = axis == 'X' ? Eigen::Vector3d::UnitX() : axis == 'Y' ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ();
  return Eigen::AngleAxisd(r, a).toRotationMatrix();
}

Vec3 toKinect(const Eigen::Vector3d& w) { return Vec3(float(-w.x()), float(w.y()), float(3.0 - w.z())); }

// A 25-joint Kinect CSV line.
std::string csvLine(long long ticks, int state = 2, const char* x0 = "0.1") {
  std::string s = std::to_string(ticks) + ",";
  for (int j = 0; j < 25; ++j) s += std::string(j == 0 ? x0 : "0.5") + ",-0.25," + "2.5," + std::to_string(state) + ",";
  return s + "\n";
}

// ------------------------------------------------------------------------------------------
// Kinect v2 CSV, real data.

struct CsvCase {
  const char* file;
  std::size_t frames;
};
const CsvCase kCsvCases[] = {
    {"Ges01_wavehand.csv", 154},
    {"Ges02_balancinghands.csv", 161},
    {"Ges04_comehere.csv", 172},
    {"KinectReader_joints_closerange.csv", 371},
};

TEST(RecordingKinectCsv, LabanotationFilesLoad) {
  for (const CsvCase& c : kCsvCases) {
    SCOPED_TRACE(c.file);
    DRAPE_REQUIRE_SHARED(path, std::string("kinect_v2_msft_labanotation/") + c.file);
    Recording rec;
    std::string err;
    ASSERT_TRUE(readRecordingFile(path, 0, rec, err)) << err;
    EXPECT_EQ(rec.format, RecordingFormat::KinectCsv);
    EXPECT_EQ(rec.layout, Layout::Kinect2);
    ASSERT_EQ(rec.frames.size(), c.frames);
    EXPECT_NEAR(rec.nominal_rate_hz, 30.0f, 1.0f);
    EXPECT_EQ(rec.frames[0].time_s, 0.0);
    for (std::size_t i = 1; i < rec.frames.size(); ++i)
      ASSERT_GT(rec.frames[i].time_s, rec.frames[i - 1].time_s) << "frame " << i;
    for (const auto& f : rec.frames) ASSERT_EQ(f.joints.size(), 25u);
    const RecordingFrame& f0 = rec.frames[0];
    const float headAbove = P(f0, Head).y() - P(f0, SpineBase).y();
    EXPECT_GT(headAbove, 0.5f);
    EXPECT_LT(headAbove, 0.9f);
    EXPECT_GT(P(f0, SpineBase).z(), 0.5f);  // in front of the sensor
    EXPECT_LT(P(f0, SpineBase).z(), 4.5f);
    // Hint equal to the content is fine.
    Recording again;
    EXPECT_TRUE(readRecordingFile(path, static_cast<int>(Layout::Kinect2), again, err)) << err;
  }
}

double inferredFraction(const Recording& rec) {
  std::size_t inferred = 0, total = 0;
  for (const auto& f : rec.frames)
    for (const auto& j : f.joints) {
      inferred += j.state == TrackingState::Inferred;
      ++total;
    }
  return double(inferred) / double(total);
}

TEST(RecordingKinectCsv, TrackingStatesMatchReadme) {
  DRAPE_REQUIRE_SHARED(close, "kinect_v2_msft_labanotation/KinectReader_joints_closerange.csv");
  DRAPE_REQUIRE_SHARED(wave, "kinect_v2_msft_labanotation/Ges01_wavehand.csv");
  Recording rec;
  std::string err;
  ASSERT_TRUE(readRecordingFile(close, 0, rec, err)) << err;
  const double frac = inferredFraction(rec);
  EXPECT_GT(frac, 0.20);
  EXPECT_LT(frac, 0.45);
  ASSERT_TRUE(readRecordingFile(wave, 0, rec, err)) << err;
  EXPECT_EQ(std::lround(inferredFraction(rec) * 154 * 25), 13);  // README: 13 inferred samples
}

// Kinect camera space: a subject facing the sensor has its left on -X and its toes toward the sensor.
TEST(RecordingKinectCsv, SubjectFacesSensorLeftIsMinusX) {
  for (int i = 0; i < 3; ++i) {
    SCOPED_TRACE(kCsvCases[i].file);
    DRAPE_REQUIRE_SHARED(path, std::string("kinect_v2_msft_labanotation/") + kCsvCases[i].file);
    Recording rec;
    std::string err;
    ASSERT_TRUE(readRecordingFile(path, 0, rec, err)) << err;
    for (const auto& f : rec.frames) {
      ASSERT_LT(P(f, ShoulderLeft).x(), P(f, ShoulderRight).x());
      ASSERT_LT(P(f, HipLeft).x(), P(f, HipRight).x());
    }
    const auto& f0 = rec.frames[0];
    EXPECT_LT(P(f0, FootLeft).z(), P(f0, AnkleLeft).z());
    EXPECT_LT(P(f0, FootRight).z(), P(f0, AnkleRight).z());
  }
}

TEST(RecordingKinectCsv, OtherLayoutsByFieldCount) {
  for (const Layout layout : {Layout::Kinect1, Layout::Azure}) {
    const int n = layoutJointCount(layout);
    std::string text;
    for (int f = 0; f < 3; ++f) {
      text += std::to_string(1000 + f * 333333);
      for (int j = 0; j < n; ++j) text += ",0.25,-1e-1,+2.5,1";
      text += f == 1 ? "\r\n" : ",\n";  // with and without trailing comma, CRLF
    }
    Recording rec;
    std::string err;
    ASSERT_TRUE(parseRecording(text, 0, rec, err)) << err;
    EXPECT_EQ(rec.layout, layout);
    ASSERT_EQ(rec.frames.size(), 3u);
    ASSERT_EQ(rec.frames[2].joints.size(), static_cast<std::size_t>(n));
    EXPECT_NEAR(rec.frames[2].time_s, 0.0666666, 1e-9);
    EXPECT_NEAR(rec.nominal_rate_hz, 30.0f, 1e-3f);
    EXPECT_EQ(rec.frames[1].joints[3].position, Vec3(0.25f, -0.1f, 2.5f));
    EXPECT_EQ(rec.frames[1].joints[3].state, TrackingState::Inferred);
    EXPECT_TRUE(parseRecording(text, static_cast<int>(layout), rec, err)) << err;
    EXPECT_FALSE(parseRecording(text, static_cast<int>(Layout::Kinect2), rec, err));
    EXPECT_NE(err.find("contradicts"), std::string::npos) << err;
  }
}

// ------------------------------------------------------------------------------------------
// BVH: forward kinematics conventions on a synthetic skeleton.

TEST(RecordingBvh, ForwardKinematicsConvention) {
  const double root[6] = {0.5, 1.0, -0.2, 30, 40, 50};  // X Y Z pos, Z Y X rot (degrees)
  const double hip[3] = {0, 0, 90};                      // LeftHip: Xrotation 90
  Recording rec;
  std::string err;
  BvhImportInfo info;
  ASSERT_TRUE(parseBvhRecording(syntheticBvh({frameLine(root, hip), frameLine(root)}), 0, rec, err, &info)) << err;
  EXPECT_STREQ(info.unit_name, "metre");
  EXPECT_EQ(info.channel_count, kSyntheticChannels);
  EXPECT_EQ(info.joint_count, 23);
  ASSERT_EQ(rec.frames.size(), 2u);
  EXPECT_EQ(rec.format, RecordingFormat::Bvh);
  EXPECT_EQ(rec.layout, Layout::Kinect2);
  EXPECT_NEAR(rec.nominal_rate_hz, 30.0f, 1e-3f);
  EXPECT_NEAR(rec.frames[1].time_s, 1.0 / 30, 1e-12);

  const Eigen::Vector3d p(0.5, 1.0, -0.2);
  const Eigen::Matrix3d R = rot('Z', 30) * rot('Y', 40) * rot('X', 50);  // channel order Z Y X
  const Eigen::Vector3d hipW = p + R * Eigen::Vector3d(0.1, -0.1, 0);
  const Eigen::Vector3d kneeW = hipW + R * rot('X', 90) * Eigen::Vector3d(0, -0.4, 0);
  const RecordingFrame& f = rec.frames[0];
  EXPECT_TRUE(P(f, SpineBase).isApprox(toKinect(p), 1e-6f)) << P(f, SpineBase).transpose();
  EXPECT_TRUE(P(f, HipLeft).isApprox(toKinect(hipW), 1e-6f)) << P(f, HipLeft).transpose();
  EXPECT_TRUE(P(f, KneeLeft).isApprox(toKinect(kneeW), 1e-6f)) << P(f, KneeLeft).transpose();
  // Frame 1 has no hip rotation: the knee hangs straight below the hip in the root frame.
  EXPECT_TRUE(P(rec.frames[1], KneeLeft).isApprox(toKinect(hipW + R * Eigen::Vector3d(0, -0.4, 0)), 1e-6f));
  // Mapping details: SpineMid = midpoint of Chest and Chest2, SpineShoulder = Neck, Neck = Head,
  // Head = the Head's End Site, HandTip = finger End Site, Thumb = thumb End Site.
  EXPECT_TRUE(P(f, SpineMid).isApprox(toKinect(p + R * Eigen::Vector3d(0, 0.375, 0)), 1e-6f));
  EXPECT_TRUE(P(f, SpineShoulder).isApprox(toKinect(p + R * Eigen::Vector3d(0, 0.6, 0)), 1e-6f));
  EXPECT_TRUE(P(f, Neck).isApprox(toKinect(p + R * Eigen::Vector3d(0, 0.7, 0)), 1e-6f));
  EXPECT_TRUE(P(f, Head).isApprox(toKinect(p + R * Eigen::Vector3d(0, 0.8, 0)), 1e-6f));
  EXPECT_TRUE(P(f, HandTipLeft).isApprox(toKinect(p + R * Eigen::Vector3d(0.18, 0.5 + 0.08 - 0.63, 0)), 1e-6f));
  EXPECT_TRUE(P(f, ThumbRight).isApprox(toKinect(p + R * Eigen::Vector3d(-0.18, 0.5 + 0.08 - 0.56, 0.03)), 1e-6f));
  for (const auto& j : f.joints) EXPECT_EQ(j.state, TrackingState::Tracked);
}

// A skeleton whose Head has no End Site: the Head is placed as far above the CMU Head as that is
// above the CMU Neck (a neck bone again), not on the Neck joint (a zero-length Neck-Head bone),
// and a skeleton without Chest takes the midpoint of Hips and the new SpineShoulder for SpineMid.
TEST(RecordingBvh, HeadWithoutEndSiteAndNoChest) {
  const double root[6] = {0, 1.0, 0, 0, 0, 0};
  std::string text = syntheticBvh({frameLine(root)});
  const std::string tip = "          End Site\n          {\n            OFFSET 0 0.1 0\n          }\n";
  const size_t head = text.find("JOINT Head");
  ASSERT_NE(head, std::string::npos);
  const size_t at = text.find(tip, head);
  ASSERT_NE(at, std::string::npos) << "the synthetic skeleton's Head End Site moved";
  text.erase(at, tip.size());
  Recording rec;
  std::string err;
  ASSERT_TRUE(parseBvhRecording(text, 0, rec, err)) << err;
  const RecordingFrame& f = rec.frames[0];
  const Eigen::Vector3d p(0, 1.0, 0);
  EXPECT_TRUE(P(f, Neck).isApprox(toKinect(p + Eigen::Vector3d(0, 0.7, 0)), 1e-6f)) << P(f, Neck).transpose();
  EXPECT_TRUE(P(f, Head).isApprox(toKinect(p + Eigen::Vector3d(0, 0.8, 0)), 1e-6f)) << P(f, Head).transpose();
  // Without Chest (renamed: Chest2 stays Chest2's child of an unknown joint).
  std::string no_chest = syntheticBvh({frameLine(root)});
  const size_t chest = no_chest.find("JOINT Chest\n");
  ASSERT_NE(chest, std::string::npos);
  no_chest.replace(chest, 12, "JOINT Torso\n");
  ASSERT_TRUE(parseBvhRecording(no_chest, 0, rec, err)) << err;
  EXPECT_TRUE(P(rec.frames[0], SpineMid).isApprox(toKinect(p + Eigen::Vector3d(0, 0.3, 0)), 1e-6f))
      << P(rec.frames[0], SpineMid).transpose();
}

TEST(RecordingBvh, ChannelOrderIsReadPerJoint) {
  // Same numbers, declared as X Y Z rotation: R = Rx * Ry * Rz with the values read in that order.
  const double root[6] = {0, 0.9, 0, 30, 40, 50};
  Recording rec;
  std::string err;
  ASSERT_TRUE(parseRecording(syntheticBvh({frameLine(root)}, "Xposition Yposition Zposition Xrotation Yrotation Zrotation"),
                             0, rec, err))
      << err;
  const Eigen::Vector3d p(0, 0.9, 0);
  const Eigen::Matrix3d R = rot('X', 30) * rot('Y', 40) * rot('Z', 50);
  EXPECT_TRUE(P(rec.frames[0], HipRight).isApprox(toKinect(p + R * Eigen::Vector3d(-0.1, -0.1, 0)), 1e-6f));
  // Position channels after the rotations still translate the root.
  ASSERT_TRUE(parseRecording(syntheticBvh({frameLine(root)}, "Xrotation Yrotation Zrotation Xposition Yposition Zposition"),
                             0, rec, err))
      << err;
  const Eigen::Vector3d p2(30, 40, 50);
  const Eigen::Matrix3d R2 = rot('X', 0) * rot('Y', 0.9) * rot('Z', 0);
  EXPECT_TRUE(P(rec.frames[0], SpineBase).isApprox(toKinect(p2), 1e-6f)) << P(rec.frames[0], SpineBase).transpose();
  EXPECT_TRUE(P(rec.frames[0], HipRight).isApprox(toKinect(p2 + R2 * Eigen::Vector3d(-0.1, -0.1, 0)), 1e-5f));
}

TEST(RecordingBvh, SyntheticSkeletonIsUnitAware) {
  // The same synthetic skeleton written in centimetres must give the same metres.
  std::string cm = syntheticBvh({frameLine(std::array<double, 6>{50, 100, -20, 0, 10, 0}.data())});
  std::string m = syntheticBvh({frameLine(std::array<double, 6>{0.5, 1.0, -0.2, 0, 10, 0}.data())});
  // Scale every OFFSET line by 100.
  std::string scaled;
  std::istringstream in(cm);
  std::string line;
  while (std::getline(in, line)) {
    const auto k = line.find("OFFSET");
    if (k != std::string::npos) {
      std::istringstream nums(line.substr(k + 6));
      double x, y, z;
      nums >> x >> y >> z;
      line = line.substr(0, k) + "OFFSET " + std::to_string(x * 100) + " " + std::to_string(y * 100) + " " + std::to_string(z * 100);
    }
    scaled += line + "\n";
  }
  Recording a, b;
  std::string err;
  BvhImportInfo ia, ib;
  ASSERT_TRUE(parseBvhRecording(scaled, 0, a, err, &ia)) << err;
  ASSERT_TRUE(parseBvhRecording(m, 0, b, err, &ib)) << err;
  EXPECT_STREQ(ia.unit_name, "centimetre");
  EXPECT_STREQ(ib.unit_name, "metre");
  for (int j = 0; j < 25; ++j) EXPECT_TRUE(P(a.frames[0], j).isApprox(P(b.frames[0], j), 1e-5f)) << j;
}

// ------------------------------------------------------------------------------------------
// BVH: the CMU files.

struct BvhCase {
  const char* file;
  std::size_t frames;
  const char* unit;
};
const BvhCase kBvhCases[] = {
    {"131_01.bvh", 994, "cmu-unit"},
    {"131_03.bvh", 1102, "cmu-unit"},
    {"scaled_131_01.bvh", 995, "metre"},
    {"scaled_131_03.bvh", 1248, "metre"},
};

bool loadBvh(const std::string& path, Recording& rec, BvhImportInfo& info, std::string& err) {
  return parseBvhRecording(readAll(path), 0, rec, err, &info);
}

TEST(RecordingBvh, CmuFilesLoad) {
  for (const BvhCase& c : kBvhCases) {
    SCOPED_TRACE(c.file);
    DRAPE_REQUIRE_SHARED(path, std::string("cmu_mocap_bvh/") + c.file);
    Recording rec;
    std::string err;
    ASSERT_TRUE(readRecordingFile(path, 0, rec, err)) << err;
    EXPECT_EQ(rec.format, RecordingFormat::Bvh);
    EXPECT_EQ(rec.layout, Layout::Kinect2);
    ASSERT_EQ(rec.frames.size(), c.frames);
    EXPECT_NEAR(rec.nominal_rate_hz, 120.0f, 0.1f);
    EXPECT_NEAR(rec.frames.back().time_s, double(c.frames - 1) * 0.008333, 0.01);
    BvhImportInfo info;
    ASSERT_TRUE(loadBvh(path, rec, info, err)) << err;
    EXPECT_STREQ(info.unit_name, c.unit);
    EXPECT_EQ(info.joint_count, 31);
    EXPECT_EQ(info.channel_count, 6 + 30 * 3);
    // Metres: the pelvis of a standing adult is ~0.95 m above the floor (BVH y = 0).
    EXPECT_NEAR(P(rec.frames[0], SpineBase).y(), 0.95f, 0.1f);
    // Placed in front of the sensor.
    EXPECT_GT(P(rec.frames[0], SpineBase).z(), 1.5f);
    EXPECT_LT(P(rec.frames[0], SpineBase).z(), 6.0f);
    // Contradicting hint.
    EXPECT_FALSE(readRecordingFile(path, static_cast<int>(Layout::Azure), rec, err));
    EXPECT_NE(err.find("contradicts"), std::string::npos) << err;
  }
}

// Same motion in CMU units and in metres: joint positions must agree (checks the unit detection).
TEST(RecordingBvh, ScaledAndUnscaledAgree) {
  for (const char* motion : {"131_01", "131_03"}) {
    SCOPED_TRACE(motion);
    DRAPE_REQUIRE_SHARED(raw, std::string("cmu_mocap_bvh/") + motion + ".bvh");
    DRAPE_REQUIRE_SHARED(scaled, std::string("cmu_mocap_bvh/scaled_") + motion + ".bvh");
    Recording a, b;
    std::string err;
    ASSERT_TRUE(readRecordingFile(raw, 0, a, err)) << err;
    ASSERT_TRUE(readRecordingFile(scaled, 0, b, err)) << err;
    const std::size_t n = std::min(a.frames.size(), b.frames.size());
    ASSERT_GE(n, 994u);
    float worst = 0;
    for (std::size_t i = 0; i < n; ++i)
      for (int j = 0; j < 25; ++j) worst = std::max(worst, (P(a.frames[i], j) - P(b.frames[i], j)).norm());
    EXPECT_LT(worst, 0.01f);
  }
}

TEST(RecordingBvh, MappedBonesArePlausible) {
  for (const BvhCase& c : kBvhCases) {
    SCOPED_TRACE(c.file);
    DRAPE_REQUIRE_SHARED(path, std::string("cmu_mocap_bvh/") + c.file);
    Recording rec;
    std::string err;
    ASSERT_TRUE(readRecordingFile(path, 0, rec, err)) << err;
    const RecordingFrame& f0 = rec.frames[0];
    for (const auto& [a, b] : {std::pair{HipLeft, KneeLeft}, std::pair{HipRight, KneeRight}}) {
      EXPECT_GT(dist(f0, a, b), 0.35f);  // thigh
      EXPECT_LT(dist(f0, a, b), 0.50f);
    }
    for (const auto& [a, b] : {std::pair{KneeLeft, AnkleLeft}, std::pair{KneeRight, AnkleRight}}) {
      EXPECT_GT(dist(f0, a, b), 0.33f);  // shin
      EXPECT_LT(dist(f0, a, b), 0.50f);
    }
    for (const auto& [a, b] : {std::pair{ShoulderLeft, ElbowLeft}, std::pair{ShoulderRight, ElbowRight}}) {
      EXPECT_GT(dist(f0, a, b), 0.20f);  // upper arm
      EXPECT_LT(dist(f0, a, b), 0.35f);
    }
    for (const auto& [a, b] : {std::pair{ElbowLeft, WristLeft}, std::pair{ElbowRight, WristRight}}) {
      EXPECT_GT(dist(f0, a, b), 0.15f);  // forearm
      EXPECT_LT(dist(f0, a, b), 0.30f);
    }
    EXPECT_GT(dist(f0, ShoulderLeft, ShoulderRight), 0.25f);
    EXPECT_LT(dist(f0, ShoulderLeft, ShoulderRight), 0.50f);
    // Head above the pelvis, feet well below it, shoulders between.
    EXPECT_GT(P(f0, Head).y() - P(f0, SpineBase).y(), 0.3f);
    EXPECT_GT(P(f0, SpineBase).y() - P(f0, FootLeft).y(), 0.7f);
    EXPECT_GT(P(f0, SpineBase).y() - P(f0, FootRight).y(), 0.7f);
    EXPECT_GT(P(f0, ShoulderLeft).y(), P(f0, SpineMid).y());
    EXPECT_GT(P(f0, SpineShoulder).y(), P(f0, SpineMid).y());
    EXPECT_GT(P(f0, SpineMid).y(), P(f0, SpineBase).y());
    // SpineShoulder level with the shoulders, as a Kinect puts it (3.5-4 cm above them in the
    // Labanotation captures); CMU's Chest2, mapped there before, was 8 cm below them.
    const float shoulders = 0.5f * (P(f0, ShoulderLeft).y() + P(f0, ShoulderRight).y());
    std::printf("[ figures  ] %s: SpineShoulder %.3f m above the shoulders, Neck %.3f, Head %.3f; Head %.3f m above "
                "SpineBase\n",
                c.file, P(f0, SpineShoulder).y() - shoulders, P(f0, Neck).y() - shoulders, P(f0, Head).y() - shoulders,
                P(f0, Head).y() - P(f0, SpineBase).y());
    EXPECT_GT(P(f0, SpineShoulder).y(), shoulders - 0.02f);
    EXPECT_LT(P(f0, SpineShoulder).y(), shoulders + 0.06f);
    EXPECT_GT(P(f0, Neck).y(), P(f0, SpineShoulder).y() + 0.04f);
    EXPECT_GT(P(f0, Head).y(), P(f0, Neck).y() + 0.04f);
    // No two neighbouring joints of the Kinect bone tree coincide (no zero-length bones).
    const std::pair<int, int> bones[] = {{SpineBase, SpineMid}, {SpineMid, SpineShoulder}, {SpineShoulder, Neck},
                                         {Neck, Head}, {WristLeft, HandLeft}, {HandLeft, HandTipLeft},
                                         {WristLeft, ThumbLeft}, {WristRight, HandRight}, {HandRight, HandTipRight},
                                         {WristRight, ThumbRight}, {AnkleLeft, FootLeft}, {AnkleRight, FootRight},
                                         {SpineBase, HipLeft}, {SpineBase, HipRight}};
    for (const auto& [a, b] : bones) EXPECT_GT(dist(f0, a, b), 0.02f) << a << "-" << b;
    // Rigid skeleton: bone lengths stay constant over the whole take.
    for (const auto& f : rec.frames) {
      ASSERT_NEAR(dist(f, HipLeft, KneeLeft), dist(f0, HipLeft, KneeLeft), 1e-3f);
      ASSERT_NEAR(dist(f, ShoulderRight, ElbowRight), dist(f0, ShoulderRight, ElbowRight), 1e-3f);
    }
  }
}

// In Kinect camera space a subject facing the sensor has its left side at smaller x. The CMU
// files start facing +Z (BVH), i.e. toward the sensor after the conversion. The handedness test
// (left = up x forward) holds in any heading, so it also proves the "Left*" BVH joints are on the
// subject's left, and that the axis conversion is a rotation, not a mirror.
TEST(RecordingBvh, LeftIsSubjectsLeftAndFacesSensor) {
  for (const BvhCase& c : kBvhCases) {
    SCOPED_TRACE(c.file);
    DRAPE_REQUIRE_SHARED(path, std::string("cmu_mocap_bvh/") + c.file);
    Recording rec;
    std::string err;
    ASSERT_TRUE(readRecordingFile(path, 0, rec, err)) << err;
    const RecordingFrame& f0 = rec.frames[0];
    EXPECT_LT(P(f0, ShoulderLeft).x(), P(f0, ShoulderRight).x());
    EXPECT_LT(P(f0, HipLeft).x(), P(f0, HipRight).x());
    EXPECT_LT(P(f0, FootLeft).z(), P(f0, AnkleLeft).z());  // toes point at the sensor
    EXPECT_LT(P(f0, FootRight).z(), P(f0, AnkleRight).z());
    std::size_t handed = 0;
    for (const auto& f : rec.frames) {
      Vec3 forward = (P(f, FootLeft) - P(f, AnkleLeft)) + (P(f, FootRight) - P(f, AnkleRight));
      forward.y() = 0;
      const Vec3 left = Vec3::UnitY().cross(forward);
      handed += left.dot(P(f, HipLeft) - P(f, HipRight)) > 0;
    }
    EXPECT_EQ(handed, rec.frames.size());  // every frame, walking, hopping and turning included
  }
}

// ------------------------------------------------------------------------------------------
// .drec

Recording randomRecording(Layout layout, int frames, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-3.f, 5.f);
  std::uniform_int_distribution<int> st(0, 2);
  Recording r;
  r.format = RecordingFormat::KinectCsv;
  r.layout = layout;
  r.nominal_rate_hz = 29.97f;
  double t = 0.1234567890123;
  for (int i = 0; i < frames; ++i) {
    RecordingFrame f;
    f.time_s = t;
    t += 1.0 / 29.97 + 1e-9 * i;
    f.joints.resize(static_cast<std::size_t>(layoutJointCount(layout)));
    for (auto& j : f.joints) {
      const float x = pos(rng);
      const float y = pos(rng) * 1e-3f;
      const float z = pos(rng) * 1e5f;
      j.position = Vec3(x, y, z);
      j.state = static_cast<TrackingState>(st(rng));
    }
    r.frames.push_back(std::move(f));
  }
  r.frames[0].joints[0].position = Vec3(-0.0f, 1e-40f, 3.4e38f);  // -0, subnormal, near max
  r.frames[0].joints[0].state = TrackingState::Tracked;
  return r;
}

void expectSame(const Recording& a, const Recording& b) {
  EXPECT_EQ(a.layout, b.layout);
  EXPECT_EQ(a.nominal_rate_hz, b.nominal_rate_hz);
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (std::size_t i = 0; i < a.frames.size(); ++i) {
    ASSERT_EQ(a.frames[i].time_s, b.frames[i].time_s) << i;
    ASSERT_EQ(a.frames[i].joints.size(), b.frames[i].joints.size());
    for (std::size_t j = 0; j < a.frames[i].joints.size(); ++j) {
      ASSERT_EQ(a.frames[i].joints[j].position, b.frames[i].joints[j].position) << i << "/" << j;
      ASSERT_EQ(a.frames[i].joints[j].state, b.frames[i].joints[j].state) << i << "/" << j;
    }
  }
}

TEST(RecordingDrape, RoundTripIsExact) {
  for (const Layout layout : {Layout::Kinect1, Layout::Kinect2, Layout::Azure}) {
    const Recording r = randomRecording(layout, 50, 7u + static_cast<unsigned>(layout));
    const std::string text = writeDrapeRecording(r);
    ASSERT_EQ(text.rfind("drape-recording 1\n", 0), 0u);
    Recording back;
    std::string err;
    ASSERT_TRUE(parseRecording(text, 0, back, err)) << err;
    EXPECT_EQ(back.format, RecordingFormat::Drape);
    expectSame(r, back);
  }
}

TEST(RecordingDrape, FileRoundTripOfRealCsv) {
  DRAPE_REQUIRE_SHARED(path, "kinect_v2_msft_labanotation/KinectReader_joints_closerange.csv");
  Recording csv, back;
  std::string err;
  ASSERT_TRUE(readRecordingFile(path, 0, csv, err)) << err;
  const std::string out = (std::filesystem::temp_directory_path() / "drape_test_recording.drec").string();
  ASSERT_TRUE(writeDrapeRecordingFile(csv, out, err)) << err;
  ASSERT_TRUE(readRecordingFile(out, 2, back, err)) << err;
  std::filesystem::remove(out);
  EXPECT_EQ(back.format, RecordingFormat::Drape);
  expectSame(csv, back);
}

TEST(RecordingDrape, HandWrittenTextParses) {
  const std::string text =
      "\xEF\xBB\xBF"
      "drape-recording 1\r\n"
      "# a tiny two-frame Kinect v1 recording\r\n"
      "layout kinect1\n"
      "\n"
      "joints 20\n"
      "rate 15\n"
      "# frames: time, then x y z state per joint\n"
      "f 0.5 " + [] { std::string s; for (int j = 0; j < 20; ++j) s += "0.1 -0.2 2.5 2 "; return s; }() + "\n"
      "f\t0.5666 " + [] { std::string s; for (int j = 0; j < 20; ++j) s += "+1 2e-1 3 1\t"; return s; }() + "\n";
  Recording rec;
  std::string err;
  ASSERT_TRUE(parseRecording(text, 0, rec, err)) << err;
  EXPECT_EQ(rec.format, RecordingFormat::Drape);
  EXPECT_EQ(rec.layout, Layout::Kinect1);
  EXPECT_EQ(rec.nominal_rate_hz, 15.0f);
  ASSERT_EQ(rec.frames.size(), 2u);
  EXPECT_EQ(rec.frames[1].time_s, 0.5666);
  ASSERT_EQ(rec.frames[1].joints.size(), 20u);
  EXPECT_EQ(rec.frames[0].joints[19].position, Vec3(0.1f, -0.2f, 2.5f));
  EXPECT_EQ(rec.frames[1].joints[19].position, Vec3(1.f, 0.2f, 3.f));
  EXPECT_EQ(rec.frames[1].joints[19].state, TrackingState::Inferred);
  // Without a rate line the rate is 1 / median interval.
  std::string noRate = text;
  noRate.erase(noRate.find("rate 15\n"), 8);
  ASSERT_TRUE(parseRecording(noRate, 1, rec, err)) << err;
  EXPECT_NEAR(rec.nominal_rate_hz, 1 / 0.0666, 1e-3);
}

// ------------------------------------------------------------------------------------------
// Bad input: false, a specific message, `out` untouched.

void expectError(std::string_view text, const std::string& needle, int hint = 0) {
  Recording rec;
  rec.nominal_rate_hz = 123;
  std::string err;
  RecordingError kind = RecordingError::None;
  EXPECT_FALSE(parseRecording(text, hint, rec, err, &kind)) << "needle " << needle;
  EXPECT_EQ(kind, isValidLayout(hint) || hint == 0 ? RecordingError::Parse : RecordingError::InvalidArgument);
  EXPECT_NE(err.find(needle), std::string::npos) << "message: " << err;
  EXPECT_EQ(rec.nominal_rate_hz, 123.0f);
  EXPECT_TRUE(rec.frames.empty());
}

TEST(RecordingErrors, EmptyAndGarbage) {
  expectError("", "empty");
  expectError(" \n\t\r\n", "whitespace");
  expectError(std::string_view("\x00\x01\xff\xfe garbage", 12), "unrecognised");
  expectError("\x7f" "ELF\x02\x01", "\\x7fELF");
  expectError("hello,world\n", "unrecognised");
  expectError("1,2,3\n", "line 1");
  expectError(csvLine(1), "invalid layout hint", 9);
}

TEST(RecordingErrors, BadCsv) {
  std::string wrongCount = csvLine(100) + csvLine(200) + "300,1,2,3,2,\n";
  expectError(wrongCount, "line 3");
  expectError(wrongCount, "expected 101");
  expectError(csvLine(100) + csvLine(200, 7), "line 2");
  expectError(csvLine(100) + csvLine(200, 7), "'7' is not 0, 1 or 2");
  expectError(csvLine(100) + csvLine(300) + csvLine(200), "line 3: timestamp 200 goes backwards");
  expectError(csvLine(100) + csvLine(100), "line 2: timestamp 100 repeats");
  expectError(csvLine(100, 2, "nan"), "line 1");
  expectError(csvLine(100, 2, "nan"), "'nan' is not a finite number");
  expectError(csvLine(100, 2, "1e999"), "not a finite number");
  expectError(csvLine(100, 2, "1,5"), "line 1");
  expectError(csvLine(100, 2, "0x10"), "line 1");
  expectError(csvLine(100) + "\n\n" + csvLine(-5), "line 4");
  expectError(csvLine(100), "contradicts", static_cast<int>(Layout::Kinect1));
  // An empty trailing line (and blank lines) are fine.
  Recording rec;
  std::string err;
  EXPECT_TRUE(parseRecording(csvLine(100) + csvLine(433433) + "\n\n", 0, rec, err)) << err;
  EXPECT_EQ(rec.frames.size(), 2u);
  EXPECT_NEAR(rec.frames[1].time_s, 0.0433333, 1e-9);
}

TEST(RecordingErrors, BadBvh) {
  const double root[6] = {0, 1, 0, 0, 0, 0};
  const std::string good = syntheticBvh({frameLine(root), frameLine(root)});
  Recording rec;
  std::string err;
  ASSERT_TRUE(parseRecording(good, 0, rec, err)) << err;

  const std::size_t motion = good.find("MOTION");
  expectError(good.substr(0, motion), "MOTION section missing");
  expectError(good.substr(0, motion / 2), "unexpected end of file");
  expectError("HIERARCHY\n", "no ROOT");
  const std::string shortLine = good.substr(0, good.rfind(" 0\n")) + "\n";  // last frame one value short
  expectError(shortLine, "frame 1 has 71 values");
  const int lastLine = static_cast<int>(std::count(good.begin(), good.end(), '\n'));
  expectError(shortLine, "line " + std::to_string(lastLine));
  expectError(good.substr(0, good.rfind('\n', good.size() - 2) + 1), "truncated BVH");  // a frame line missing
  expectError(good + frameLine(root), "more frame lines");
  std::string bad = good;
  bad.replace(bad.find("Zrotation Yrotation Xrotation"), 9, "Wrotation");
  expectError(bad, "unknown channel 'Wrotation'");
  bad = good;
  bad.replace(bad.find("LeftKnee"), 8, "LeftKnie");
  expectError(bad, "lacks joint(s) LeftKnee");
  bad = good;
  bad.replace(bad.rfind("0 0\n"), 3, "0 x");
  expectError(bad, "'x' is not a finite number");
  expectError(good, "contradicts", static_cast<int>(Layout::Kinect1));
  expectError(good.substr(0, motion) + "MOTION\nFrames: 99999999999\nFrame Time: 0.1\n", "Frames: N");
  expectError(good.substr(0, motion) + "MOTION\nFrames: 1\nFrame Time: 0\n", "Frame Time");
}

// Every truncation of a BVH file is refused (the last value of the synthetic frames is a lone "0",
// so only the missing final newline leaves a complete file).
TEST(RecordingErrors, EveryTruncatedBvhIsRefused) {
  const double root[6] = {0.1, 1, 0.2, 10, 20, 30};
  const std::string good = syntheticBvh({frameLine(root), frameLine(root)});
  Recording rec;
  std::string err;
  ASSERT_TRUE(parseRecording(good.substr(0, good.size() - 1), 0, rec, err)) << err;
  for (std::size_t cut = 0; cut + 1 < good.size(); ++cut) {
    rec = Recording{};
    ASSERT_FALSE(parseRecording(good.substr(0, cut), 0, rec, err)) << "cut at " << cut;
    ASSERT_FALSE(err.empty()) << "cut at " << cut;
    ASSERT_TRUE(rec.frames.empty());
  }
}

TEST(RecordingErrors, BvhLimits) {
  // Deep nesting: refused, not recursed into.
  std::string deep = "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n";
  for (int i = 0; i < 100000; ++i) deep += "JOINT j\n{\nOFFSET 0 1 0\nCHANNELS 1 Xrotation\n";
  expectError(deep, "deeper than 64");
  // Too many joints.
  std::string wide = "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n";
  for (int i = 0; i < 300; ++i) wide += "JOINT j" + std::to_string(i) + "\n{\nOFFSET 0 1 0\nCHANNELS 1 Xrotation\n}\n";
  expectError(wide + "}\n", "more than 256 joints");
  // A second ROOT.
  const double root[6] = {0, 1, 0, 0, 0, 0};
  std::string two = syntheticBvh({frameLine(root)});
  const std::string hier = two.substr(0, two.find("MOTION"));
  expectError(hier + hier.substr(10), "second ROOT");
}

TEST(RecordingErrors, BadDrape) {
  const Recording r = randomRecording(Layout::Kinect2, 3, 1);
  const std::string good = writeDrapeRecording(r);
  auto replace = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  expectError(replace("drape-recording 1", "drape-recording 2"), "unsupported drape-recording version");
  expectError(replace("layout kinect2", "layout kinect9"), "unknown layout 'kinect9'");
  expectError(replace("joints 25", "joints 24"), "line 4");
  expectError(replace("rate ", "speed "), "unknown line type 'speed'");
  expectError(replace("rate 29.97", "rate -1"), "rate '-1'");
  expectError(good.substr(0, good.size() - 1) + " 1\n", "more than 100 joint values");
  expectError(good.substr(0, good.size() - 3) + "\n", "frame has 99 joint values");
  {
    std::string s = good;
    s.replace(s.find(" 2 ", s.find("\nf ")), 3, " 3 ");  // frame 0, joint 0's state
    expectError(s, "line 6: joint 0: tracking state '3'");
  }
  expectError(good + "f 0 " + std::string(100 * 2, ' ') + "\n", "not after the previous frame");
  expectError(good, "contradicts", static_cast<int>(Layout::Azure));
  expectError(good.substr(0, good.find("f ")), "no frames");
}

TEST(RecordingErrors, FilePaths) {
  Recording rec;
  std::string err;
  RecordingError kind = RecordingError::None;
  const std::string missing = "/nonexistent/drape/recording_42.csv";
  EXPECT_FALSE(readRecordingFile(missing, 0, rec, err, &kind));
  EXPECT_NE(err.find(missing), std::string::npos) << err;
  EXPECT_EQ(kind, RecordingError::Io);
  const std::string dir = std::filesystem::temp_directory_path().string();
  EXPECT_FALSE(readRecordingFile(dir, 0, rec, err, &kind));
  EXPECT_NE(err.find("not a regular file"), std::string::npos) << err;
  EXPECT_EQ(kind, RecordingError::Io);
  // Parse errors are prefixed with the path as well, and reported as Parse.
  const std::string empty = (std::filesystem::temp_directory_path() / "drape_test_empty.csv").string();
  { std::ofstream(empty).flush(); }
  EXPECT_FALSE(readRecordingFile(empty, 0, rec, err, &kind));
  EXPECT_NE(err.find(empty), std::string::npos) << err;
  EXPECT_NE(err.find("empty"), std::string::npos) << err;
  EXPECT_EQ(kind, RecordingError::Parse);
  EXPECT_FALSE(readRecordingFile(empty, 7, rec, err, &kind));
  EXPECT_EQ(kind, RecordingError::InvalidArgument) << err;
  std::filesystem::remove(empty);

  const Recording good = randomRecording(Layout::Kinect2, 2, 3);
  EXPECT_FALSE(writeDrapeRecordingFile(good, "/nonexistent/dir/out.drec", err, &kind));
  EXPECT_NE(err.find("/nonexistent/dir/out.drec"), std::string::npos) << err;
  EXPECT_EQ(kind, RecordingError::Io);
  EXPECT_FALSE(writeDrapeRecordingFile(good, dir, err, &kind));
  EXPECT_EQ(kind, RecordingError::Io) << err;
  Recording bad = good;
  bad.frames[1].joints.pop_back();
  EXPECT_FALSE(writeDrapeRecordingFile(bad, "/tmp/never_written.drec", err, &kind));
  EXPECT_NE(err.find("frame 1 has 24 joints"), std::string::npos) << err;
  EXPECT_EQ(kind, RecordingError::InvalidArgument);
  const std::string out = (std::filesystem::temp_directory_path() / "drape_test_kind.drec").string();
  EXPECT_TRUE(writeDrapeRecordingFile(good, out, err, &kind)) << err;
  EXPECT_EQ(kind, RecordingError::None);
  EXPECT_TRUE(readRecordingFile(out, 0, rec, err, &kind)) << err;
  EXPECT_EQ(kind, RecordingError::None);
  std::filesystem::remove(out);
}

TEST(RecordingFormats, DetectionAndNames) {
  EXPECT_EQ(detectRecordingFormat("\xEF\xBB\xBF  drape-recording 1\n"), RecordingFormat::Drape);
  EXPECT_EQ(detectRecordingFormat("\r\nHIERARCHY\r\nROOT"), RecordingFormat::Bvh);
  EXPECT_EQ(detectRecordingFormat("123,0.5,"), RecordingFormat::KinectCsv);
  EXPECT_EQ(detectRecordingFormat("HIERARCHYX"), RecordingFormat::Unknown);
  EXPECT_EQ(detectRecordingFormat(""), RecordingFormat::Unknown);
  EXPECT_STREQ(recordingFormatName(RecordingFormat::KinectCsv), "kinect-csv");
  EXPECT_STREQ(recordingFormatName(RecordingFormat::Bvh), "bvh");
  EXPECT_STREQ(recordingFormatName(RecordingFormat::Drape), "drape");
  EXPECT_STREQ(recordingFormatName(static_cast<RecordingFormat>(42)), "unknown");
  EXPECT_STREQ(recordingErrorName(RecordingError::Io), "io");
  EXPECT_STREQ(recordingErrorName(RecordingError::Parse), "parse");
  EXPECT_EQ(static_cast<int>(RecordingFormat::Drape), 3);
}

// Mutated and truncated inputs of every format: never a crash, always an answer (false + message
// or a consistent recording), quickly.
TEST(RecordingErrors, MutationFuzzNeverCrashes) {
  const double root[6] = {0.1, 1, 0.2, 10, 20, 30};
  const std::vector<std::string> seeds = {
      syntheticBvh({frameLine(root), frameLine(root), frameLine(root)}),
      csvLine(100) + csvLine(433433) + csvLine(766766, 1),
      writeDrapeRecording(randomRecording(Layout::Kinect1, 3, 5)),
  };
  std::mt19937 rng(1234);
  const auto start = std::chrono::steady_clock::now();
  int accepted = 0;
  for (int iter = 0; iter < 6000; ++iter) {
    std::string s = seeds[static_cast<std::size_t>(iter) % seeds.size()];
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits && !s.empty(); ++e) {
      const std::size_t at = rng() % s.size();
      switch (rng() % 5) {
        case 0: s[at] = static_cast<char>(rng() & 0xff); break;
        case 1: s.erase(at, 1 + rng() % 16); break;
        case 2: s.insert(at, 1, "{}\n ,-.e9"[rng() % 9]); break;
        case 3: s.resize(at); break;
        default: {
          const std::size_t from = rng() % s.size();
          const std::size_t len = rng() % 64;
          s.insert(at, s.substr(from, len));
          break;
        }
      }
    }
    Recording rec;
    std::string err;
    if (parseRecording(s, static_cast<int>(rng() % 4), rec, err)) {
      ++accepted;
      ASSERT_FALSE(rec.frames.empty());
      const auto n = static_cast<std::size_t>(layoutJointCount(rec.layout));
      for (std::size_t i = 0; i < rec.frames.size(); ++i) {
        ASSERT_EQ(rec.frames[i].joints.size(), n);
        if (i > 0) {
          ASSERT_GT(rec.frames[i].time_s, rec.frames[i - 1].time_s);
        }
        for (const auto& j : rec.frames[i].joints) ASSERT_TRUE(isFinite(j.position));
      }
    } else {
      ASSERT_FALSE(err.empty());
    }
  }
  EXPECT_GT(accepted, 0);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 60.0);
}

}  // namespace
}  // namespace drape
