// Helpers shared by the C ABI tests: error checks, RAII owners, synthetic skeletons in every
// layout, frame construction. Everything here goes through drape.h only.
#pragma once

#include "drape/drape.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr const char* kWaveHand = "kinect_v2_msft_labanotation/Ges01_wavehand.csv";

// ------------------------------------------------------------------------------------------
// Error checking helpers.

// Puts a known message into this thread's last error so that a later check can tell the message
// was written by the call under test (and not left over from an earlier failure).
const char* const kPrimeMessage = "drape_context_desc_init_sized: desc is NULL";
void primeLastError() {
  ASSERT_EQ(drape_context_desc_init(nullptr), DRAPE_ERROR_NULL_ARGUMENT);
  ASSERT_STREQ(drape_last_error(), kPrimeMessage);
}

std::string lastError() {
  const char* m = drape_last_error();
  return m ? std::string(m) : std::string("<drape_last_error returned NULL>");
}

// The context's backend (drape_context_get_backend_info), the struct filled with 0xAB first so a
// field the call leaves unwritten shows.
drape_backend_info backendInfo(drape_context* ctx) {
  drape_backend_info i;
  std::memset(&i, 0xAB, sizeof(i));
  i.struct_size = sizeof(i);
  EXPECT_EQ(drape_context_get_backend_info(ctx, &i), DRAPE_OK) << lastError();
  return i;
}

// `call` must fail with `code` and leave a fresh, non-empty message. When `fn` is non-null the
// message must also name that function.
::testing::AssertionResult failsWith(drape_result code, const char* fn, const std::function<drape_result()>& call,
                                     const char* text) {
  // Prime with a message that names a different function (desc_init primes for everything else;
  // the header maps it to drape_context_desc_init_sized, whose name it also prefixes).
  if (fn && std::strncmp(fn, "drape_context_desc_init", std::strlen("drape_context_desc_init")) == 0) {
    (void)drape_body_shape_init(nullptr);
  } else {
    (void)drape_context_desc_init(nullptr);
  }
  const std::string primed = lastError();
  const drape_result r = call();
  const char* raw = drape_last_error();
  const std::string msg = raw ? std::string(raw) : std::string();
  if (r != code)
    return ::testing::AssertionFailure() << text << " returned " << drape_result_name(r) << " (" << int(r)
                                         << "), expected " << drape_result_name(code) << "; message: '" << msg
                                         << "'";
  if (!raw) return ::testing::AssertionFailure() << text << ": drape_last_error() returned NULL";
  if (msg.empty()) return ::testing::AssertionFailure() << text << ": empty drape_last_error()";
  if (msg == primed)
    return ::testing::AssertionFailure() << text << ": drape_last_error() was not updated (still '" << msg << "')";
  if (fn && msg.find(fn) == std::string::npos)
    return ::testing::AssertionFailure() << text << ": message '" << msg << "' does not name " << fn;
  return ::testing::AssertionSuccess();
}

#define EXPECT_FAILS(code, fn, call) EXPECT_TRUE(failsWith((code), (fn), [&]() { return (call); }, #call))
// For errors whose message need not name the function (only be fresh and non-empty).
#define EXPECT_FAILS_MSG(code, call) EXPECT_TRUE(failsWith((code), nullptr, [&]() { return (call); }, #call))

// Streamable (the message is read after the call, when the failure is reported).
#define ASSERT_OK(call) ASSERT_EQ((call), DRAPE_OK) << #call << ": " << lastError()
#define EXPECT_OK(call) EXPECT_EQ((call), DRAPE_OK) << #call << ": " << lastError()

// ------------------------------------------------------------------------------------------
// A grown struct's inits never write past the caller's struct (drape.h's struct convention): the
// exported init fills `exported_size` bytes, the sized init the size it is given (from
// `first_size`, the first layout's, to sizeof(T)) and every byte it fills is the default's; a size
// outside that range, or a NULL struct, is refused with nothing written. Guard bytes after the
// struct in a buffer show what was written. Fills `defaults` with the whole struct's defaults.
template <class T>
void expectInitsWriteOnlyTheirSize(drape_result (*sized)(T*, uint32_t), const char* sized_name,
                                   drape_result (*exported)(T*), const char* exported_name, uint32_t first_size,
                                   uint32_t exported_size, T& defaults) {
  ASSERT_OK(sized(&defaults, static_cast<uint32_t>(sizeof(T))));
  uint32_t defaults_size = 0;
  std::memcpy(&defaults_size, &defaults, sizeof(defaults_size));
  EXPECT_EQ(defaults_size, sizeof(T));
  alignas(T) unsigned char buf[sizeof(T) + 16];
  T* t = reinterpret_cast<T*>(buf);
  auto expectFilled = [&](uint32_t size, const char* what) {
    uint32_t written = 0;
    std::memcpy(&written, buf, sizeof(written));
    EXPECT_EQ(written, size) << what;
    EXPECT_EQ(std::memcmp(buf + 4, reinterpret_cast<const unsigned char*>(&defaults) + 4, size - 4), 0) << what;
    for (size_t k = size; k < sizeof(buf); ++k) ASSERT_EQ(buf[k], 0xAB) << what << ": byte " << k << " written";
  };
  std::memset(buf, 0xAB, sizeof(buf));
  ASSERT_OK(exported(t));
  expectFilled(exported_size, exported_name);
  for (uint32_t size : {first_size, first_size + 4, exported_size, static_cast<uint32_t>(sizeof(T))}) {
    if (size > sizeof(T)) continue;
    std::memset(buf, 0xAB, sizeof(buf));
    ASSERT_OK(sized(t, size));
    expectFilled(size, sized_name);
  }
  for (uint32_t bad : {0u, first_size - 1, static_cast<uint32_t>(sizeof(T)) + 1, 0xFFFFFFFFu}) {
    std::memset(buf, 0xAB, sizeof(buf));
    EXPECT_FAILS(DRAPE_ERROR_INVALID_ARGUMENT, sized_name, sized(t, bad));
    for (size_t k = 0; k < sizeof(buf); ++k) ASSERT_EQ(buf[k], 0xAB) << "byte " << k << " written for size " << bad;
  }
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, sized_name, sized(nullptr, static_cast<uint32_t>(sizeof(T))));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, exported_name, exported(nullptr));
}

// ------------------------------------------------------------------------------------------
// RAII owners (the tests still call drape_*_destroy explicitly where that is what is tested).

struct ContextDeleter {
  void operator()(drape_context* c) const { drape_context_destroy(c); }
};
using ContextPtr = std::unique_ptr<drape_context, ContextDeleter>;
struct RecordingDeleter {
  void operator()(drape_recording* r) const { drape_recording_destroy(r); }
};
using RecordingPtr = std::unique_ptr<drape_recording, RecordingDeleter>;

ContextPtr makeContext(const drape_context_desc* desc = nullptr) {
  drape_context* c = nullptr;
  const drape_result r = drape_context_create(desc, &c);
  EXPECT_EQ(r, DRAPE_OK) << lastError();
  EXPECT_NE(c, nullptr);
  return ContextPtr(r == DRAPE_OK ? c : nullptr);
}

// ------------------------------------------------------------------------------------------
// Synthetic skeletons: a person standing ~2.5 m in front of the sensor, facing it (+Y up, the
// subject's right at +X), written by hand in each sensor layout's own joint order.

struct V {
  float x, y, z;
};

// Kinect v2 (JointType order), metres. `t` animates a small sway and an arm swing.
std::array<V, 25> kinect2Pose(double t) {
  const float sway = 0.03f * static_cast<float>(std::sin(1.3 * t));
  const float swing = 0.08f * static_cast<float>(std::sin(2.1 * t));
  const float z = 2.5f;
  std::array<V, 25> p{};
  p[0] = {0.00f, 0.00f, z};            // SpineBase
  p[1] = {0.00f, 0.30f, z};            // SpineMid
  p[2] = {0.00f, 0.60f, z};            // Neck
  p[3] = {0.00f, 0.75f, z - 0.02f};    // Head
  p[4] = {-0.18f, 0.50f, z};           // ShoulderLeft
  p[5] = {-0.24f, 0.24f, z + swing};   // ElbowLeft
  p[6] = {-0.27f, 0.01f, z - 0.02f + swing};  // WristLeft
  p[7] = {-0.28f, -0.06f, z - 0.03f + swing}; // HandLeft
  p[8] = {0.18f, 0.50f, z};            // ShoulderRight
  p[9] = {0.24f, 0.24f, z - swing};    // ElbowRight
  p[10] = {0.27f, 0.01f, z - 0.02f - swing};  // WristRight
  p[11] = {0.28f, -0.06f, z - 0.03f - swing}; // HandRight
  p[12] = {-0.08f, -0.02f, z};         // HipLeft
  p[13] = {-0.09f, -0.45f, z + 0.02f}; // KneeLeft
  p[14] = {-0.09f, -0.85f, z + 0.05f}; // AnkleLeft
  p[15] = {-0.09f, -0.92f, z - 0.05f}; // FootLeft
  p[16] = {0.08f, -0.02f, z};          // HipRight
  p[17] = {0.09f, -0.45f, z + 0.02f};  // KneeRight
  p[18] = {0.09f, -0.85f, z + 0.05f};  // AnkleRight
  p[19] = {0.09f, -0.92f, z - 0.05f};  // FootRight
  p[20] = {0.00f, 0.52f, z};           // SpineShoulder
  p[21] = {-0.29f, -0.14f, z - 0.03f + swing};  // HandTipLeft
  p[22] = {-0.25f, -0.08f, z - 0.07f + swing};  // ThumbLeft
  p[23] = {0.29f, -0.14f, z - 0.03f - swing};   // HandTipRight
  p[24] = {0.25f, -0.08f, z - 0.07f - swing};   // ThumbRight
  for (V& v : p) v.x += sway;
  return p;
}

std::vector<drape_joint> toJoints(const V* p, size_t n) {
  std::vector<drape_joint> j(n);
  for (size_t i = 0; i < n; ++i) {
    j[i].position = drape_vec3{p[i].x, p[i].y, p[i].z};
    j[i].tracking_state = DRAPE_TRACKING_TRACKED;
  }
  return j;
}

V mid(V a, V b, float f = 0.5f) { return V{a.x + f * (b.x - a.x), a.y + f * (b.y - a.y), a.z + f * (b.z - a.z)}; }

// The same pose in each layout (Kinect v1: 20 joints, NUI order; Azure: 32 joints, k4abt order in
// metres; points the Kinect v2 lacks are placed by hand).
std::vector<drape_joint> poseJoints(drape_layout layout, double t) {
  const std::array<V, 25> k = kinect2Pose(t);
  if (layout == DRAPE_LAYOUT_KINECT2) return toJoints(k.data(), k.size());
  if (layout == DRAPE_LAYOUT_KINECT1) {
    // HipCenter, Spine, ShoulderCenter, Head, then shoulders..feet as Kinect v2 4..19.
    std::array<V, 20> v1{};
    v1[0] = k[0];
    v1[1] = k[1];
    v1[2] = k[20];
    v1[3] = k[3];
    for (int i = 4; i < 20; ++i) v1[i] = k[i];
    return toJoints(v1.data(), v1.size());
  }
  // Azure Kinect.
  std::array<V, 32> a{};
  a[0] = k[0];                     // PELVIS
  a[1] = k[1];                     // SPINE_NAVEL
  a[2] = mid(k[1], k[20]);         // SPINE_CHEST
  a[3] = k[2];                     // NECK
  a[4] = mid(k[20], k[4], 0.3f);   // CLAVICLE_LEFT
  a[5] = k[4];                     // SHOULDER_LEFT
  a[6] = k[5];                     // ELBOW_LEFT
  a[7] = k[6];                     // WRIST_LEFT
  a[8] = k[7];                     // HAND_LEFT
  a[9] = k[21];                    // HANDTIP_LEFT
  a[10] = k[22];                   // THUMB_LEFT
  a[11] = mid(k[20], k[8], 0.3f);  // CLAVICLE_RIGHT
  a[12] = k[8];                    // SHOULDER_RIGHT
  a[13] = k[9];                    // ELBOW_RIGHT
  a[14] = k[10];                   // WRIST_RIGHT
  a[15] = k[11];                   // HAND_RIGHT
  a[16] = k[23];                   // HANDTIP_RIGHT
  a[17] = k[24];                   // THUMB_RIGHT
  for (int i = 0; i < 8; ++i) a[18 + i] = k[12 + i];  // HIP_LEFT .. FOOT_RIGHT
  a[26] = k[3];                                        // HEAD
  const V h = k[3];
  a[27] = {h.x, h.y - 0.01f, h.z - 0.09f};             // NOSE
  a[28] = {h.x - 0.032f, h.y + 0.03f, h.z - 0.07f};    // EYE_LEFT
  a[29] = {h.x - 0.075f, h.y, h.z + 0.01f};            // EAR_LEFT
  a[30] = {h.x + 0.032f, h.y + 0.03f, h.z - 0.07f};    // EYE_RIGHT
  a[31] = {h.x + 0.075f, h.y, h.z + 0.01f};            // EAR_RIGHT
  return toJoints(a.data(), a.size());
}

uint32_t jointCount(drape_layout layout) {
  return layout == DRAPE_LAYOUT_KINECT1 ? 20u : layout == DRAPE_LAYOUT_KINECT2 ? 25u : 32u;
}

drape_skeleton_frame makeFrame(drape_layout layout, const std::vector<drape_joint>& joints, double t,
                               const drape_quat* orientations = nullptr) {
  drape_skeleton_frame f;
  std::memset(&f, 0, sizeof(f));
  f.struct_size = sizeof(drape_skeleton_frame);
  f.layout = layout;
  f.joint_count = static_cast<uint32_t>(joints.size());
  f.reserved = 0;
  f.timestamp_s = t;
  f.joints = joints.data();
  f.orientations = orientations;
  return f;
}

}  // namespace
