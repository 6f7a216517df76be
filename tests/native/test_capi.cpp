// The C ABI (include/drape/drape.h) as a host sees it: every entry point called directly, only
// through its C signature. The standard held here: every C entry point checks its arguments (null,
// sizes, NaN/Inf, out-of-range enums, wrong call order) and returns an error code with a message
// retrievable afterwards; nothing the caller owns is lost or corrupted, and a rejected call leaves
// the context's state bit for bit as it was.
#include "drape/drape.h"

#include "test_data.h"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "capi_test_support.h"

namespace {

// ------------------------------------------------------------------------------------------
// Reading results back.

// Everything a host reads back after an update: the body mesh and the tracking ellipsoids.
struct Mesh {
  std::vector<drape_vec3> positions, normals;
  std::vector<uint32_t> indices;
  std::vector<drape_ellipsoid> ellipsoids;
  std::vector<float> matrices;  // 16 per ellipsoid
};

::testing::AssertionResult bitIdentical(const Mesh& a, const Mesh& b) {
  if (a.positions.size() != b.positions.size() || a.indices.size() != b.indices.size())
    return ::testing::AssertionFailure() << "mesh sizes differ";
  if (std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(drape_vec3)) != 0)
    return ::testing::AssertionFailure() << "positions differ";
  if (std::memcmp(a.normals.data(), b.normals.data(), a.normals.size() * sizeof(drape_vec3)) != 0)
    return ::testing::AssertionFailure() << "normals differ";
  if (std::memcmp(a.indices.data(), b.indices.data(), a.indices.size() * sizeof(uint32_t)) != 0)
    return ::testing::AssertionFailure() << "indices differ";
  if (a.ellipsoids.size() != b.ellipsoids.size() || a.matrices.size() != b.matrices.size())
    return ::testing::AssertionFailure() << "ellipsoid counts differ";
  if (std::memcmp(a.ellipsoids.data(), b.ellipsoids.data(), a.ellipsoids.size() * sizeof(drape_ellipsoid)) != 0)
    return ::testing::AssertionFailure() << "ellipsoids differ";
  if (std::memcmp(a.matrices.data(), b.matrices.data(), a.matrices.size() * sizeof(float)) != 0)
    return ::testing::AssertionFailure() << "ellipsoid matrices differ";
  return ::testing::AssertionSuccess();
}

void readEllipsoidsInto(drape_context* c, Mesh& m) {
  uint32_t n = 0, got = 0, gotM = 0;
  EXPECT_EQ(drape_context_get_ellipsoid_count(c, &n), DRAPE_OK) << lastError();
  m.ellipsoids.resize(n);
  m.matrices.resize(16 * size_t{n});
  EXPECT_EQ(drape_context_read_ellipsoids(c, m.ellipsoids.data(), n, &got), DRAPE_OK) << lastError();
  EXPECT_EQ(drape_context_read_ellipsoid_matrices(c, m.matrices.data(), n, &gotM), DRAPE_OK) << lastError();
  EXPECT_EQ(got, n);
  EXPECT_EQ(gotM, n);
}

bool ellipsoidsFinite(const Mesh& m) {
  for (const drape_ellipsoid& e : m.ellipsoids) {
    const float* f = &e.centre.x;
    for (int k = 0; k < 15; ++k)
      if (!std::isfinite(f[k])) return false;
  }
  for (float f : m.matrices)
    if (!std::isfinite(f)) return false;
  return true;
}

Mesh readMesh(drape_context* c) {
  Mesh m;
  uint32_t nv = 0, ni = 0;
  EXPECT_EQ(drape_context_get_body_mesh_size(c, &nv, &ni), DRAPE_OK) << lastError();
  m.positions.resize(nv);
  m.normals.resize(nv);
  m.indices.resize(ni);
  EXPECT_EQ(drape_context_read_body_mesh(c, m.positions.data(), m.normals.data(), nv, m.indices.data(), ni),
            DRAPE_OK)
      << lastError();
  readEllipsoidsInto(c, m);
  return m;
}

bool allFinite(const std::vector<drape_vec3>& v) {
  for (const drape_vec3& p : v)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return false;
  return true;
}

drape_frame_stats stats(drape_context* c) {
  drape_frame_stats s;
  std::memset(&s, 0, sizeof(s));
  s.struct_size = sizeof(s);
  EXPECT_EQ(drape_context_get_frame_stats(c, &s), DRAPE_OK) << lastError();
  return s;
}

drape_body_shape getShape(drape_context* c) {
  drape_body_shape s;
  std::memset(&s, 0, sizeof(s));
  s.struct_size = sizeof(s);
  EXPECT_EQ(drape_context_get_body_shape(c, &s), DRAPE_OK) << lastError();
  return s;
}

// Pushes frame i of the synthetic sequence (30 Hz) and updates.
void pushAndUpdate(drape_context* c, drape_layout layout, int i) {
  const double t = i / 30.0;
  const std::vector<drape_joint> j = poseJoints(layout, t);
  const drape_skeleton_frame f = makeFrame(layout, j, t);
  EXPECT_EQ(drape_context_push_skeleton(c, &f), DRAPE_OK) << "frame " << i << ": " << lastError();
  EXPECT_EQ(drape_context_update(c), DRAPE_OK) << "frame " << i << ": " << lastError();
}

template <typename T>
void fillSentinel(std::vector<T>& v) {
  std::memset(v.data(), 0xA5, v.size() * sizeof(T));
}
template <typename T>
bool isSentinel(const std::vector<T>& v) {
  const auto* b = reinterpret_cast<const unsigned char*>(v.data());
  for (size_t i = 0; i < v.size() * sizeof(T); ++i)
    if (b[i] != 0xA5) return false;
  return true;
}

drape_context* const kContextSentinel = reinterpret_cast<drape_context*>(uintptr_t{0xDEADBEE0});
drape_recording* const kRecordingSentinel = reinterpret_cast<drape_recording*>(uintptr_t{0xDEADBEE0});

// A file name in the temp folder no other test run uses at the same time.
std::string tempPath(const std::string& name) {
  static const std::string unique = std::to_string(std::random_device{}()) + "_" +
                                    std::to_string(std::chrono::steady_clock::now().time_since_epoch().count());
  return (std::filesystem::temp_directory_path() / ("drape_capi_" + unique + "_" + name)).string();
}

// ==========================================================================================
// Results, errors, version.

TEST(Capi, ResultNameForEveryCode) {
  const std::pair<drape_result, const char*> names[] = {
      {DRAPE_OK, "DRAPE_OK"},
      {DRAPE_ERROR_NULL_ARGUMENT, "DRAPE_ERROR_NULL_ARGUMENT"},
      {DRAPE_ERROR_INVALID_ARGUMENT, "DRAPE_ERROR_INVALID_ARGUMENT"},
      {DRAPE_ERROR_INVALID_HANDLE, "DRAPE_ERROR_INVALID_HANDLE"},
      {DRAPE_ERROR_BUFFER_TOO_SMALL, "DRAPE_ERROR_BUFFER_TOO_SMALL"},
      {DRAPE_ERROR_NONFINITE, "DRAPE_ERROR_NONFINITE"},
      {DRAPE_ERROR_OUT_OF_RANGE, "DRAPE_ERROR_OUT_OF_RANGE"},
      {DRAPE_ERROR_CALL_ORDER, "DRAPE_ERROR_CALL_ORDER"},
      {DRAPE_ERROR_TIMESTAMP, "DRAPE_ERROR_TIMESTAMP"},
      {DRAPE_ERROR_IO, "DRAPE_ERROR_IO"},
      {DRAPE_ERROR_PARSE, "DRAPE_ERROR_PARSE"},
      {DRAPE_ERROR_OUT_OF_MEMORY, "DRAPE_ERROR_OUT_OF_MEMORY"},
      {DRAPE_ERROR_INTERNAL, "DRAPE_ERROR_INTERNAL"},
  };
  for (const auto& [code, name] : names) {
    const char* got = drape_result_name(code);
    ASSERT_NE(got, nullptr) << int(code);
    EXPECT_STREQ(got, name);
  }
  // Unknown values: never NULL, and not the name of a real code.
  for (int unknown : {13, 99, -1, 0x7fffffff}) {
    const char* got = drape_result_name(static_cast<drape_result>(unknown));
    ASSERT_NE(got, nullptr) << unknown;
    EXPECT_GT(std::strlen(got), 0u);
    for (const auto& [code, name] : names) EXPECT_STRNE(got, name) << unknown << " named like code " << int(code);
  }
}

TEST(Capi, Version) {
  const uint32_t v = drape_version();
  EXPECT_EQ(v >> 22, static_cast<uint32_t>(DRAPE_VERSION_MAJOR));
  EXPECT_EQ((v >> 12) & 0x3ffu, static_cast<uint32_t>(DRAPE_VERSION_MINOR));
  EXPECT_EQ(v & 0xfffu, static_cast<uint32_t>(DRAPE_VERSION_PATCH));
  EXPECT_EQ(v, DRAPE_VERSION);
  EXPECT_EQ(DRAPE_MAKE_VERSION(1, 2, 3), (1u << 22) | (2u << 12) | 3u);
  const char* s = drape_version_string();
  ASSERT_NE(s, nullptr);
  char expected[64];
  std::snprintf(expected, sizeof(expected), "%d.%d.%d", DRAPE_VERSION_MAJOR, DRAPE_VERSION_MINOR, DRAPE_VERSION_PATCH);
  EXPECT_STREQ(s, expected);
  EXPECT_EQ(drape_version_string(), s) << "the version string is static";
}

TEST(Capi, LastErrorIsEmptyOnAFreshThreadAndSurvivesSuccess) {
  std::string fresh = "<not run>";
  std::thread([&] { fresh = lastError(); }).join();
  EXPECT_EQ(fresh, "");
  primeLastError();
  // A success does not clear the message of the earlier failure (drape.h: "last failed call").
  drape_context_desc d;
  ASSERT_OK(drape_context_desc_init(&d));
  EXPECT_STREQ(drape_last_error(), kPrimeMessage);
}

// ==========================================================================================
// NULL arguments, for every pointer of every function.

TEST(Capi, NullArgumentsAreRejectedWithTheFunctionNamed) {
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_desc_init", drape_context_desc_init(nullptr));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_body_shape_init", drape_body_shape_init(nullptr));

  drape_context_desc desc;
  ASSERT_OK(drape_context_desc_init(&desc));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_create", drape_context_create(&desc, nullptr));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_create", drape_context_create(nullptr, nullptr));

  drape_body_shape shape;
  ASSERT_OK(drape_body_shape_init(&shape));
  drape_frame_stats st;
  std::memset(&st, 0, sizeof(st));
  st.struct_size = sizeof(st);
  const std::vector<drape_joint> joints = poseJoints(DRAPE_LAYOUT_KINECT2, 0.0);
  const drape_skeleton_frame frame = makeFrame(DRAPE_LAYOUT_KINECT2, joints, 0.0);
  drape_vec3 pos[64];
  uint32_t nv = 0, ni = 0, idx[64];

  // A NULL context, for every context function (destroy(NULL) is OK, tested separately).
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_set_body_shape", drape_context_set_body_shape(nullptr, &shape));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_get_body_shape", drape_context_get_body_shape(nullptr, &shape));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_push_skeleton", drape_context_push_skeleton(nullptr, &frame));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_update", drape_context_update(nullptr));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_read_skeleton", drape_context_read_skeleton(nullptr, pos, 64, &nv));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_get_body_mesh_size",
               drape_context_get_body_mesh_size(nullptr, &nv, &ni));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_read_body_mesh",
               drape_context_read_body_mesh(nullptr, pos, nullptr, 64, idx, 64));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_get_frame_stats", drape_context_get_frame_stats(nullptr, &st));
  drape_ellipsoid ell[4];
  float mats[64];
  drape_proxy_fidelity fid;
  std::memset(&fid, 0, sizeof(fid));
  fid.struct_size = sizeof(fid);
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_get_ellipsoid_count", drape_context_get_ellipsoid_count(nullptr, &nv));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_read_ellipsoids", drape_context_read_ellipsoids(nullptr, ell, 4, &nv));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_read_ellipsoid_matrices",
               drape_context_read_ellipsoid_matrices(nullptr, mats, 4, &nv));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_measure_proxy_fidelity",
               drape_context_measure_proxy_fidelity(nullptr, &fid));

  // A live context, NULL for every other pointer.
  ContextPtr ctx = makeContext();
  drape_context* c = ctx.get();
  ASSERT_NE(c, nullptr);
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_set_body_shape", drape_context_set_body_shape(c, nullptr));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_get_body_shape", drape_context_get_body_shape(c, nullptr));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_push_skeleton", drape_context_push_skeleton(c, nullptr));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_read_skeleton", drape_context_read_skeleton(c, nullptr, 64, &nv));
  // "One of the two out pointers may be NULL, not both."
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_get_body_mesh_size",
               drape_context_get_body_mesh_size(c, nullptr, nullptr));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_read_body_mesh",
               drape_context_read_body_mesh(c, nullptr, nullptr, 64, nullptr, 64));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_get_frame_stats", drape_context_get_frame_stats(c, nullptr));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_get_ellipsoid_count", drape_context_get_ellipsoid_count(c, nullptr));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_read_ellipsoids", drape_context_read_ellipsoids(c, nullptr, 1000, &nv));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_read_ellipsoid_matrices",
               drape_context_read_ellipsoid_matrices(c, nullptr, 1000, &nv));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_measure_proxy_fidelity",
               drape_context_measure_proxy_fidelity(c, nullptr));
  {
    // NULL joints inside an otherwise valid frame.
    drape_skeleton_frame f = frame;
    f.joints = nullptr;
    EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_push_skeleton", drape_context_push_skeleton(c, &f));
  }
  {
    // Both NULL pushes count as rejected frames (drape.h, drape_context_push_skeleton).
    drape_frame_stats s;
    std::memset(&s, 0, sizeof(s));
    s.struct_size = sizeof(s);
    ASSERT_OK(drape_context_get_frame_stats(c, &s));
    EXPECT_EQ(s.frames_rejected, 2u);
    EXPECT_EQ(s.frames_pushed, 2u);
    EXPECT_EQ(s.frames_accepted, 0u);
  }
  // Either out pointer of the size query may be NULL on its own.
  nv = ni = 0;
  EXPECT_OK(drape_context_get_body_mesh_size(c, &nv, nullptr));
  EXPECT_OK(drape_context_get_body_mesh_size(c, nullptr, &ni));
  EXPECT_GT(nv, 0u);
  EXPECT_GT(ni, 0u);
  EXPECT_EQ(ni % 3, 0u);

  // Recordings.
  drape_recording* rec = kRecordingSentinel;
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_recording_open", drape_recording_open(nullptr, 0, &rec));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_recording_open", drape_recording_open("/nonexistent.csv", 0, nullptr));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_recording_open_memory", drape_recording_open_memory(nullptr, 10, 0, &rec));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_recording_open_memory", drape_recording_open_memory("1,2", 3, 0, nullptr));
  EXPECT_EQ(rec, kRecordingSentinel) << "a failed open wrote *out_recording";
  drape_recording_info info;
  std::memset(&info, 0, sizeof(info));
  info.struct_size = sizeof(info);
  drape_joint jbuf[32];
  double ts = 0;
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_recording_get_info", drape_recording_get_info(nullptr, &info));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_recording_read_frame", drape_recording_read_frame(nullptr, 0, jbuf, 32, &ts));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_recording_save", drape_recording_save(nullptr, "/tmp/x.drec"));

  // A live recording (from memory, so no shared data is needed), NULL for every other pointer.
  std::string csv = "1000000";
  for (int j = 0; j < 25; ++j) csv += ",0.1,0.2,2.5,2";
  csv += ",\n2000000";
  for (int j = 0; j < 25; ++j) csv += ",0.1,0.2,2.5,2";
  csv += ",\n";
  drape_recording* r = nullptr;
  ASSERT_OK(drape_recording_open_memory(csv.data(), csv.size(), DRAPE_LAYOUT_AUTO, &r));
  RecordingPtr owner(r);
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_recording_get_info", drape_recording_get_info(r, nullptr));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_recording_read_frame", drape_recording_read_frame(r, 0, nullptr, 32, &ts));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_recording_save", drape_recording_save(r, nullptr));
  // out_timestamp_s is optional.
  EXPECT_OK(drape_recording_read_frame(r, 1, jbuf, 32, nullptr));
  ts = -1;
  EXPECT_OK(drape_recording_read_frame(r, 1, jbuf, 32, &ts));
  EXPECT_NEAR(ts, 0.1, 1e-9);
  // out_count of read_skeleton is optional (after an update).
  ASSERT_OK(drape_context_push_skeleton(c, &frame));
  ASSERT_OK(drape_context_update(c));
  drape_vec3 sk[21];
  EXPECT_OK(drape_context_read_skeleton(c, sk, 21, nullptr));
}

TEST(Capi, DestroyNullIsOk) {
  EXPECT_EQ(drape_context_destroy(nullptr), DRAPE_OK);
  EXPECT_EQ(drape_recording_destroy(nullptr), DRAPE_OK);
}

// ==========================================================================================
// Stale and foreign handles.

void expectEveryContextFunctionRejects(drape_context* bad, const char* what) {
  SCOPED_TRACE(what);
  drape_body_shape shape;
  ASSERT_OK(drape_body_shape_init(&shape));
  drape_body_shape outShape = shape;
  drape_frame_stats st;
  std::memset(&st, 0, sizeof(st));
  st.struct_size = sizeof(st);
  const std::vector<drape_joint> joints = poseJoints(DRAPE_LAYOUT_KINECT2, 0.0);
  const drape_skeleton_frame frame = makeFrame(DRAPE_LAYOUT_KINECT2, joints, 0.0);
  std::vector<drape_vec3> pos(4096), nrm(4096);
  std::vector<uint32_t> idx(1 << 16);
  uint32_t nv = 7, ni = 7;
  fillSentinel(pos);
  fillSentinel(idx);
  const drape_result H = DRAPE_ERROR_INVALID_HANDLE;
  EXPECT_FAILS(H, "drape_context_set_body_shape", drape_context_set_body_shape(bad, &shape));
  EXPECT_FAILS(H, "drape_context_get_body_shape", drape_context_get_body_shape(bad, &outShape));
  EXPECT_FAILS(H, "drape_context_push_skeleton", drape_context_push_skeleton(bad, &frame));
  EXPECT_FAILS(H, "drape_context_update", drape_context_update(bad));
  EXPECT_FAILS(H, "drape_context_read_skeleton", drape_context_read_skeleton(bad, pos.data(), 4096, &nv));
  EXPECT_FAILS(H, "drape_context_get_body_mesh_size", drape_context_get_body_mesh_size(bad, &nv, &ni));
  EXPECT_FAILS(H, "drape_context_read_body_mesh",
               drape_context_read_body_mesh(bad, pos.data(), nrm.data(), 4096, idx.data(), 1 << 16));
  EXPECT_FAILS(H, "drape_context_get_frame_stats", drape_context_get_frame_stats(bad, &st));
  std::vector<drape_ellipsoid> ell(256);
  std::vector<float> mats(16 * 256);
  fillSentinel(ell);
  fillSentinel(mats);
  drape_proxy_fidelity fid;
  std::memset(&fid, 0x5A, sizeof(fid));
  fid.struct_size = sizeof(fid);
  const drape_proxy_fidelity fidBefore = fid;
  EXPECT_FAILS(H, "drape_context_get_ellipsoid_count", drape_context_get_ellipsoid_count(bad, &nv));
  EXPECT_FAILS(H, "drape_context_read_ellipsoids", drape_context_read_ellipsoids(bad, ell.data(), 256, &ni));
  EXPECT_FAILS(H, "drape_context_read_ellipsoid_matrices",
               drape_context_read_ellipsoid_matrices(bad, mats.data(), 256, &ni));
  EXPECT_FAILS(H, "drape_context_measure_proxy_fidelity", drape_context_measure_proxy_fidelity(bad, &fid));
  EXPECT_TRUE(isSentinel(ell));
  EXPECT_TRUE(isSentinel(mats));
  EXPECT_EQ(std::memcmp(&fid, &fidBefore, sizeof(fid)), 0);
  EXPECT_FAILS(H, "drape_context_destroy", drape_context_destroy(bad));
  // Nothing the caller owns was touched.
  EXPECT_EQ(nv, 7u);
  EXPECT_EQ(ni, 7u);
  EXPECT_TRUE(isSentinel(pos));
  EXPECT_TRUE(isSentinel(idx));
  EXPECT_EQ(std::memcmp(&outShape, &shape, sizeof(shape)), 0);
}

void expectEveryRecordingFunctionRejects(drape_recording* bad, const char* what) {
  SCOPED_TRACE(what);
  drape_recording_info info;
  std::memset(&info, 0x5A, sizeof(info));
  info.struct_size = sizeof(info);
  const drape_recording_info before = info;
  std::vector<drape_joint> joints(32);
  fillSentinel(joints);
  double ts = 123.0;
  const std::string path = tempPath("stale.drec");
  const drape_result H = DRAPE_ERROR_INVALID_HANDLE;
  EXPECT_FAILS(H, "drape_recording_get_info", drape_recording_get_info(bad, &info));
  EXPECT_FAILS(H, "drape_recording_read_frame", drape_recording_read_frame(bad, 0, joints.data(), 32, &ts));
  EXPECT_FAILS(H, "drape_recording_save", drape_recording_save(bad, path.c_str()));
  EXPECT_FAILS(H, "drape_recording_destroy", drape_recording_destroy(bad));
  EXPECT_EQ(std::memcmp(&info, &before, sizeof(info)), 0);
  EXPECT_TRUE(isSentinel(joints));
  EXPECT_EQ(ts, 123.0);
  EXPECT_FALSE(std::filesystem::exists(path)) << "save through a bad handle created " << path;
}

TEST(Capi, StaleAndForeignContextHandlesAreRejected) {
  // Destroyed.
  drape_context* c = nullptr;
  ASSERT_OK(drape_context_create(nullptr, &c));
  ASSERT_OK(drape_context_destroy(c));
  expectEveryContextFunctionRejects(c, "destroyed context");

  // Never created: the address of a local, and a pointer into the middle of a heap block.
  alignas(16) unsigned char local[256];
  std::memset(local, 0, sizeof(local));
  expectEveryContextFunctionRejects(reinterpret_cast<drape_context*>(local), "address of a local");
  auto heap = std::make_unique<uint64_t[]>(64);
  expectEveryContextFunctionRejects(reinterpret_cast<drape_context*>(heap.get() + 3), "heap pointer");
  for (unsigned char b : local) ASSERT_EQ(b, 0) << "the library wrote through a foreign handle";

  // A live recording handle is not a context.
  std::string csv = "0";
  for (int j = 0; j < 25; ++j) csv += ",0,0,2,2";
  csv += "\n";
  drape_recording* r = nullptr;
  ASSERT_OK(drape_recording_open_memory(csv.data(), csv.size(), 0, &r));
  RecordingPtr owner(r);
  expectEveryContextFunctionRejects(reinterpret_cast<drape_context*>(r), "recording passed as a context");
  // ... and the recording is still alive and intact after all that.
  drape_recording_info info;
  std::memset(&info, 0, sizeof(info));
  info.struct_size = sizeof(info);
  EXPECT_OK(drape_recording_get_info(r, &info));
  EXPECT_EQ(info.frame_count, 1u);
}

TEST(Capi, StaleAndForeignRecordingHandlesAreRejected) {
  std::string csv = "0";
  for (int j = 0; j < 25; ++j) csv += ",0,0,2,2";
  csv += "\n";
  drape_recording* r = nullptr;
  ASSERT_OK(drape_recording_open_memory(csv.data(), csv.size(), 0, &r));
  ASSERT_OK(drape_recording_destroy(r));
  expectEveryRecordingFunctionRejects(r, "destroyed recording");

  alignas(16) unsigned char local[256];
  std::memset(local, 0, sizeof(local));
  expectEveryRecordingFunctionRejects(reinterpret_cast<drape_recording*>(local), "address of a local");
  for (unsigned char b : local) ASSERT_EQ(b, 0);

  ContextPtr ctx = makeContext();
  expectEveryRecordingFunctionRejects(reinterpret_cast<drape_recording*>(ctx.get()), "context passed as a recording");
  // The context survived being passed as a recording (destroy included).
  uint32_t nv = 0;
  EXPECT_OK(drape_context_get_body_mesh_size(ctx.get(), &nv, nullptr));
  EXPECT_GT(nv, 0u);
}

// ==========================================================================================
// struct_size.

TEST(Capi, StructSizeTooSmallIsRejected) {
  // Below the desc's first layout (DRAPE_CONTEXT_DESC_SIZE_V1; sizes from it up are accepted).
  for (uint32_t bad : {0u, 4u, DRAPE_CONTEXT_DESC_SIZE_V1 - 1}) {
    SCOPED_TRACE(bad);
    drape_context_desc d;
    ASSERT_OK(drape_context_desc_init(&d));
    d.struct_size = bad;
    drape_context* out = kContextSentinel;
    EXPECT_FAILS_MSG(DRAPE_ERROR_INVALID_ARGUMENT, drape_context_create(&d, &out));
    EXPECT_EQ(out, kContextSentinel);
    EXPECT_NE(lastError().find("struct_size"), std::string::npos) << lastError();
  }

  ContextPtr ctx = makeContext();
  drape_context* c = ctx.get();
  const drape_body_shape before = getShape(c);
  for (uint32_t bad : {0u, static_cast<uint32_t>(sizeof(drape_body_shape) - 1)}) {
    SCOPED_TRACE(bad);
    drape_body_shape s;
    ASSERT_OK(drape_body_shape_init(&s));
    s.height_m = 1.9f;  // would change the shape if accepted
    s.struct_size = bad;
    EXPECT_FAILS_MSG(DRAPE_ERROR_INVALID_ARGUMENT, drape_context_set_body_shape(c, &s));
    const drape_body_shape after = getShape(c);
    EXPECT_EQ(std::memcmp(&before, &after, sizeof(before)), 0);

    drape_body_shape out;
    std::memset(&out, 0x5A, sizeof(out));
    out.struct_size = bad;
    const drape_body_shape outBefore = out;
    EXPECT_FAILS_MSG(DRAPE_ERROR_INVALID_ARGUMENT, drape_context_get_body_shape(c, &out));
    EXPECT_EQ(std::memcmp(&out, &outBefore, sizeof(out)), 0) << "get_body_shape wrote into a rejected struct";
  }
  for (uint32_t bad : {0u, static_cast<uint32_t>(sizeof(drape_frame_stats) - 1)}) {
    SCOPED_TRACE(bad);
    drape_frame_stats s;
    std::memset(&s, 0x5A, sizeof(s));
    s.struct_size = bad;
    const drape_frame_stats sBefore = s;
    EXPECT_FAILS_MSG(DRAPE_ERROR_INVALID_ARGUMENT, drape_context_get_frame_stats(c, &s));
    EXPECT_EQ(std::memcmp(&s, &sBefore, sizeof(s)), 0);
  }
  for (uint32_t bad : {0u, static_cast<uint32_t>(sizeof(drape_proxy_fidelity) - 1)}) {
    SCOPED_TRACE(bad);
    drape_proxy_fidelity f;
    std::memset(&f, 0x5A, sizeof(f));
    f.struct_size = bad;
    const drape_proxy_fidelity fBefore = f;
    EXPECT_FAILS_MSG(DRAPE_ERROR_INVALID_ARGUMENT, drape_context_measure_proxy_fidelity(c, &f));
    EXPECT_EQ(std::memcmp(&f, &fBefore, sizeof(f)), 0);
  }
  const std::vector<drape_joint> joints = poseJoints(DRAPE_LAYOUT_KINECT2, 0.0);
  for (uint32_t bad : {0u, static_cast<uint32_t>(sizeof(drape_skeleton_frame) - 1)}) {
    SCOPED_TRACE(bad);
    drape_skeleton_frame f = makeFrame(DRAPE_LAYOUT_KINECT2, joints, 0.0);
    f.struct_size = bad;
    EXPECT_FAILS_MSG(DRAPE_ERROR_INVALID_ARGUMENT, drape_context_push_skeleton(c, &f));
  }
  // The rejected frames were not queued, and (drape.h: "A rejected frame (NULL, bad struct_size,
  // ...) ... is counted in drape_frame_stats.frames_rejected") they were counted.
  EXPECT_FAILS(DRAPE_ERROR_CALL_ORDER, "drape_context_update", drape_context_update(c));
  const drape_frame_stats s = stats(c);
  EXPECT_EQ(s.frames_accepted, 0u);
  EXPECT_EQ(s.frames_rejected, 2u);
  EXPECT_EQ(s.frames_pushed, 2u);

  std::string csv = "0";
  for (int j = 0; j < 25; ++j) csv += ",0,0,2,2";
  csv += "\n";
  drape_recording* r = nullptr;
  ASSERT_OK(drape_recording_open_memory(csv.data(), csv.size(), 0, &r));
  RecordingPtr owner(r);
  for (uint32_t bad : {0u, static_cast<uint32_t>(sizeof(drape_recording_info) - 1)}) {
    SCOPED_TRACE(bad);
    drape_recording_info info;
    std::memset(&info, 0x5A, sizeof(info));
    info.struct_size = bad;
    const drape_recording_info infoBefore = info;
    EXPECT_FAILS_MSG(DRAPE_ERROR_INVALID_ARGUMENT, drape_recording_get_info(r, &info));
    EXPECT_EQ(std::memcmp(&info, &infoBefore, sizeof(info)), 0);
  }
}

// ==========================================================================================
// Context desc.

TEST(Capi, DescInitFillsDocumentedDefaults) {
  drape_context_desc d;
  std::memset(&d, 0x5A, sizeof(d));
  ASSERT_OK(drape_context_desc_init(&d));
  EXPECT_EQ(d.struct_size, sizeof(drape_context_desc));
  EXPECT_EQ(d.ring_points, 20u);
  EXPECT_EQ(d.rings_per_segment, 1u);
  EXPECT_EQ(d.calibration_frames, 30u);
  EXPECT_EQ(d.filter, DRAPE_FILTER_ONE_EURO);
  EXPECT_EQ(d.proxy_rule, DRAPE_PROXY_RULE_DRAPE);
  EXPECT_EQ(d.garment_fit, DRAPE_GARMENT_FIT_SHAPE);
  EXPECT_EQ(d.arms_clear_torso, 1);
  EXPECT_FLOAT_EQ(d.arm_torso_clearance_m, 0.01f);
  EXPECT_FLOAT_EQ(d.teleport_distance_m, 0.5f);
  EXPECT_GT(d.filter_min_cutoff_hz, 0.0f);
  EXPECT_GE(d.filter_beta, 0.0f);
  EXPECT_GT(d.filter_d_cutoff_hz, 0.0f);
  EXPECT_GE(d.smoothing, 0.0f);
  EXPECT_LT(d.smoothing, 1.0f);
  drape_context* c = nullptr;
  ASSERT_OK(drape_context_create(&d, &c));
  ContextPtr owner(c);
  // desc = NULL means the same defaults: same mesh size.
  ContextPtr dflt = makeContext(nullptr);
  uint32_t a = 0, b = 0, ai = 0, bi = 0;
  ASSERT_OK(drape_context_get_body_mesh_size(c, &a, &ai));
  ASSERT_OK(drape_context_get_body_mesh_size(dflt.get(), &b, &bi));
  EXPECT_EQ(a, b);
  EXPECT_EQ(ai, bi);
}

TEST(Capi, EveryDescFieldOutOfRangeOrNonFiniteIsRejected) {
  struct Case {
    const char* name;
    std::function<void(drape_context_desc&)> edit;
    drape_result code;
  };
  const drape_result R = DRAPE_ERROR_OUT_OF_RANGE, N = DRAPE_ERROR_NONFINITE;
  std::vector<Case> cases = {
      {"ring_points 0", [](drape_context_desc& d) { d.ring_points = 0; }, R},
      {"ring_points 4", [](drape_context_desc& d) { d.ring_points = 4; }, R},
      {"ring_points 10 (not a multiple of 4)", [](drape_context_desc& d) { d.ring_points = 10; }, R},
      {"ring_points 260", [](drape_context_desc& d) { d.ring_points = 260; }, R},
      {"ring_points 0xffffffff", [](drape_context_desc& d) { d.ring_points = 0xffffffffu; }, R},
      {"rings_per_segment 17", [](drape_context_desc& d) { d.rings_per_segment = 17; }, R},
      {"rings_per_segment 0xffffffff", [](drape_context_desc& d) { d.rings_per_segment = 0xffffffffu; }, R},
      {"calibration_frames 0", [](drape_context_desc& d) { d.calibration_frames = 0; }, R},
      {"calibration_frames 100001", [](drape_context_desc& d) { d.calibration_frames = 100001; }, R},
      {"filter -1", [](drape_context_desc& d) { d.filter = -1; }, R},
      {"filter 3", [](drape_context_desc& d) { d.filter = 3; }, R},
      {"filter FORCE32", [](drape_context_desc& d) { d.filter = DRAPE_FILTER_FORCE32; }, R},
      {"filter_min_cutoff_hz 0", [](drape_context_desc& d) { d.filter_min_cutoff_hz = 0; }, R},
      {"filter_min_cutoff_hz -1", [](drape_context_desc& d) { d.filter_min_cutoff_hz = -1; }, R},
      {"filter_min_cutoff_hz NaN", [](drape_context_desc& d) { d.filter_min_cutoff_hz = kNaN; }, N},
      {"filter_min_cutoff_hz Inf", [](drape_context_desc& d) { d.filter_min_cutoff_hz = kInf; }, N},
      {"filter_min_cutoff_hz 0.0005", [](drape_context_desc& d) { d.filter_min_cutoff_hz = 0.0005f; }, R},
      {"filter_min_cutoff_hz 1000.5", [](drape_context_desc& d) { d.filter_min_cutoff_hz = 1000.5f; }, R},
      {"filter_beta 1000.5", [](drape_context_desc& d) { d.filter_beta = 1000.5f; }, R},
      {"filter_d_cutoff_hz 1001", [](drape_context_desc& d) { d.filter_d_cutoff_hz = 1001.0f; }, R},
      {"smoothing 0.9995", [](drape_context_desc& d) { d.smoothing = 0.9995f; }, R},
      {"jitter_radius_m 10.5", [](drape_context_desc& d) { d.jitter_radius_m = 10.5f; }, R},
      {"max_deviation_m 10.5", [](drape_context_desc& d) { d.max_deviation_m = 10.5f; }, R},
      {"filter_beta -0.1", [](drape_context_desc& d) { d.filter_beta = -0.1f; }, R},
      {"filter_beta NaN", [](drape_context_desc& d) { d.filter_beta = kNaN; }, N},
      {"filter_beta Inf", [](drape_context_desc& d) { d.filter_beta = kInf; }, N},
      {"filter_d_cutoff_hz 0", [](drape_context_desc& d) { d.filter_d_cutoff_hz = 0; }, R},
      {"filter_d_cutoff_hz -2", [](drape_context_desc& d) { d.filter_d_cutoff_hz = -2; }, R},
      {"filter_d_cutoff_hz NaN", [](drape_context_desc& d) { d.filter_d_cutoff_hz = kNaN; }, N},
      {"filter_d_cutoff_hz -Inf", [](drape_context_desc& d) { d.filter_d_cutoff_hz = -kInf; }, N},
      {"smoothing 1", [](drape_context_desc& d) { d.smoothing = 1.0f; }, R},
      {"smoothing -0.01", [](drape_context_desc& d) { d.smoothing = -0.01f; }, R},
      {"smoothing NaN", [](drape_context_desc& d) { d.smoothing = kNaN; }, N},
      {"correction 1.01", [](drape_context_desc& d) { d.correction = 1.01f; }, R},
      {"correction -0.01", [](drape_context_desc& d) { d.correction = -0.01f; }, R},
      {"correction NaN", [](drape_context_desc& d) { d.correction = kNaN; }, N},
      {"prediction 10.5", [](drape_context_desc& d) { d.prediction = 10.5f; }, R},
      {"prediction -1", [](drape_context_desc& d) { d.prediction = -1; }, R},
      {"prediction Inf", [](drape_context_desc& d) { d.prediction = kInf; }, N},
      {"jitter_radius_m -0.01", [](drape_context_desc& d) { d.jitter_radius_m = -0.01f; }, R},
      {"jitter_radius_m NaN", [](drape_context_desc& d) { d.jitter_radius_m = kNaN; }, N},
      {"max_deviation_m -0.01", [](drape_context_desc& d) { d.max_deviation_m = -0.01f; }, R},
      {"max_deviation_m NaN", [](drape_context_desc& d) { d.max_deviation_m = kNaN; }, N},
      {"arms_clear_torso -1", [](drape_context_desc& d) { d.arms_clear_torso = -1; }, R},
      {"arms_clear_torso 2", [](drape_context_desc& d) { d.arms_clear_torso = 2; }, R},
      {"arm_torso_clearance_m -0.001", [](drape_context_desc& d) { d.arm_torso_clearance_m = -0.001f; }, R},
      {"arm_torso_clearance_m 0.0501", [](drape_context_desc& d) { d.arm_torso_clearance_m = 0.0501f; }, R},
      {"arm_torso_clearance_m NaN", [](drape_context_desc& d) { d.arm_torso_clearance_m = kNaN; }, N},
      {"arm_torso_clearance_m -Inf", [](drape_context_desc& d) { d.arm_torso_clearance_m = -kInf; }, N},
      {"teleport_distance_m 0", [](drape_context_desc& d) { d.teleport_distance_m = 0; }, R},
      {"teleport_distance_m -1", [](drape_context_desc& d) { d.teleport_distance_m = -1; }, R},
      {"teleport_distance_m 100.5", [](drape_context_desc& d) { d.teleport_distance_m = 100.5f; }, R},
      {"teleport_distance_m NaN", [](drape_context_desc& d) { d.teleport_distance_m = kNaN; }, N},
      {"teleport_distance_m Inf", [](drape_context_desc& d) { d.teleport_distance_m = kInf; }, N},
      {"proxy_rule -1", [](drape_context_desc& d) { d.proxy_rule = -1; }, R},
      {"proxy_rule 2", [](drape_context_desc& d) { d.proxy_rule = 2; }, R},
      {"proxy_rule FORCE32", [](drape_context_desc& d) { d.proxy_rule = DRAPE_PROXY_RULE_FORCE32; }, R},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.name);
    drape_context_desc d;
    ASSERT_OK(drape_context_desc_init(&d));
    k.edit(d);
    const drape_context_desc copy = d;
    drape_context* out = kContextSentinel;
    EXPECT_FAILS(k.code, "drape_context_create", drape_context_create(&d, &out));
    EXPECT_EQ(out, kContextSentinel) << "*out_context was written by a failed create";
    EXPECT_EQ(std::memcmp(&d, &copy, sizeof(d)), 0) << "create modified the caller's desc";
  }
  // The edges of every documented range are accepted (so the rejections above are about range,
  // not about the field being touched at all).
  std::vector<Case> edges = {
      {"ring_points 8", [](drape_context_desc& d) { d.ring_points = 8; }, DRAPE_OK},
      {"ring_points 256", [](drape_context_desc& d) { d.ring_points = 256; }, DRAPE_OK},
      {"rings_per_segment 0", [](drape_context_desc& d) { d.rings_per_segment = 0; }, DRAPE_OK},
      {"rings_per_segment 16", [](drape_context_desc& d) { d.rings_per_segment = 16; }, DRAPE_OK},
      {"calibration_frames 1", [](drape_context_desc& d) { d.calibration_frames = 1; }, DRAPE_OK},
      {"calibration_frames 100000", [](drape_context_desc& d) { d.calibration_frames = 100000; }, DRAPE_OK},
      {"filter NONE", [](drape_context_desc& d) { d.filter = DRAPE_FILTER_NONE; }, DRAPE_OK},
      {"filter DOUBLE_EXPONENTIAL", [](drape_context_desc& d) { d.filter = DRAPE_FILTER_DOUBLE_EXPONENTIAL; }, DRAPE_OK},
      {"filter_beta 0", [](drape_context_desc& d) { d.filter_beta = 0; }, DRAPE_OK},
      {"smoothing 0", [](drape_context_desc& d) { d.smoothing = 0; }, DRAPE_OK},
      // 0.999f (what a host writes into this float field) is 0.99900001 > 0.999: accepted
      // because validateContextDesc compares as float (it once compared as double and refused it).
      {"smoothing 0.999", [](drape_context_desc& d) { d.smoothing = 0.999f; }, DRAPE_OK},
      {"filter_min_cutoff_hz 0.001", [](drape_context_desc& d) { d.filter_min_cutoff_hz = 0.001f; }, DRAPE_OK},
      {"filter_min_cutoff_hz 1000", [](drape_context_desc& d) { d.filter_min_cutoff_hz = 1000.0f; }, DRAPE_OK},
      {"filter_beta 1000", [](drape_context_desc& d) { d.filter_beta = 1000.0f; }, DRAPE_OK},
      {"filter_d_cutoff_hz 0.001", [](drape_context_desc& d) { d.filter_d_cutoff_hz = 0.001f; }, DRAPE_OK},
      {"filter_d_cutoff_hz 1000", [](drape_context_desc& d) { d.filter_d_cutoff_hz = 1000.0f; }, DRAPE_OK},
      {"jitter_radius_m 10", [](drape_context_desc& d) { d.jitter_radius_m = 10.0f; }, DRAPE_OK},
      {"max_deviation_m 10", [](drape_context_desc& d) { d.max_deviation_m = 10.0f; }, DRAPE_OK},
      {"correction 0", [](drape_context_desc& d) { d.correction = 0; }, DRAPE_OK},
      {"correction 1", [](drape_context_desc& d) { d.correction = 1; }, DRAPE_OK},
      {"prediction 0", [](drape_context_desc& d) { d.prediction = 0; }, DRAPE_OK},
      {"prediction 10", [](drape_context_desc& d) { d.prediction = 10; }, DRAPE_OK},
      {"jitter_radius_m 0", [](drape_context_desc& d) { d.jitter_radius_m = 0; }, DRAPE_OK},
      {"max_deviation_m 0", [](drape_context_desc& d) { d.max_deviation_m = 0; }, DRAPE_OK},
      {"teleport_distance_m 100", [](drape_context_desc& d) { d.teleport_distance_m = 100; }, DRAPE_OK},
      {"teleport_distance_m 0.01", [](drape_context_desc& d) { d.teleport_distance_m = 0.01f; }, DRAPE_OK},
      {"proxy_rule PAPER", [](drape_context_desc& d) { d.proxy_rule = DRAPE_PROXY_RULE_PAPER; }, DRAPE_OK},
      {"proxy_rule DRAPE", [](drape_context_desc& d) { d.proxy_rule = DRAPE_PROXY_RULE_DRAPE; }, DRAPE_OK},
      {"arms_clear_torso 0", [](drape_context_desc& d) { d.arms_clear_torso = 0; }, DRAPE_OK},
      {"arm_torso_clearance_m 0", [](drape_context_desc& d) { d.arm_torso_clearance_m = 0; }, DRAPE_OK},
      {"arm_torso_clearance_m 0.05", [](drape_context_desc& d) { d.arm_torso_clearance_m = 0.05f; }, DRAPE_OK},
  };
  for (const Case& k : edges) {
    SCOPED_TRACE(k.name);
    drape_context_desc d;
    ASSERT_OK(drape_context_desc_init(&d));
    k.edit(d);
    drape_context* out = nullptr;
    EXPECT_OK(drape_context_create(&d, &out));
    EXPECT_NE(out, nullptr);
    EXPECT_OK(drape_context_destroy(out));
  }
}

// The arm clearance (drape_context_desc.arms_clear_torso, arm_torso_clearance_m) moves only the
// arms' ellipsoids, and a desc of the first layout (struct_size DRAPE_CONTEXT_DESC_SIZE_V1, the
// bytes after it whatever the caller's memory holds) gets the defaults of the fields after it.
TEST(Capi, ArmClearanceMovesOnlyTheArmsAndAFirstLayoutDescGetsItsDefaults) {
  auto ellipsoidsAfter = [](const drape_context_desc* d) {
    drape_context* c = nullptr;
    EXPECT_OK(drape_context_create(d, &c));
    ContextPtr owner(c);
    for (int i = 0; i < 3; ++i) pushAndUpdate(c, DRAPE_LAYOUT_KINECT2, i);
    Mesh m;
    readEllipsoidsInto(c, m);
    return m.ellipsoids;
  };
  drape_context_desc d;
  ASSERT_OK(drape_context_desc_init(&d));
  const std::vector<drape_ellipsoid> dflt = ellipsoidsAfter(&d);
  d.arms_clear_torso = 0;
  const std::vector<drape_ellipsoid> off = ellipsoidsAfter(&d);
  d.arms_clear_torso = 1;
  d.arm_torso_clearance_m = 0.03f;
  const std::vector<drape_ellipsoid> wide = ellipsoidsAfter(&d);
  ASSERT_EQ(dflt.size(), off.size());
  ASSERT_EQ(dflt.size(), wide.size());
  auto dist = [](const drape_vec3& a, const drape_vec3& b) {
    return std::sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z));
  };
  float moved = 0.0f, moved_wide = 0.0f;
  for (size_t k = 0; k < dflt.size(); ++k) {
    SCOPED_TRACE(k);
    const bool arm = dflt[k].chain == 2 || dflt[k].chain == 3;
    if (!arm) {
      // Torso, head and legs: the same to the bit whatever the arms do.
      EXPECT_EQ(std::memcmp(&dflt[k], &off[k], sizeof(drape_ellipsoid)), 0);
      EXPECT_EQ(std::memcmp(&dflt[k], &wide[k], sizeof(drape_ellipsoid)), 0);
      continue;
    }
    moved = std::max(moved, dist(dflt[k].centre, off[k].centre));
    moved_wide = std::max(moved_wide, dist(wide[k].centre, off[k].centre));
  }
  // The synthetic pose hangs the arms against the torso (shoulders 18 cm from the spine): the
  // default 1 cm gap moves some arm ellipsoid, a 3 cm gap moves it farther.
  EXPECT_GT(moved, 0.002f);
  EXPECT_GT(moved_wide, moved + 0.01f);
  std::printf("[ figures  ] arm ellipsoids moved off the bones by up to %.1f mm (1 cm gap), %.1f mm (3 cm)\n",
              1000.0f * moved, 1000.0f * moved_wide);

  // A caller built against the first layout: struct_size 64, then whatever its memory holds
  // where the later fields are (here arms_clear_torso 0x5A5A5A5A, out of range if it were read).
  drape_context_desc v1;
  ASSERT_OK(drape_context_desc_init(&v1));
  v1.struct_size = DRAPE_CONTEXT_DESC_SIZE_V1;
  std::memset(reinterpret_cast<unsigned char*>(&v1) + DRAPE_CONTEXT_DESC_SIZE_V1, 0x5A,
              sizeof(v1) - DRAPE_CONTEXT_DESC_SIZE_V1);
  const std::vector<drape_ellipsoid> first = ellipsoidsAfter(&v1);
  ASSERT_EQ(first.size(), dflt.size());
  EXPECT_EQ(std::memcmp(first.data(), dflt.data(), dflt.size() * sizeof(drape_ellipsoid)), 0)
      << "a first-layout desc did not get the arm clearance's defaults";
}

// The exported drape_context_desc_init, which hosts built before the sized init call with a
// 72-byte struct (the header's drape_context_desc_init is the sized init with the caller's
// sizeof): taken past the header's macro.
#pragma push_macro("drape_context_desc_init")
#undef drape_context_desc_init
drape_result (*const kExportedContextDescInit)(drape_context_desc*) = &drape_context_desc_init;
#pragma pop_macro("drape_context_desc_init")

// No init writes past the caller's struct: the exported init fills the 72 bytes the struct had
// when the sized init came, the sized one the size it is given (the first layout's 64 up to this
// header's sizeof), and a size outside that range writes nothing. A first-layout host's init and
// struct make a context with the later fields' defaults.
TEST(Capi, ContextDescInitNeverWritesPastTheCallersStruct) {
  drape_context_desc full;
  expectInitsWriteOnlyTheirSize(&drape_context_desc_init_sized, "drape_context_desc_init_sized",
                                kExportedContextDescInit, "drape_context_desc_init", DRAPE_CONTEXT_DESC_SIZE_V1,
                                72u, full);
  if (HasFatalFailure()) return;
  alignas(drape_context_desc) unsigned char buf[sizeof(drape_context_desc) + 16];
  auto* d = reinterpret_cast<drape_context_desc*>(buf);
  // A first-layout host: its 64 bytes filled by the sized init, guard bytes after them where the
  // later fields are (arms_clear_torso 0xABABABAB, out of range if it were read): accepted, and
  // the body the default desc's.
  std::memset(buf, 0xAB, sizeof(buf));
  ASSERT_OK(drape_context_desc_init_sized(d, DRAPE_CONTEXT_DESC_SIZE_V1));
  drape_context* first = nullptr;
  ASSERT_OK(drape_context_create(d, &first)) << lastError();
  ContextPtr first_ctx(first);
  ContextPtr dflt_ctx = makeContext(&full);
  pushAndUpdate(first_ctx.get(), DRAPE_LAYOUT_KINECT2, 0);
  pushAndUpdate(dflt_ctx.get(), DRAPE_LAYOUT_KINECT2, 0);
  const Mesh a = readMesh(first_ctx.get()), b = readMesh(dflt_ctx.get());
  ASSERT_EQ(a.positions.size(), b.positions.size());
  EXPECT_EQ(std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(a.positions[0])), 0);
}

TEST(Capi, MeshSizeFollowsTheDesc) {
  drape_context_desc d;
  ASSERT_OK(drape_context_desc_init(&d));
  d.ring_points = 8;
  d.rings_per_segment = 0;
  ContextPtr small = makeContext(&d);
  d.ring_points = 32;
  d.rings_per_segment = 2;
  ContextPtr big = makeContext(&d);
  uint32_t nvS = 0, niS = 0, nvB = 0, niB = 0;
  ASSERT_OK(drape_context_get_body_mesh_size(small.get(), &nvS, &niS));
  ASSERT_OK(drape_context_get_body_mesh_size(big.get(), &nvB, &niB));
  EXPECT_GT(nvB, nvS);
  EXPECT_GT(niB, niS);
  // Fixed for a context: the same before and after updates.
  pushAndUpdate(big.get(), DRAPE_LAYOUT_KINECT2, 0);
  uint32_t nv2 = 0, ni2 = 0;
  ASSERT_OK(drape_context_get_body_mesh_size(big.get(), &nv2, &ni2));
  EXPECT_EQ(nv2, nvB);
  EXPECT_EQ(ni2, niB);
  const Mesh m = readMesh(big.get());
  for (uint32_t i : m.indices) ASSERT_LT(i, nvB);
  EXPECT_TRUE(allFinite(m.positions));
  EXPECT_TRUE(allFinite(m.normals));
}

// ==========================================================================================
// Body shape.

TEST(Capi, BodyShapeDefaultsAndPrediction) {
  drape_body_shape init;
  std::memset(&init, 0x5A, sizeof(init));
  ASSERT_OK(drape_body_shape_init(&init));
  EXPECT_EQ(init.struct_size, sizeof(drape_body_shape));
  EXPECT_EQ(init.sex, DRAPE_SEX_UNSPECIFIED);
  EXPECT_FLOAT_EQ(init.height_m, 1.70f);
  EXPECT_FLOAT_EQ(init.weight_kg, 65.0f);
  const float* g = &init.neck_mm;
  for (int i = 0; i < 8; ++i) EXPECT_EQ(g[i], 0.0f) << "girth " << i << " should be 0 (= predict)";

  ContextPtr ctx = makeContext();
  const drape_body_shape s = getShape(ctx.get());
  EXPECT_EQ(s.struct_size, sizeof(drape_body_shape));
  EXPECT_EQ(s.sex, DRAPE_SEX_UNSPECIFIED);
  EXPECT_FLOAT_EQ(s.height_m, 1.70f);
  EXPECT_FLOAT_EQ(s.weight_kg, 65.0f);
  const float* sg = &s.neck_mm;
  for (int i = 0; i < 8; ++i) {
    EXPECT_TRUE(std::isfinite(sg[i]));
    EXPECT_GT(sg[i], 50.0f) << "predicted girth " << i;
    EXPECT_LT(sg[i], 3000.0f) << "predicted girth " << i;
  }
  // Plausible ordering for an adult: neck < chest, calf < thigh, forearm < upper arm.
  EXPECT_LT(s.neck_mm, s.chest_mm);
  EXPECT_LT(s.calf_mm, s.thigh_mm);
  EXPECT_LT(s.forearm_mm, s.upper_arm_mm);
}

TEST(Capi, BodyShapeValidSetChangesItAndGivenGirthsComeBackAsGiven) {
  ContextPtr ctx = makeContext();
  drape_context* c = ctx.get();
  for (int i = 0; i < 35; ++i) pushAndUpdate(c, DRAPE_LAYOUT_KINECT2, i);
  const Mesh before = readMesh(c);
  const drape_body_shape dflt = getShape(c);

  drape_body_shape s;
  ASSERT_OK(drape_body_shape_init(&s));
  s.sex = DRAPE_SEX_FEMALE;
  s.height_m = 1.62f;
  s.weight_kg = 80.0f;
  s.chest_mm = 1040.0f;
  s.hip_mm = 1123.5f;
  s.calf_mm = 371.3f;
  ASSERT_OK(drape_context_set_body_shape(c, &s));
  const drape_body_shape got = getShape(c);
  EXPECT_EQ(got.sex, DRAPE_SEX_FEMALE);
  EXPECT_EQ(got.height_m, 1.62f);
  EXPECT_EQ(got.weight_kg, 80.0f);
  // Given girths are returned exactly as given (drape.h; a float round trip through metres would
  // give 1040.00012 and 371.300018 here - 850 happens to survive, hence these values).
  EXPECT_EQ(got.chest_mm, 1040.0f);
  EXPECT_EQ(got.hip_mm, 1123.5f);
  EXPECT_EQ(got.calf_mm, 371.3f);
  // The others are predicted for the new height/weight: non-zero and different from the default
  // person's (80 kg vs 65 kg).
  const float* gg = &got.neck_mm;
  const float* dg = &dflt.neck_mm;
  for (int i : {0, 2, 4, 6, 7}) {
    EXPECT_GT(gg[i], 50.0f) << "girth " << i;
    EXPECT_NE(gg[i], dg[i]) << "girth " << i << " not re-predicted";
  }
  // The next update (even without a new frame) rebuilds the body with the new shape.
  ASSERT_OK(drape_context_update(c));
  const Mesh after = readMesh(c);
  EXPECT_FALSE(bitIdentical(before, after)) << "the body mesh did not change with the shape";
  EXPECT_TRUE(allFinite(after.positions));
  // Sex MALE is accepted and reported.
  s.sex = DRAPE_SEX_MALE;
  ASSERT_OK(drape_context_set_body_shape(c, &s));
  EXPECT_EQ(getShape(c).sex, DRAPE_SEX_MALE);
}

TEST(Capi, RejectedBodyShapeKeepsThePreviousShapeExactly) {
  ContextPtr ctx = makeContext();
  drape_context* c = ctx.get();
  drape_body_shape valid;
  ASSERT_OK(drape_body_shape_init(&valid));
  valid.height_m = 1.80f;
  valid.weight_kg = 75.0f;
  valid.waist_mm = 850.0f;
  ASSERT_OK(drape_context_set_body_shape(c, &valid));
  for (int i = 0; i < 35; ++i) pushAndUpdate(c, DRAPE_LAYOUT_KINECT2, i);
  const drape_body_shape before = getShape(c);
  const Mesh meshBefore = readMesh(c);

  struct Case {
    const char* name;
    std::function<void(drape_body_shape&)> edit;
    drape_result code;
  };
  const drape_result R = DRAPE_ERROR_OUT_OF_RANGE, N = DRAPE_ERROR_NONFINITE;
  std::vector<Case> cases = {
      {"height NaN", [](drape_body_shape& s) { s.height_m = kNaN; }, N},
      {"height Inf", [](drape_body_shape& s) { s.height_m = kInf; }, N},
      {"height 0.5", [](drape_body_shape& s) { s.height_m = 0.5f; }, R},
      {"height 3.0", [](drape_body_shape& s) { s.height_m = 3.0f; }, R},
      {"height -1.7", [](drape_body_shape& s) { s.height_m = -1.7f; }, R},
      {"weight NaN", [](drape_body_shape& s) { s.weight_kg = kNaN; }, N},
      {"weight -Inf", [](drape_body_shape& s) { s.weight_kg = -kInf; }, N},
      {"weight 10", [](drape_body_shape& s) { s.weight_kg = 10.0f; }, R},
      {"weight 400", [](drape_body_shape& s) { s.weight_kg = 400.0f; }, R},
      {"sex 7", [](drape_body_shape& s) { s.sex = 7; }, R},
      {"sex -1", [](drape_body_shape& s) { s.sex = -1; }, R},
      {"sex FORCE32", [](drape_body_shape& s) { s.sex = DRAPE_SEX_FORCE32; }, R},
  };
  const char* girthNames[8] = {"neck", "chest", "waist", "hip", "thigh", "calf", "upper_arm", "forearm"};
  for (int gi = 0; gi < 8; ++gi) {
    for (float v : {20.0f, 5000.0f, -5.0f, 49.9f, 3000.5f}) {
      cases.push_back({girthNames[gi], [gi, v](drape_body_shape& s) { (&s.neck_mm)[gi] = v; }, R});
    }
    for (float v : {kNaN, kInf, -kInf}) {
      cases.push_back({girthNames[gi], [gi, v](drape_body_shape& s) { (&s.neck_mm)[gi] = v; }, N});
    }
  }
  for (const Case& k : cases) {
    SCOPED_TRACE(k.name);
    drape_body_shape s;
    ASSERT_OK(drape_body_shape_init(&s));
    s.height_m = 1.55f;  // otherwise valid and different from the shape in use
    s.weight_kg = 50.0f;
    k.edit(s);
    EXPECT_FAILS_MSG(k.code, drape_context_set_body_shape(c, &s));
    const drape_body_shape after = getShape(c);
    EXPECT_EQ(std::memcmp(&before, &after, sizeof(before)), 0) << "the shape changed after a rejected set";
  }
  // Not even the mesh changes: update (no new frame) and compare bit for bit.
  ASSERT_OK(drape_context_update(c));
  EXPECT_TRUE(bitIdentical(meshBefore, readMesh(c)));
  // Girth edges are accepted.
  drape_body_shape edge;
  ASSERT_OK(drape_body_shape_init(&edge));
  edge.height_m = 0.8f;
  edge.weight_kg = 15.0f;
  edge.neck_mm = 50.0f;
  EXPECT_OK(drape_context_set_body_shape(c, &edge));
  edge.height_m = 2.5f;
  edge.weight_kg = 300.0f;
  edge.neck_mm = 3000.0f;
  EXPECT_OK(drape_context_set_body_shape(c, &edge));
}

// ==========================================================================================
// Skeleton input.

TEST(Capi, AllThreeLayoutsAreAccepted) {
  for (drape_layout layout : {DRAPE_LAYOUT_KINECT1, DRAPE_LAYOUT_KINECT2, DRAPE_LAYOUT_AZURE}) {
    SCOPED_TRACE(int(layout));
    ContextPtr ctx = makeContext();
    drape_context* c = ctx.get();
    for (int i = 0; i < 40; ++i) {
      const double t = i / 30.0;
      const std::vector<drape_joint> j = poseJoints(layout, t);
      ASSERT_EQ(j.size(), jointCount(layout));
      const drape_skeleton_frame f = makeFrame(layout, j, t);
      ASSERT_OK(drape_context_push_skeleton(c, &f));
      ASSERT_OK(drape_context_update(c));
    }
    const drape_frame_stats s = stats(c);
    EXPECT_EQ(s.frames_accepted, 40u);
    EXPECT_EQ(s.frames_rejected, 0u);
    EXPECT_EQ(s.updates, 40u);
    EXPECT_EQ(s.calibrated, 1);
    EXPECT_GT(s.body_volume_l, 20.0f);
    EXPECT_LT(s.body_volume_l, 200.0f);
    const Mesh m = readMesh(c);
    EXPECT_TRUE(allFinite(m.positions));
    EXPECT_TRUE(allFinite(m.normals));
    // The canonical skeleton's pelvis sits where the sensor put SpineBase / HipCenter / PELVIS.
    drape_vec3 sk[21];
    uint32_t n = 0;
    ASSERT_OK(drape_context_read_skeleton(c, sk, 21, &n));
    EXPECT_EQ(n, 21u);
    const V pelvis = kinect2Pose(39 / 30.0)[0];
    EXPECT_NEAR(sk[0].x, pelvis.x, 0.05f);
    EXPECT_NEAR(sk[0].y, pelvis.y, 0.05f);
    EXPECT_NEAR(sk[0].z, pelvis.z, 0.05f);
    // The body is around the skeleton: every vertex within 1.5 m of the pelvis.
    for (const drape_vec3& p : m.positions) {
      const float d = std::sqrt((p.x - pelvis.x) * (p.x - pelvis.x) + (p.y - pelvis.y) * (p.y - pelvis.y) +
                                (p.z - pelvis.z) * (p.z - pelvis.z));
      ASSERT_LT(d, 1.5f);
    }
  }
}

TEST(Capi, OrientationsAreOptionalAndValidated) {
  ContextPtr ctx = makeContext();
  drape_context* c = ctx.get();
  const std::vector<drape_joint> j = poseJoints(DRAPE_LAYOUT_KINECT2, 0.0);
  std::vector<drape_quat> q(25, drape_quat{0, 0, 0, 1});
  q[3] = drape_quat{0.5f, 0.5f, 0.5f, 0.5f};
  drape_skeleton_frame f = makeFrame(DRAPE_LAYOUT_KINECT2, j, 0.0, q.data());
  EXPECT_OK(drape_context_push_skeleton(c, &f));
  q[7] = drape_quat{0, 0, 0, 2};  // |q| = 2
  f.timestamp_s = 1.0;
  EXPECT_FAILS_MSG(DRAPE_ERROR_INVALID_ARGUMENT, drape_context_push_skeleton(c, &f));
  q[7] = drape_quat{0, 0, 0, 0};
  EXPECT_FAILS_MSG(DRAPE_ERROR_INVALID_ARGUMENT, drape_context_push_skeleton(c, &f));
  q[7] = drape_quat{kNaN, 0, 0, 1};
  EXPECT_FAILS_MSG(DRAPE_ERROR_NONFINITE, drape_context_push_skeleton(c, &f));
  q[7] = drape_quat{0, 0, 0, kInf};
  EXPECT_FAILS_MSG(DRAPE_ERROR_NONFINITE, drape_context_push_skeleton(c, &f));
  q[7] = drape_quat{0, 0, 0, 1};
  EXPECT_OK(drape_context_push_skeleton(c, &f));
  const drape_frame_stats s = stats(c);
  EXPECT_EQ(s.frames_accepted, 2u);
  EXPECT_EQ(s.frames_rejected, 4u);
  EXPECT_EQ(s.frames_pushed, 6u);
  EXPECT_EQ(s.frames_dropped, 1u) << "two accepted pushes without an update: the first is dropped";
}

// A push that must be rejected: a description, the frame to push, the expected code.
struct BadPush {
  std::string name;
  drape_result code;
  std::function<drape_result(drape_context*, double /*t*/, double /*lastAccepted*/)> push;
};

std::vector<BadPush> badPushes() {
  std::vector<BadPush> out;
  const drape_layout L = DRAPE_LAYOUT_KINECT2;
  auto withFrame = [L](std::function<void(drape_skeleton_frame&, std::vector<drape_joint>&, double last)> edit) {
    return [L, edit](drape_context* c, double t, double last) {
      std::vector<drape_joint> j = poseJoints(L, t);
      drape_skeleton_frame f = makeFrame(L, j, t);
      edit(f, j, last);
      f.joints = f.joints ? j.data() : nullptr;
      return drape_context_push_skeleton(c, &f);
    };
  };
  for (int32_t layout : {0, 4, -1, 0x7fffffff}) {
    out.push_back({"layout " + std::to_string(layout), DRAPE_ERROR_OUT_OF_RANGE,
                   withFrame([layout](drape_skeleton_frame& f, std::vector<drape_joint>&, double) { f.layout = layout; })});
  }
  for (uint32_t n : {0u, 20u, 24u, 26u, 32u, 0xffffffffu}) {
    out.push_back({"joint_count " + std::to_string(n), DRAPE_ERROR_INVALID_ARGUMENT,
                   withFrame([n](drape_skeleton_frame& f, std::vector<drape_joint>&, double) { f.joint_count = n; })});
  }
  out.push_back({"25 joints declared as Kinect v1", DRAPE_ERROR_INVALID_ARGUMENT,
                 withFrame([](drape_skeleton_frame& f, std::vector<drape_joint>&, double) { f.layout = DRAPE_LAYOUT_KINECT1; })});
  out.push_back({"NULL frame", DRAPE_ERROR_NULL_ARGUMENT,
                 [](drape_context* c, double, double) { return drape_context_push_skeleton(c, nullptr); }});
  for (uint32_t size : {0u, 8u, static_cast<uint32_t>(sizeof(drape_skeleton_frame) - 1)}) {
    out.push_back({"struct_size " + std::to_string(size), DRAPE_ERROR_INVALID_ARGUMENT,
                   withFrame([size](drape_skeleton_frame& f, std::vector<drape_joint>&, double) { f.struct_size = size; })});
  }
  out.push_back({"NULL joints", DRAPE_ERROR_NULL_ARGUMENT,
                 withFrame([](drape_skeleton_frame& f, std::vector<drape_joint>&, double) { f.joints = nullptr; })});
  const float badCoords[] = {kNaN, kInf, -kInf};
  for (int joint : {0, 3, 11, 24}) {
    for (int axis = 0; axis < 3; ++axis) {
      for (float v : badCoords) {
        out.push_back({"joint " + std::to_string(joint) + " axis " + std::to_string(axis) + " = " + std::to_string(v),
                       DRAPE_ERROR_NONFINITE,
                       withFrame([joint, axis, v](drape_skeleton_frame&, std::vector<drape_joint>& j, double) {
                         (&j[joint].position.x)[axis] = v;
                       })});
      }
    }
  }
  // |coordinate| > 1000 m: the push contract's documented range, hence DRAPE_ERROR_OUT_OF_RANGE.
  // (drape.h's comment on DRAPE_ERROR_NONFINITE, "NaN or Inf (or absurdly large)", could be read
  // as covering 1e30 too; the implementation and this test use OUT_OF_RANGE for every value past
  // the 1000 m limit.)
  for (int joint : {0, 24}) {
    out.push_back({"joint " + std::to_string(joint) + " x = 1e30", DRAPE_ERROR_OUT_OF_RANGE,
                   withFrame([joint](drape_skeleton_frame&, std::vector<drape_joint>& j, double) { j[joint].position.x = 1e30f; })});
    out.push_back({"joint " + std::to_string(joint) + " z = -1e30", DRAPE_ERROR_OUT_OF_RANGE,
                   withFrame([joint](drape_skeleton_frame&, std::vector<drape_joint>& j, double) { j[joint].position.z = -1e30f; })});
    out.push_back({"joint " + std::to_string(joint) + " y = 1000.5", DRAPE_ERROR_OUT_OF_RANGE,
                   withFrame([joint](drape_skeleton_frame&, std::vector<drape_joint>& j, double) { j[joint].position.y = 1000.5f; })});
  }
  for (int32_t st : {3, -1, 0x7fffffff}) {
    out.push_back({"tracking_state " + std::to_string(st), DRAPE_ERROR_OUT_OF_RANGE,
                   withFrame([st](drape_skeleton_frame&, std::vector<drape_joint>& j, double) { j[5].tracking_state = st; })});
  }
  out.push_back({"timestamp NaN", DRAPE_ERROR_NONFINITE,
                 withFrame([](drape_skeleton_frame& f, std::vector<drape_joint>&, double) {
                   f.timestamp_s = std::numeric_limits<double>::quiet_NaN();
                 })});
  out.push_back({"timestamp Inf", DRAPE_ERROR_NONFINITE,
                 withFrame([](drape_skeleton_frame& f, std::vector<drape_joint>&, double) {
                   f.timestamp_s = std::numeric_limits<double>::infinity();
                 })});
  out.push_back({"timestamp equal to the previous accepted one", DRAPE_ERROR_TIMESTAMP,
                 withFrame([](drape_skeleton_frame& f, std::vector<drape_joint>&, double last) { f.timestamp_s = last; })});
  out.push_back({"timestamp before the previous accepted one", DRAPE_ERROR_TIMESTAMP,
                 withFrame([](drape_skeleton_frame& f, std::vector<drape_joint>&, double last) { f.timestamp_s = last - 0.01; })});
  out.push_back({"timestamp far in the past", DRAPE_ERROR_TIMESTAMP,
                 withFrame([](drape_skeleton_frame& f, std::vector<drape_joint>&, double last) { f.timestamp_s = last - 1e6; })});
  out.push_back({"non-unit orientation", DRAPE_ERROR_INVALID_ARGUMENT, [L](drape_context* c, double t, double) {
                   const std::vector<drape_joint> j = poseJoints(L, t);
                   std::vector<drape_quat> q(25, drape_quat{0, 0, 0, 1});
                   q[12] = drape_quat{0.3f, 0.3f, 0.3f, 0.3f};
                   const drape_skeleton_frame f = makeFrame(L, j, t, q.data());
                   return drape_context_push_skeleton(c, &f);
                 }});
  return out;
}

// Two contexts get the same valid frames; one of them also gets every kind of garbage in between
// (before and after pushes, queued frame pending or not). Each garbage push must fail with its
// code, count as rejected, and leave the context's state exactly as it was: the meshes of the two
// contexts stay bit-identical after every update.
TEST(Capi, RejectedPushesLeaveTheContextBitIdentical) {
  ContextPtr control = makeContext();
  ContextPtr tested = makeContext();
  const std::vector<BadPush> bad = badPushes();
  const int frames = 45;  // past calibration (30)
  uint32_t rejected = 0;
  double lastAccepted = 0;
  for (int i = 0; i < frames; ++i) {
    const double t = 0.25 + i / 30.0;
    // Garbage before this frame's push (the previous frame was already consumed), except on the
    // very first frame where "previous accepted" does not exist yet.
    if (i > 0) {
      const BadPush& g = bad[static_cast<size_t>(i) % bad.size()];
      SCOPED_TRACE("before push, frame " + std::to_string(i) + ": " + g.name);
      EXPECT_FAILS_MSG(g.code, g.push(tested.get(), t, lastAccepted));
      ++rejected;
    }
    const std::vector<drape_joint> j = poseJoints(DRAPE_LAYOUT_KINECT2, t);
    const drape_skeleton_frame f = makeFrame(DRAPE_LAYOUT_KINECT2, j, t);
    ASSERT_OK(drape_context_push_skeleton(control.get(), &f));
    ASSERT_OK(drape_context_push_skeleton(tested.get(), &f));
    lastAccepted = t;
    // Garbage while a frame is queued: every kind, on a few frames.
    if (i == 1 || i == 29 || i == 40) {
      for (const BadPush& g : bad) {
        SCOPED_TRACE("queued, frame " + std::to_string(i) + ": " + g.name);
        EXPECT_FAILS_MSG(g.code, g.push(tested.get(), t + 0.01, lastAccepted));
        ++rejected;
      }
    }
    ASSERT_OK(drape_context_update(control.get()));
    ASSERT_OK(drape_context_update(tested.get()));
    if (i == 0 || i == 1 || i == 29 || i == 30 || i == 40 || i == frames - 1) {
      ASSERT_TRUE(bitIdentical(readMesh(control.get()), readMesh(tested.get()))) << "after frame " << i;
    }
    const drape_frame_stats a = stats(control.get()), b = stats(tested.get());
    ASSERT_EQ(b.frames_rejected, rejected) << "after frame " << i;
    ASSERT_EQ(b.frames_pushed, a.frames_pushed + rejected);
    ASSERT_EQ(b.frames_accepted, a.frames_accepted);
    ASSERT_EQ(b.frames_dropped, a.frames_dropped);
    ASSERT_EQ(b.updates, a.updates);
    ASSERT_EQ(b.teleports, a.teleports);
    ASSERT_EQ(b.calibrated, a.calibrated);
    ASSERT_EQ(b.last_timestamp_s, a.last_timestamp_s);
    ASSERT_EQ(b.body_volume_l, a.body_volume_l);
  }
  EXPECT_EQ(stats(tested.get()).frames_accepted, static_cast<uint32_t>(frames));
  EXPECT_EQ(stats(tested.get()).calibrated, 1);
  // The filtered skeletons agree too.
  drape_vec3 a[21], b[21];
  ASSERT_OK(drape_context_read_skeleton(control.get(), a, 21, nullptr));
  ASSERT_OK(drape_context_read_skeleton(tested.get(), b, 21, nullptr));
  EXPECT_EQ(std::memcmp(a, b, sizeof(a)), 0);
}

TEST(Capi, RejectedFirstPushDoesNotStartTheContext) {
  // Garbage as the very first frame: no frame is queued, and a later valid frame with an earlier
  // timestamp than the rejected one is accepted (the rejected timestamp was not recorded).
  ContextPtr ctx = makeContext();
  drape_context* c = ctx.get();
  std::vector<drape_joint> j = poseJoints(DRAPE_LAYOUT_KINECT2, 0.0);
  j[4].position.y = kNaN;
  drape_skeleton_frame f = makeFrame(DRAPE_LAYOUT_KINECT2, j, 5.0);
  EXPECT_FAILS_MSG(DRAPE_ERROR_NONFINITE, drape_context_push_skeleton(c, &f));
  EXPECT_FAILS(DRAPE_ERROR_CALL_ORDER, "drape_context_update", drape_context_update(c));
  j = poseJoints(DRAPE_LAYOUT_KINECT2, 0.0);
  f = makeFrame(DRAPE_LAYOUT_KINECT2, j, 1.0);
  EXPECT_OK(drape_context_push_skeleton(c, &f));
  EXPECT_OK(drape_context_update(c));
  const drape_frame_stats s = stats(c);
  EXPECT_EQ(s.frames_rejected, 1u);
  EXPECT_EQ(s.frames_accepted, 1u);
  EXPECT_EQ(s.last_timestamp_s, 1.0);
}

TEST(Capi, PushesAndUpdatesAreCountedAsDocumented) {
  ContextPtr ctx = makeContext();
  drape_context* c = ctx.get();
  const drape_frame_stats s0 = stats(c);
  EXPECT_EQ(s0.struct_size, sizeof(drape_frame_stats));
  EXPECT_EQ(s0.frames_pushed + s0.frames_accepted + s0.updates, 0u);
  EXPECT_EQ(s0.body_volume_l, 0.0f) << "no body before the first update";
  pushAndUpdate(c, DRAPE_LAYOUT_KINECT2, 0);
  const Mesh m1 = readMesh(c);
  // Update again without a new frame: allowed, nothing changes.
  EXPECT_OK(drape_context_update(c));
  EXPECT_OK(drape_context_update(c));
  EXPECT_TRUE(bitIdentical(m1, readMesh(c)));
  EXPECT_EQ(stats(c).updates, 1u);
  // Three pushes, one update: two dropped, the newest wins.
  for (int i = 1; i <= 3; ++i) {
    const std::vector<drape_joint> j = poseJoints(DRAPE_LAYOUT_KINECT2, i / 30.0);
    const drape_skeleton_frame f = makeFrame(DRAPE_LAYOUT_KINECT2, j, i / 30.0);
    ASSERT_OK(drape_context_push_skeleton(c, &f));
  }
  ASSERT_OK(drape_context_update(c));
  const drape_frame_stats s = stats(c);
  EXPECT_EQ(s.frames_pushed, 4u);
  EXPECT_EQ(s.frames_accepted, 4u);
  EXPECT_EQ(s.frames_dropped, 2u);
  EXPECT_EQ(s.updates, 2u);
  EXPECT_DOUBLE_EQ(s.last_timestamp_s, 3 / 30.0);
  EXPECT_GT(s.body_volume_l, 0.0f);
  EXPECT_GE(s.skeleton_ms, 0.0);
  EXPECT_GE(s.body_ms, 0.0);
  EXPECT_EQ(s.calibrated, 0) << "30 calibration frames by default; 2 updates so far";
}

// ==========================================================================================
// Call order and buffers.

TEST(Capi, CallOrder) {
  ContextPtr ctx = makeContext();
  drape_context* c = ctx.get();
  EXPECT_FAILS(DRAPE_ERROR_CALL_ORDER, "drape_context_update", drape_context_update(c));
  uint32_t nv = 0, ni = 0;
  ASSERT_OK(drape_context_get_body_mesh_size(c, &nv, &ni));
  std::vector<drape_vec3> pos(nv), nrm(nv);
  std::vector<uint32_t> idx(ni);
  fillSentinel(pos);
  fillSentinel(nrm);
  fillSentinel(idx);
  EXPECT_FAILS(DRAPE_ERROR_CALL_ORDER, "drape_context_read_body_mesh",
               drape_context_read_body_mesh(c, pos.data(), nullptr, nv, nullptr, 0));
  EXPECT_FAILS(DRAPE_ERROR_CALL_ORDER, "drape_context_read_body_mesh",
               drape_context_read_body_mesh(c, nullptr, nrm.data(), nv, nullptr, 0));
  // Positions + indices before an update: fails as a whole, nothing written (indices included).
  EXPECT_FAILS(DRAPE_ERROR_CALL_ORDER, "drape_context_read_body_mesh",
               drape_context_read_body_mesh(c, pos.data(), nrm.data(), nv, idx.data(), ni));
  EXPECT_TRUE(isSentinel(pos));
  EXPECT_TRUE(isSentinel(nrm));
  EXPECT_TRUE(isSentinel(idx));
  // Indices alone are available at once.
  EXPECT_OK(drape_context_read_body_mesh(c, nullptr, nullptr, 0, idx.data(), ni));
  for (uint32_t i : idx) ASSERT_LT(i, nv);
  std::vector<drape_vec3> sk(21);
  fillSentinel(sk);
  uint32_t count = 77;
  EXPECT_FAILS(DRAPE_ERROR_CALL_ORDER, "drape_context_read_skeleton",
               drape_context_read_skeleton(c, sk.data(), 21, &count));
  EXPECT_TRUE(isSentinel(sk));
  EXPECT_EQ(count, 77u);
  // After a push but before the update: still no mesh.
  const std::vector<drape_joint> j = poseJoints(DRAPE_LAYOUT_KINECT2, 0.0);
  const drape_skeleton_frame f = makeFrame(DRAPE_LAYOUT_KINECT2, j, 0.0);
  ASSERT_OK(drape_context_push_skeleton(c, &f));
  EXPECT_FAILS(DRAPE_ERROR_CALL_ORDER, "drape_context_read_body_mesh",
               drape_context_read_body_mesh(c, pos.data(), nullptr, nv, nullptr, 0));
  EXPECT_TRUE(isSentinel(pos));
  ASSERT_OK(drape_context_update(c));
  EXPECT_OK(drape_context_read_body_mesh(c, pos.data(), nrm.data(), nv, idx.data(), ni));
  EXPECT_TRUE(allFinite(pos));
  EXPECT_TRUE(allFinite(nrm));
  EXPECT_OK(drape_context_read_skeleton(c, sk.data(), 21, &count));
  EXPECT_EQ(count, 21u);
  EXPECT_TRUE(allFinite(sk));
  // A shape set before the first push does not let update run.
  ContextPtr c2 = makeContext();
  drape_body_shape s;
  ASSERT_OK(drape_body_shape_init(&s));
  s.height_m = 1.9f;
  ASSERT_OK(drape_context_set_body_shape(c2.get(), &s));
  EXPECT_FAILS(DRAPE_ERROR_CALL_ORDER, "drape_context_update", drape_context_update(c2.get()));
}

TEST(Capi, BuffersTooSmallByOneAreRejectedAndUntouched) {
  ContextPtr ctx = makeContext();
  drape_context* c = ctx.get();
  for (int i = 0; i < 3; ++i) pushAndUpdate(c, DRAPE_LAYOUT_KINECT2, i);
  uint32_t nv = 0, ni = 0;
  ASSERT_OK(drape_context_get_body_mesh_size(c, &nv, &ni));
  ASSERT_GT(nv, 1u);
  ASSERT_GT(ni, 1u);
  // One extra element past the capacity we announce: must never be written either.
  std::vector<drape_vec3> pos(nv + 1), nrm(nv + 1);
  std::vector<uint32_t> idx(ni + 1);
  auto reset = [&] {
    fillSentinel(pos);
    fillSentinel(nrm);
    fillSentinel(idx);
  };
  auto untouched = [&] { return isSentinel(pos) && isSentinel(nrm) && isSentinel(idx); };
  const drape_result B = DRAPE_ERROR_BUFFER_TOO_SMALL;
  const char* fn = "drape_context_read_body_mesh";
  reset();
  EXPECT_FAILS(B, fn, drape_context_read_body_mesh(c, pos.data(), nullptr, nv - 1, nullptr, 0));
  EXPECT_TRUE(untouched());
  EXPECT_FAILS(B, fn, drape_context_read_body_mesh(c, nullptr, nrm.data(), nv - 1, nullptr, 0));
  EXPECT_TRUE(untouched());
  EXPECT_FAILS(B, fn, drape_context_read_body_mesh(c, nullptr, nullptr, 0, idx.data(), ni - 1));
  EXPECT_TRUE(untouched());
  // One buffer too small fails the whole call: the others (big enough) stay untouched too.
  EXPECT_FAILS(B, fn, drape_context_read_body_mesh(c, pos.data(), nrm.data(), nv, idx.data(), ni - 1));
  EXPECT_TRUE(untouched());
  EXPECT_FAILS(B, fn, drape_context_read_body_mesh(c, pos.data(), nrm.data(), nv - 1, idx.data(), ni));
  EXPECT_TRUE(untouched());
  EXPECT_FAILS(B, fn, drape_context_read_body_mesh(c, pos.data(), nullptr, 0, idx.data(), ni));
  EXPECT_TRUE(untouched());
  // All three NULL.
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, fn, drape_context_read_body_mesh(c, nullptr, nullptr, nv, nullptr, ni));
  // Exact capacity: written, and nothing past it.
  EXPECT_OK(drape_context_read_body_mesh(c, pos.data(), nrm.data(), nv, idx.data(), ni));
  std::vector<drape_vec3> tailP(pos.end() - 1, pos.end()), tailN(nrm.end() - 1, nrm.end());
  std::vector<uint32_t> tailI(idx.end() - 1, idx.end());
  EXPECT_TRUE(isSentinel(tailP)) << "wrote past vertex_capacity";
  EXPECT_TRUE(isSentinel(tailN)) << "wrote past vertex_capacity";
  EXPECT_TRUE(isSentinel(tailI)) << "wrote past index_capacity";
  pos.pop_back();
  nrm.pop_back();
  idx.pop_back();
  EXPECT_TRUE(allFinite(pos));
  EXPECT_TRUE(allFinite(nrm));
  for (uint32_t i : idx) ASSERT_LT(i, nv);
  // Larger capacity than needed is fine.
  std::vector<drape_vec3> big(nv + 100);
  EXPECT_OK(drape_context_read_body_mesh(c, big.data(), nullptr, nv + 100, nullptr, 0));
  EXPECT_EQ(std::memcmp(big.data(), pos.data(), nv * sizeof(drape_vec3)), 0);

  // read_skeleton: capacity 20.
  std::vector<drape_vec3> sk(22);
  fillSentinel(sk);
  uint32_t count = 5;
  EXPECT_FAILS(B, "drape_context_read_skeleton", drape_context_read_skeleton(c, sk.data(), 20, &count));
  EXPECT_TRUE(isSentinel(sk));
  EXPECT_EQ(count, 5u);
  EXPECT_OK(drape_context_read_skeleton(c, sk.data(), 21, &count));
  EXPECT_EQ(count, 21u);
  EXPECT_TRUE(isSentinel(std::vector<drape_vec3>(sk.begin() + 21, sk.end()))) << "wrote past capacity";
}

// ==========================================================================================
// Recordings.

std::string smallCsv(int frames, int64_t tick0 = 89810293609, int64_t step = 333333) {
  std::ostringstream s;
  s.precision(9);
  for (int f = 0; f < frames; ++f) {
    s << (tick0 + f * step);
    const std::array<V, 25> p = kinect2Pose(f / 30.0);
    for (const V& v : p) s << ',' << v.x << ',' << v.y << ',' << v.z << ",2";
    s << ",\n";
  }
  return s.str();
}

TEST(Capi, RecordingOpenErrors) {
  drape_recording* out = kRecordingSentinel;
  EXPECT_FAILS(DRAPE_ERROR_IO, "drape_recording_open",
               drape_recording_open("/nonexistent/drape/no_such_file.csv", DRAPE_LAYOUT_AUTO, &out));
  EXPECT_EQ(out, kRecordingSentinel);
  EXPECT_NE(lastError().find("no_such_file.csv"), std::string::npos) << "the message should name the path";
  // A directory cannot be read as a recording: "a file could not be opened or read" (drape.h,
  // DRAPE_ERROR_IO), not "not in a format Drape reads" (PARSE). (Was PARSE before 79b4783.)
  const std::string dir = std::filesystem::temp_directory_path().string();
  EXPECT_FAILS(DRAPE_ERROR_IO, "drape_recording_open", drape_recording_open(dir.c_str(), DRAPE_LAYOUT_AUTO, &out));
  EXPECT_EQ(out, kRecordingSentinel);

  // Garbage from memory.
  const char garbage[] = "\x7f" "ELF\x01\x02\x00 this is not a recording \xff\xfe";
  EXPECT_FAILS(DRAPE_ERROR_PARSE, "drape_recording_open_memory",
               drape_recording_open_memory(garbage, sizeof(garbage), DRAPE_LAYOUT_AUTO, &out));
  EXPECT_EQ(out, kRecordingSentinel);
  const std::string text = "hello, world\nnot,a,csv\n";
  EXPECT_FAILS(DRAPE_ERROR_PARSE, "drape_recording_open_memory",
               drape_recording_open_memory(text.data(), text.size(), DRAPE_LAYOUT_AUTO, &out));
  EXPECT_EQ(out, kRecordingSentinel);
  // Empty input (NULL with size 0 is not a NULL argument: there is simply nothing to read).
  EXPECT_FAILS(DRAPE_ERROR_PARSE, "drape_recording_open_memory", drape_recording_open_memory(nullptr, 0, 0, &out));
  EXPECT_FAILS(DRAPE_ERROR_PARSE, "drape_recording_open_memory", drape_recording_open_memory("", 0, 0, &out));
  // A CSV row with a wrong number of fields, and one with NaN.
  std::string csv = smallCsv(3);
  std::string truncated = csv.substr(0, csv.size() - 40) + "\n";
  EXPECT_FAILS(DRAPE_ERROR_PARSE, "drape_recording_open_memory",
               drape_recording_open_memory(truncated.data(), truncated.size(), 0, &out));
  std::string withNan = csv;  // the first joint's X of the first row becomes "nan"
  const size_t c1 = withNan.find(','), c2 = withNan.find(',', c1 + 1);
  withNan.replace(c1 + 1, c2 - c1 - 1, "nan");
  EXPECT_FAILS(DRAPE_ERROR_PARSE, "drape_recording_open_memory",
               drape_recording_open_memory(withNan.data(), withNan.size(), 0, &out));
  EXPECT_EQ(out, kRecordingSentinel);

  // Layout hint out of range, from file and from memory.
  for (int32_t hint : {9, 4, -1, 0x7fffffff}) {
    SCOPED_TRACE(hint);
    EXPECT_FAILS(DRAPE_ERROR_OUT_OF_RANGE, "drape_recording_open_memory",
                 drape_recording_open_memory(csv.data(), csv.size(), hint, &out));
    EXPECT_FAILS(DRAPE_ERROR_OUT_OF_RANGE, "drape_recording_open",
                 drape_recording_open("/nonexistent.csv", hint, &out));
  }
  EXPECT_EQ(out, kRecordingSentinel);
  // A layout hint that contradicts the content (a 25-joint CSV read as Kinect v1 / Azure).
  for (int32_t hint : {DRAPE_LAYOUT_KINECT1, DRAPE_LAYOUT_AZURE}) {
    SCOPED_TRACE(hint);
    const drape_result r = drape_recording_open_memory(csv.data(), csv.size(), hint, &out);
    EXPECT_NE(r, DRAPE_OK);
    EXPECT_EQ(out, kRecordingSentinel);
  }
  // The matching hint works.
  drape_recording* r = nullptr;
  EXPECT_OK(drape_recording_open_memory(csv.data(), csv.size(), DRAPE_LAYOUT_KINECT2, &r));
  EXPECT_OK(drape_recording_destroy(r));
}

TEST(Capi, RecordingFromMemoryIsACopy) {
  std::string csv = smallCsv(5);
  drape_recording* r = nullptr;
  ASSERT_OK(drape_recording_open_memory(csv.data(), csv.size(), DRAPE_LAYOUT_AUTO, &r));
  RecordingPtr owner(r);
  std::vector<drape_joint> before(25), after(25);
  ASSERT_OK(drape_recording_read_frame(r, 2, before.data(), 25, nullptr));
  std::fill(csv.begin(), csv.end(), 'x');  // the caller keeps (and here scribbles over) its bytes
  csv.clear();
  csv.shrink_to_fit();
  ASSERT_OK(drape_recording_read_frame(r, 2, after.data(), 25, nullptr));
  EXPECT_EQ(std::memcmp(before.data(), after.data(), 25 * sizeof(drape_joint)), 0);
  drape_recording_info info;
  std::memset(&info, 0, sizeof(info));
  info.struct_size = sizeof(info);
  ASSERT_OK(drape_recording_get_info(r, &info));
  EXPECT_EQ(info.format, DRAPE_RECORDING_KINECT_CSV);
  EXPECT_EQ(info.layout, DRAPE_LAYOUT_KINECT2);
  EXPECT_EQ(info.joint_count, 25u);
  EXPECT_EQ(info.frame_count, 5u);
  EXPECT_NEAR(info.nominal_rate_hz, 30.0f, 0.1f);
  EXPECT_NEAR(info.duration_s, 4 * 0.0333333, 1e-6);
  // Frame values are the CSV's.
  const V p = kinect2Pose(2 / 30.0)[7];
  EXPECT_NEAR(after[7].position.x, p.x, 1e-6f);
  EXPECT_NEAR(after[7].position.y, p.y, 1e-6f);
  EXPECT_NEAR(after[7].position.z, p.z, 1e-6f);
  EXPECT_EQ(after[7].tracking_state, DRAPE_TRACKING_TRACKED);
}

TEST(Capi, RealKinectCsvRecording) {
  DRAPE_REQUIRE_SHARED(path, kWaveHand);
  drape_recording* r = kRecordingSentinel;
  ASSERT_OK(drape_recording_open(path.c_str(), DRAPE_LAYOUT_AUTO, &r));
  ASSERT_NE(r, kRecordingSentinel);
  RecordingPtr owner(r);
  drape_recording_info info;
  std::memset(&info, 0x5A, sizeof(info));
  info.struct_size = sizeof(info);
  ASSERT_OK(drape_recording_get_info(r, &info));
  EXPECT_EQ(info.struct_size, sizeof(info));
  EXPECT_EQ(info.format, DRAPE_RECORDING_KINECT_CSV);
  EXPECT_EQ(info.layout, DRAPE_LAYOUT_KINECT2);
  EXPECT_EQ(info.joint_count, 25u);
  EXPECT_EQ(info.frame_count, 154u);  // README: Ges01_wavehand.csv, 154 frames, 5.2 s
  EXPECT_NEAR(info.nominal_rate_hz, 30.0f, 0.5f);
  EXPECT_NEAR(info.duration_s, 5.2, 0.15);

  // First frame = the file's first line (timestamp 0 by definition, first joint as written).
  std::vector<drape_joint> j(26);
  double ts = -1;
  ASSERT_OK(drape_recording_read_frame(r, 0, j.data(), 25, &ts));
  EXPECT_EQ(ts, 0.0);
  EXPECT_FLOAT_EQ(j[0].position.x, 0.0111604f);
  EXPECT_FLOAT_EQ(j[0].position.y, -0.367822f);
  EXPECT_FLOAT_EQ(j[0].position.z, 2.69467f);
  EXPECT_EQ(j[0].tracking_state, 2);
  EXPECT_FLOAT_EQ(j[19].position.x, 0.112428f);  // FootRight, the 20th joint of the first line
  EXPECT_FLOAT_EQ(j[19].position.y, -1.10687f);
  // Timestamps strictly increase and end at the duration.
  double prev = -1;
  for (uint32_t i = 0; i < info.frame_count; ++i) {
    ASSERT_OK(drape_recording_read_frame(r, i, j.data(), 25, &ts));
    ASSERT_GT(ts, prev) << "frame " << i;
    prev = ts;
  }
  EXPECT_DOUBLE_EQ(prev, info.duration_s);

  // Index out of range, capacity too small, both with the caller's buffer untouched.
  fillSentinel(j);
  ts = 42.0;
  EXPECT_FAILS(DRAPE_ERROR_OUT_OF_RANGE, "drape_recording_read_frame", drape_recording_read_frame(r, 154, j.data(), 26, &ts));
  EXPECT_FAILS(DRAPE_ERROR_OUT_OF_RANGE, "drape_recording_read_frame",
               drape_recording_read_frame(r, 0xffffffffu, j.data(), 26, &ts));
  EXPECT_FAILS(DRAPE_ERROR_BUFFER_TOO_SMALL, "drape_recording_read_frame", drape_recording_read_frame(r, 0, j.data(), 24, &ts));
  EXPECT_FAILS(DRAPE_ERROR_BUFFER_TOO_SMALL, "drape_recording_read_frame", drape_recording_read_frame(r, 0, j.data(), 0, &ts));
  EXPECT_TRUE(isSentinel(j));
  EXPECT_EQ(ts, 42.0);
  // Capacity larger than needed: only joint_count joints are written.
  ASSERT_OK(drape_recording_read_frame(r, 3, j.data(), 26, nullptr));
  EXPECT_TRUE(isSentinel(std::vector<drape_joint>(j.begin() + 25, j.end()))) << "wrote past joint_count";

  // Layout hints: AUTO and KINECT2 work, 9 is out of range, 1/3 contradict the content.
  drape_recording* r2 = kRecordingSentinel;
  EXPECT_FAILS(DRAPE_ERROR_OUT_OF_RANGE, "drape_recording_open", drape_recording_open(path.c_str(), 9, &r2));
  EXPECT_NE(drape_recording_open(path.c_str(), DRAPE_LAYOUT_KINECT1, &r2), DRAPE_OK);
  EXPECT_EQ(r2, kRecordingSentinel);
  ASSERT_OK(drape_recording_open(path.c_str(), DRAPE_LAYOUT_KINECT2, &r2));
  EXPECT_OK(drape_recording_destroy(r2));
}

// Compares every frame (joints bit for bit, timestamps exactly) of two recordings.
void expectSameFrames(drape_recording* a, drape_recording* b) {
  drape_recording_info ia, ib;
  std::memset(&ia, 0, sizeof(ia));
  std::memset(&ib, 0, sizeof(ib));
  ia.struct_size = ib.struct_size = sizeof(drape_recording_info);
  ASSERT_OK(drape_recording_get_info(a, &ia));
  ASSERT_OK(drape_recording_get_info(b, &ib));
  ASSERT_EQ(ia.frame_count, ib.frame_count);
  ASSERT_EQ(ia.joint_count, ib.joint_count);
  EXPECT_EQ(ia.layout, ib.layout);
  EXPECT_EQ(ia.duration_s, ib.duration_s);
  EXPECT_FLOAT_EQ(ia.nominal_rate_hz, ib.nominal_rate_hz);
  std::vector<drape_joint> ja(ia.joint_count), jb(ia.joint_count);
  for (uint32_t i = 0; i < ia.frame_count; ++i) {
    double ta = -1, tb = -2;
    ASSERT_OK(drape_recording_read_frame(a, i, ja.data(), ia.joint_count, &ta));
    ASSERT_OK(drape_recording_read_frame(b, i, jb.data(), ib.joint_count, &tb));
    ASSERT_EQ(ta, tb) << "frame " << i;
    ASSERT_EQ(std::memcmp(ja.data(), jb.data(), ja.size() * sizeof(drape_joint)), 0) << "frame " << i;
  }
}

TEST(Capi, RecordingSaveAndReopenGivesIdenticalFrames) {
  DRAPE_REQUIRE_SHARED(path, kWaveHand);
  drape_recording* r = nullptr;
  ASSERT_OK(drape_recording_open(path.c_str(), DRAPE_LAYOUT_AUTO, &r));
  RecordingPtr owner(r);
  const std::string out = tempPath("wavehand.drec");
  std::filesystem::remove(out);
  ASSERT_OK(drape_recording_save(r, out.c_str()));
  ASSERT_TRUE(std::filesystem::exists(out));
  drape_recording* back = nullptr;
  ASSERT_OK(drape_recording_open(out.c_str(), DRAPE_LAYOUT_AUTO, &back));
  RecordingPtr owner2(back);
  drape_recording_info info;
  std::memset(&info, 0, sizeof(info));
  info.struct_size = sizeof(info);
  ASSERT_OK(drape_recording_get_info(back, &info));
  EXPECT_EQ(info.format, DRAPE_RECORDING_DRAPE);
  expectSameFrames(r, back);
  // Save again from the reopened one: the same text apart from '#' comments (which name the
  // source format) - a stable writer.
  const std::string out2 = tempPath("wavehand2.drec");
  ASSERT_OK(drape_recording_save(back, out2.c_str()));
  std::ifstream f1(out, std::ios::binary), f2(out2, std::ios::binary);
  const std::string s1((std::istreambuf_iterator<char>(f1)), std::istreambuf_iterator<char>());
  const std::string s2((std::istreambuf_iterator<char>(f2)), std::istreambuf_iterator<char>());
  auto withoutComments = [](const std::string& text) {
    std::istringstream in(text);
    std::string line, kept;
    while (std::getline(in, line))
      if (line.empty() || line[0] != '#') kept += line + "\n";
    return kept;
  };
  EXPECT_EQ(withoutComments(s1), withoutComments(s2));
  EXPECT_GT(withoutComments(s1).size(), 1000u);
  // The saved text opens from memory too.
  drape_recording* mem = nullptr;
  ASSERT_OK(drape_recording_open_memory(s1.data(), s1.size(), DRAPE_LAYOUT_AUTO, &mem));
  RecordingPtr owner3(mem);
  expectSameFrames(r, mem);
  std::filesystem::remove(out);
  std::filesystem::remove(out2);

  // Saving where no file can be written: IO error.
  EXPECT_FAILS(DRAPE_ERROR_IO, "drape_recording_save", drape_recording_save(r, "/nonexistent/drape/dir/out.drec"));
  const std::string dir = std::filesystem::temp_directory_path().string();
  EXPECT_FAILS(DRAPE_ERROR_IO, "drape_recording_save", drape_recording_save(r, dir.c_str()));
}

TEST(Capi, SyntheticRecordingSaveAndReopen) {
  // Independent of the shared data: a CSV built here, saved and read back.
  const std::string csv = smallCsv(12);
  drape_recording* r = nullptr;
  ASSERT_OK(drape_recording_open_memory(csv.data(), csv.size(), DRAPE_LAYOUT_AUTO, &r));
  RecordingPtr owner(r);
  const std::string out = tempPath("synthetic.drec");
  ASSERT_OK(drape_recording_save(r, out.c_str()));
  drape_recording* back = nullptr;
  ASSERT_OK(drape_recording_open(out.c_str(), DRAPE_LAYOUT_KINECT2, &back));
  RecordingPtr owner2(back);
  expectSameFrames(r, back);
  std::filesystem::remove(out);
}

// ==========================================================================================
// The whole pipeline through the C ABI on a real recording.

struct RunResult {
  std::vector<Mesh> meshes;  // one per frame
  drape_frame_stats last{};
  bool ok = true;
};

// Plays `rec` into a new context, frame by frame (push + update + read), and returns everything.
RunResult play(drape_recording* rec, bool keepMeshes) {
  RunResult out;
  drape_recording_info info;
  std::memset(&info, 0, sizeof(info));
  info.struct_size = sizeof(info);
  if (drape_recording_get_info(rec, &info) != DRAPE_OK) {
    out.ok = false;
    return out;
  }
  drape_context* c = nullptr;
  if (drape_context_create(nullptr, &c) != DRAPE_OK) {
    out.ok = false;
    return out;
  }
  std::vector<drape_joint> j(info.joint_count);
  for (uint32_t i = 0; i < info.frame_count && out.ok; ++i) {
    double ts = 0;
    drape_skeleton_frame f;
    std::memset(&f, 0, sizeof(f));
    f.struct_size = sizeof(f);
    f.layout = info.layout;
    f.joint_count = info.joint_count;
    f.joints = j.data();
    out.ok = drape_recording_read_frame(rec, i, j.data(), info.joint_count, &ts) == DRAPE_OK;
    f.timestamp_s = ts;
    out.ok = out.ok && drape_context_push_skeleton(c, &f) == DRAPE_OK;
    out.ok = out.ok && drape_context_update(c) == DRAPE_OK;
    if (!out.ok) break;
    uint32_t nv = 0, ni = 0;
    drape_context_get_body_mesh_size(c, &nv, &ni);
    Mesh m;
    m.positions.resize(nv);
    m.normals.resize(nv);
    m.indices.resize(ni);
    out.ok = drape_context_read_body_mesh(c, m.positions.data(), m.normals.data(), nv, m.indices.data(), ni) ==
             DRAPE_OK;
    uint32_t ne = 0;
    out.ok = out.ok && drape_context_get_ellipsoid_count(c, &ne) == DRAPE_OK;
    m.ellipsoids.resize(ne);
    m.matrices.resize(16 * size_t{ne});
    out.ok = out.ok && drape_context_read_ellipsoids(c, m.ellipsoids.data(), ne, nullptr) == DRAPE_OK;
    out.ok = out.ok && drape_context_read_ellipsoid_matrices(c, m.matrices.data(), ne, nullptr) == DRAPE_OK;
    if (keepMeshes || i + 1 == info.frame_count) out.meshes.push_back(std::move(m));
  }
  std::memset(&out.last, 0, sizeof(out.last));
  out.last.struct_size = sizeof(out.last);
  if (drape_context_get_frame_stats(c, &out.last) != DRAPE_OK) out.ok = false;
  if (drape_context_destroy(c) != DRAPE_OK) out.ok = false;
  return out;
}

TEST(Capi, HappyPathOnARealRecording) {
  DRAPE_REQUIRE_SHARED(path, kWaveHand);
  drape_recording* rec = nullptr;
  ASSERT_OK(drape_recording_open(path.c_str(), DRAPE_LAYOUT_AUTO, &rec));
  RecordingPtr owner(rec);
  drape_recording_info info;
  std::memset(&info, 0, sizeof(info));
  info.struct_size = sizeof(info);
  ASSERT_OK(drape_recording_get_info(rec, &info));

  ContextPtr ctx = makeContext();
  drape_context* c = ctx.get();
  drape_body_shape shape;
  ASSERT_OK(drape_body_shape_init(&shape));
  shape.height_m = 1.60f;  // README: head-to-foot joint distance ~1.45-1.5 m
  shape.weight_kg = 58.0f;
  ASSERT_OK(drape_context_set_body_shape(c, &shape));
  uint32_t nv = 0, ni = 0;
  ASSERT_OK(drape_context_get_body_mesh_size(c, &nv, &ni));
  std::vector<drape_vec3> pos(nv), nrm(nv);
  std::vector<uint32_t> idx(ni);
  std::vector<drape_joint> j(info.joint_count);
  uint8_t calibratedAt = 0;
  uint32_t firstCalibrated = 0;
  for (uint32_t i = 0; i < info.frame_count; ++i) {
    double ts = 0;
    ASSERT_OK(drape_recording_read_frame(rec, i, j.data(), info.joint_count, &ts));
    drape_skeleton_frame f;
    std::memset(&f, 0, sizeof(f));
    f.struct_size = sizeof(f);
    f.layout = info.layout;
    f.joint_count = info.joint_count;
    f.timestamp_s = ts;
    f.joints = j.data();
    ASSERT_OK(drape_context_push_skeleton(c, &f)) << "frame " << i;
    ASSERT_OK(drape_context_update(c)) << "frame " << i;
    ASSERT_OK(drape_context_read_body_mesh(c, pos.data(), nrm.data(), nv, idx.data(), ni));
    ASSERT_TRUE(allFinite(pos)) << "frame " << i;
    ASSERT_TRUE(allFinite(nrm)) << "frame " << i;
    for (uint32_t k : idx) ASSERT_LT(k, nv);
    // Unit normals.
    for (const drape_vec3& n : nrm) {
      const float len = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
      ASSERT_NEAR(len, 1.0f, 1e-3f) << "frame " << i;
    }
    const drape_frame_stats s = stats(c);
    if (s.calibrated && !calibratedAt) {
      calibratedAt = 1;
      firstCalibrated = i;
    }
    ASSERT_TRUE(std::isfinite(s.body_volume_l));
    ASSERT_GT(s.body_volume_l, 0.0f) << "frame " << i;
  }
  const drape_frame_stats s = stats(c);
  EXPECT_EQ(s.frames_accepted, info.frame_count);
  EXPECT_EQ(s.frames_pushed, info.frame_count);
  EXPECT_EQ(s.frames_rejected, 0u);
  EXPECT_EQ(s.frames_dropped, 0u);
  EXPECT_EQ(s.updates, info.frame_count);
  EXPECT_EQ(s.calibrated, 1);
  EXPECT_EQ(firstCalibrated + 1, 30u) << "calibration_frames = 30 by default";
  EXPECT_EQ(s.teleports, 0u) << "a person standing and waving does not teleport";
  EXPECT_GT(s.body_volume_l, 20.0f);
  EXPECT_LT(s.body_volume_l, 150.0f);
  EXPECT_EQ(s.last_timestamp_s, info.duration_s);
  // The body stands where the sensor saw the person (~2.7 m away).
  drape_vec3 sk[21];
  ASSERT_OK(drape_context_read_skeleton(c, sk, 21, nullptr));
  EXPECT_NEAR(sk[0].z, j[0].position.z, 0.1f);
  EXPECT_NEAR(sk[0].x, j[0].position.x, 0.1f);
  EXPECT_NEAR(sk[0].y, j[0].position.y, 0.1f);
}

// ==========================================================================================
// Threads.

TEST(Capi, TwoContextsOnTwoThreadsMatchSequentialRuns) {
  DRAPE_REQUIRE_SHARED(pathA, kWaveHand);
  DRAPE_REQUIRE_SHARED(pathB, "kinect_v2_msft_labanotation/Ges02_balancinghands.csv");
  drape_recording *a = nullptr, *b = nullptr;
  ASSERT_OK(drape_recording_open(pathA.c_str(), 0, &a));
  RecordingPtr ownA(a);
  ASSERT_OK(drape_recording_open(pathB.c_str(), 0, &b));
  RecordingPtr ownB(b);
  const RunResult seqA = play(a, true);
  const RunResult seqB = play(b, true);
  ASSERT_TRUE(seqA.ok);
  ASSERT_TRUE(seqB.ok);
  RunResult parA, parB;
  std::atomic<int> ready{0};
  auto run = [&ready](drape_recording* r, RunResult* out) {
    ready.fetch_add(1);
    while (ready.load() < 2) std::this_thread::yield();  // start together
    *out = play(r, true);
  };
  std::thread ta(run, a, &parA), tb(run, b, &parB);
  ta.join();
  tb.join();
  ASSERT_TRUE(parA.ok);
  ASSERT_TRUE(parB.ok);
  ASSERT_EQ(parA.meshes.size(), seqA.meshes.size());
  ASSERT_EQ(parB.meshes.size(), seqB.meshes.size());
  for (size_t i = 0; i < seqA.meshes.size(); ++i) ASSERT_TRUE(bitIdentical(seqA.meshes[i], parA.meshes[i])) << "A frame " << i;
  for (size_t i = 0; i < seqB.meshes.size(); ++i) ASSERT_TRUE(bitIdentical(seqB.meshes[i], parB.meshes[i])) << "B frame " << i;
  EXPECT_EQ(parA.last.frames_accepted, seqA.last.frames_accepted);
  EXPECT_EQ(parB.last.frames_accepted, seqB.last.frames_accepted);
  EXPECT_EQ(parA.last.body_volume_l, seqA.last.body_volume_l);
  EXPECT_EQ(parB.last.body_volume_l, seqB.last.body_volume_l);
}

TEST(Capi, TwoContextsOnTwoThreadsSynthetic) {
  // Same as above without shared data: both threads play synthetic poses of different layouts.
  auto runSynthetic = [](drape_layout layout, std::vector<Mesh>* out) {
    drape_context* c = nullptr;
    if (drape_context_create(nullptr, &c) != DRAPE_OK) return;
    for (int i = 0; i < 60; ++i) {
      const double t = i / 30.0;
      const std::vector<drape_joint> j = poseJoints(layout, t);
      const drape_skeleton_frame f = makeFrame(layout, j, t);
      if (drape_context_push_skeleton(c, &f) != DRAPE_OK || drape_context_update(c) != DRAPE_OK) break;
      uint32_t nv = 0, ni = 0;
      drape_context_get_body_mesh_size(c, &nv, &ni);
      Mesh m;
      m.positions.resize(nv);
      m.normals.resize(nv);
      m.indices.resize(ni);
      drape_context_read_body_mesh(c, m.positions.data(), m.normals.data(), nv, m.indices.data(), ni);
      readEllipsoidsInto(c, m);
      out->push_back(std::move(m));
    }
    drape_context_destroy(c);
  };
  std::vector<Mesh> seq1, seq3, par1, par3;
  runSynthetic(DRAPE_LAYOUT_KINECT1, &seq1);
  runSynthetic(DRAPE_LAYOUT_AZURE, &seq3);
  std::thread t1(runSynthetic, DRAPE_LAYOUT_KINECT1, &par1), t3(runSynthetic, DRAPE_LAYOUT_AZURE, &par3);
  t1.join();
  t3.join();
  ASSERT_EQ(seq1.size(), 60u);
  ASSERT_EQ(seq3.size(), 60u);
  ASSERT_EQ(par1.size(), 60u);
  ASSERT_EQ(par3.size(), 60u);
  for (size_t i = 0; i < 60; ++i) {
    ASSERT_TRUE(bitIdentical(seq1[i], par1[i])) << i;
    ASSERT_TRUE(bitIdentical(seq3[i], par3[i])) << i;
  }
}

TEST(Capi, LastErrorIsPerThread) {
  // Thread B fails first and keeps its message while thread A fails (differently) afterwards;
  // the main thread's message is not affected by either.
  primeLastError();
  std::atomic<int> step{0};
  std::string bBefore, bAfter, aMessage;
  drape_result aResult = DRAPE_OK, bResult = DRAPE_OK;
  std::thread tb([&] {
    bResult = drape_context_update(nullptr);  // "drape_context_update: context is NULL"
    bBefore = lastError();
    step = 1;
    while (step.load() != 2) std::this_thread::yield();
    bAfter = lastError();
  });
  std::thread ta([&] {
    while (step.load() != 1) std::this_thread::yield();
    drape_recording* out = nullptr;
    aResult = drape_recording_open("/nonexistent/drape/thread_a.csv", 0, &out);
    aMessage = lastError();
    step = 2;
  });
  ta.join();
  tb.join();
  EXPECT_EQ(bResult, DRAPE_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(aResult, DRAPE_ERROR_IO);
  EXPECT_NE(bBefore.find("drape_context_update"), std::string::npos) << bBefore;
  EXPECT_NE(aMessage.find("thread_a.csv"), std::string::npos) << aMessage;
  EXPECT_EQ(bAfter, bBefore) << "thread A's failure changed thread B's message";
  EXPECT_STREQ(drape_last_error(), kPrimeMessage) << "a failure on another thread changed this thread's message";
}

TEST(Capi, HandlesCreatedAndDestroyedConcurrently) {
  // The live-handle registry is shared: hammer it from four threads, then check that every handle
  // each thread made is dead and that live ones from other threads were never confused.
  std::atomic<int> failures{0};
  auto worker = [&failures] {
    for (int i = 0; i < 25; ++i) {
      drape_context* c = nullptr;
      if (drape_context_create(nullptr, &c) != DRAPE_OK) {
        ++failures;
        continue;
      }
      uint32_t nv = 0;
      if (drape_context_get_body_mesh_size(c, &nv, nullptr) != DRAPE_OK || nv == 0) ++failures;
      if (drape_context_destroy(c) != DRAPE_OK) ++failures;
    }
  };
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) threads.emplace_back(worker);
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(failures.load(), 0);
}

// ==========================================================================================
// Robustness: valid but strange input must never produce NaN output.

TEST(Capi, DegenerateButFiniteSkeletonsGiveFiniteMeshes) {
  struct Case {
    const char* name;
    std::function<void(std::vector<drape_joint>&)> edit;
  };
  const std::vector<Case> cases = {
      {"all joints at one point", [](std::vector<drape_joint>& j) {
         for (drape_joint& k : j) k.position = drape_vec3{0.1f, 0.2f, 2.0f};
       }},
      {"all joints at the origin, not tracked", [](std::vector<drape_joint>& j) {
         for (drape_joint& k : j) k = drape_joint{{0, 0, 0}, DRAPE_TRACKING_NOT_TRACKED};
       }},
      {"all joints inferred", [](std::vector<drape_joint>& j) {
         for (drape_joint& k : j) k.tracking_state = DRAPE_TRACKING_INFERRED;
       }},
      {"head and neck coincide", [](std::vector<drape_joint>& j) { j[3].position = j[2].position; }},
      {"far away (999 m)", [](std::vector<drape_joint>& j) {
         for (drape_joint& k : j) k.position.z += 996.0f;
       }},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.name);
    ContextPtr ctx = makeContext();
    drape_context* c = ctx.get();
    for (int i = 0; i < 40; ++i) {
      const double t = i / 30.0;
      std::vector<drape_joint> j = poseJoints(DRAPE_LAYOUT_KINECT2, t);
      if (i >= 5 && i < 15) k.edit(j);  // a stretch of strange frames, then normal ones again
      const drape_skeleton_frame f = makeFrame(DRAPE_LAYOUT_KINECT2, j, t);
      ASSERT_OK(drape_context_push_skeleton(c, &f)) << "frame " << i;
      const drape_result r = drape_context_update(c);
      ASSERT_EQ(r, DRAPE_OK) << "frame " << i << ": " << drape_result_name(r) << " " << lastError();
      const Mesh m = readMesh(c);
      ASSERT_TRUE(allFinite(m.positions)) << "frame " << i;
      ASSERT_TRUE(allFinite(m.normals)) << "frame " << i;
      ASSERT_TRUE(ellipsoidsFinite(m)) << "frame " << i;
      ASSERT_TRUE(std::isfinite(stats(c).body_volume_l)) << "frame " << i;
    }
  }
}


// Finite, strictly increasing timestamps and in-range coordinates are valid input however odd:
// the pipeline must stay finite (an update may not fail with INTERNAL, a mesh may not hold NaN).
TEST(Capi, ExtremeButValidTimestampsAndJumpsStayFinite) {
  struct Case {
    const char* name;
    std::function<double(int)> time;                       // timestamp of frame i
    std::function<void(int, std::vector<drape_joint>&)> edit;  // change frame i's joints
  };
  const std::vector<Case> cases = {
      {"denormal time steps (1e-300 s)", [](int i) { return i * 1e-300; }, nullptr},
      {"one-ulp time steps near 1 s", [](int i) {
         double t = 1.0;
         for (int k = 0; k < i; ++k) t = std::nextafter(t, 2.0);
         return t;
       }, nullptr},
      {"a 1e300 s gap", [](int i) { return i < 10 ? i / 30.0 : 1e300 + (i - 10) * 1e285; }, nullptr},
      {"negative timestamps", [](int i) { return -1000.0 + i / 30.0; }, nullptr},
      {"jumping between +-999 m every frame", [](int i) { return i / 30.0; },
       [](int i, std::vector<drape_joint>& j) {
         if (i < 5) return;
         const float d = (i % 2) ? 996.0f : -1001.0f;  // z: 2.5 + 996 = 998.5, 2.5 - 1001 = -998.5
         for (drape_joint& k : j) k.position.z += d;
       }},
      {"one joint flickering 900 m away", [](int i) { return i / 30.0; },
       [](int i, std::vector<drape_joint>& j) {
         if (i % 3 == 0) j[11].position = drape_vec3{900.0f, -900.0f, 900.0f};
       }},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.name);
    for (int32_t filter : {DRAPE_FILTER_NONE, DRAPE_FILTER_ONE_EURO, DRAPE_FILTER_DOUBLE_EXPONENTIAL}) {
      SCOPED_TRACE(filter);
      drape_context_desc d;
      ASSERT_OK(drape_context_desc_init(&d));
      d.filter = filter;
      ContextPtr ctx = makeContext(&d);
      drape_context* c = ctx.get();
      for (int i = 0; i < 32; ++i) {
        const double t = k.time(i);
        std::vector<drape_joint> j = poseJoints(DRAPE_LAYOUT_KINECT2, i / 30.0);
        if (k.edit) k.edit(i, j);
        const drape_skeleton_frame f = makeFrame(DRAPE_LAYOUT_KINECT2, j, t);
        ASSERT_OK(drape_context_push_skeleton(c, &f)) << "frame " << i << " t=" << t;
        const drape_result r = drape_context_update(c);
        ASSERT_EQ(r, DRAPE_OK) << "frame " << i << " t=" << t << ": " << drape_result_name(r) << " " << lastError();
        const Mesh m = readMesh(c);
        ASSERT_TRUE(allFinite(m.positions)) << "frame " << i;
        ASSERT_TRUE(allFinite(m.normals)) << "frame " << i;
        ASSERT_TRUE(ellipsoidsFinite(m)) << "frame " << i;
        drape_vec3 sk[21];
        ASSERT_OK(drape_context_read_skeleton(c, sk, 21, nullptr));
        ASSERT_TRUE(allFinite(std::vector<drape_vec3>(sk, sk + 21))) << "frame " << i;
      }
      const drape_frame_stats s = stats(c);
      EXPECT_EQ(s.frames_accepted, 32u);
      EXPECT_TRUE(std::isfinite(s.body_volume_l));
    }
  }
}


TEST(Capi, NewestQueuedFrameWins) {
  // Frames 0, then 1, 2, 3 pushed without updates in between, then one update: the body must be
  // exactly that of a context that only ever saw frames 0 and 3.
  ContextPtr a = makeContext(), b = makeContext();
  pushAndUpdate(a.get(), DRAPE_LAYOUT_KINECT2, 0);
  pushAndUpdate(b.get(), DRAPE_LAYOUT_KINECT2, 0);
  for (int i = 1; i <= 3; ++i) {
    const std::vector<drape_joint> j = poseJoints(DRAPE_LAYOUT_KINECT2, i / 30.0);
    const drape_skeleton_frame f = makeFrame(DRAPE_LAYOUT_KINECT2, j, i / 30.0);
    ASSERT_OK(drape_context_push_skeleton(a.get(), &f));
  }
  ASSERT_OK(drape_context_update(a.get()));
  pushAndUpdate(b.get(), DRAPE_LAYOUT_KINECT2, 3);
  EXPECT_TRUE(bitIdentical(readMesh(a.get()), readMesh(b.get())));
  EXPECT_EQ(stats(a.get()).frames_dropped, 2u);
  EXPECT_EQ(stats(b.get()).frames_dropped, 0u);
}

TEST(Capi, DescSettingsTakeEffect) {
  // calibration_frames: calibrated exactly after that many updates.
  drape_context_desc d;
  ASSERT_OK(drape_context_desc_init(&d));
  d.calibration_frames = 5;
  ContextPtr c = makeContext(&d);
  for (int i = 0; i < 4; ++i) pushAndUpdate(c.get(), DRAPE_LAYOUT_KINECT2, i);
  EXPECT_EQ(stats(c.get()).calibrated, 0);
  pushAndUpdate(c.get(), DRAPE_LAYOUT_KINECT2, 4);
  EXPECT_EQ(stats(c.get()).calibrated, 1);

  // teleport_distance_m: the whole person moves 2 m sideways in one frame.
  auto teleportsFor = [](float distance) {
    drape_context_desc dd;
    drape_context_desc_init(&dd);
    dd.teleport_distance_m = distance;
    ContextPtr ctx = makeContext(&dd);
    std::vector<uint8_t> flags;
    for (int i = 0; i < 12; ++i) {
      const double t = i / 30.0;
      std::vector<drape_joint> j = poseJoints(DRAPE_LAYOUT_KINECT2, t);
      if (i >= 6)
        for (drape_joint& k : j) k.position.x += 2.0f;
      const drape_skeleton_frame f = makeFrame(DRAPE_LAYOUT_KINECT2, j, t);
      EXPECT_EQ(drape_context_push_skeleton(ctx.get(), &f), DRAPE_OK);
      EXPECT_EQ(drape_context_update(ctx.get()), DRAPE_OK);
      flags.push_back(stats(ctx.get()).teleported);
    }
    return std::make_pair(stats(ctx.get()).teleports, flags);
  };
  const auto [near, nearFlags] = teleportsFor(0.5f);
  EXPECT_EQ(near, 1u);
  for (int i = 0; i < 12; ++i) EXPECT_EQ(nearFlags[static_cast<size_t>(i)], i == 6 ? 1 : 0) << "update " << i;
  const auto [far, farFlags] = teleportsFor(5.0f);
  EXPECT_EQ(far, 0u);

  // A skeleton flipped upside down (every joint reflected through the pelvis) for frames 6-8: a
  // pose jump on the flip and on the way back, no teleport (the pelvis stays).
  {
    ContextPtr ctx = makeContext(nullptr);
    std::vector<uint8_t> flags;
    for (int i = 0; i < 12; ++i) {
      const double t = i / 30.0;
      std::vector<drape_joint> j = poseJoints(DRAPE_LAYOUT_KINECT2, t);
      const drape_vec3 c = j[0].position;
      if (i >= 6 && i < 9)
        for (drape_joint& k : j) k.position = drape_vec3{2 * c.x - k.position.x, 2 * c.y - k.position.y, 2 * c.z - k.position.z};
      const drape_skeleton_frame f = makeFrame(DRAPE_LAYOUT_KINECT2, j, t);
      EXPECT_EQ(drape_context_push_skeleton(ctx.get(), &f), DRAPE_OK);
      EXPECT_EQ(drape_context_update(ctx.get()), DRAPE_OK);
      flags.push_back(stats(ctx.get()).pose_jumped);
    }
    EXPECT_EQ(stats(ctx.get()).pose_jumps, 2u);
    EXPECT_EQ(stats(ctx.get()).teleports, 0u);
    for (int i = 0; i < 12; ++i) EXPECT_EQ(flags[static_cast<size_t>(i)], i == 6 || i == 9 ? 1 : 0) << "update " << i;
  }

  // A desc from a newer header (larger struct_size) is accepted: only smaller sizes are rejected.
  struct Bigger {
    drape_context_desc desc;
    uint32_t future_fields[4];
  } big;
  std::memset(&big, 0, sizeof(big));
  ASSERT_OK(drape_context_desc_init(&big.desc));
  big.desc.struct_size = sizeof(Bigger);
  drape_context* out = nullptr;
  EXPECT_OK(drape_context_create(&big.desc, &out));
  EXPECT_OK(drape_context_destroy(out));
}


// drape.h: "A destroyed ... pointer passed as a handle returns DRAPE_ERROR_INVALID_HANDLE; it is
// never dereferenced." That must hold even when the allocator hands the destroyed object's
// address to the next object created - the common case with glibc, which reuses a freed block of
// the same size at once.
// Handles were once the objects' addresses, so a stale `a` reused as `b`'s address silently worked
// on `b` (drape_context_update(a) answered CALL_ORDER from b); they are tokens never handed out
// twice since (api_support.h, registerHandle), and this test is what would see the bug come back.
TEST(Capi, StaleHandleStaysInvalidWhenItsAddressIsReused) {
  // destroy immediately followed by create, a few times (nothing else allocates in between).
  std::vector<drape_context*> destroyed;
  std::vector<ContextPtr> fresh;
  bool reused = false;
  for (int i = 0; i < 3; ++i) {
    drape_context* a = nullptr;
    drape_context* b = nullptr;
    const drape_result ra = drape_context_create(nullptr, &a);
    const drape_result rd = drape_context_destroy(a);
    const drape_result rb = drape_context_create(nullptr, &b);
    ASSERT_EQ(ra, DRAPE_OK);
    ASSERT_EQ(rd, DRAPE_OK);
    ASSERT_EQ(rb, DRAPE_OK);
    reused = reused || a == b;
    destroyed.push_back(a);
    fresh.emplace_back(b);
  }
  for (drape_context* stale : destroyed) {
    // Non-destructive calls only: if the bug is present they land on a live context.
    uint32_t nv = 0;
    EXPECT_FAILS(DRAPE_ERROR_INVALID_HANDLE, "drape_context_get_body_mesh_size",
                 drape_context_get_body_mesh_size(stale, &nv, nullptr));
    const std::vector<drape_joint> j = poseJoints(DRAPE_LAYOUT_KINECT2, 0.0);
    const drape_skeleton_frame f = makeFrame(DRAPE_LAYOUT_KINECT2, j, 0.0);
    EXPECT_FAILS(DRAPE_ERROR_INVALID_HANDLE, "drape_context_push_skeleton", drape_context_push_skeleton(stale, &f));
  }
  // Whatever happened above, the fresh contexts must have seen no push.
  for (const ContextPtr& f : fresh) EXPECT_EQ(stats(f.get()).frames_pushed, 0u);
  if (!reused) std::printf("note: the allocator did not reuse a destroyed context's address this run\n");

  // The same for recordings.
  std::string csv = "0";
  for (int k = 0; k < 25; ++k) csv += ",0,0,2,2";
  csv += "\n";
  drape_recording* old = nullptr;
  ASSERT_OK(drape_recording_open_memory(csv.data(), csv.size(), 0, &old));
  ASSERT_OK(drape_recording_destroy(old));
  drape_recording* now = nullptr;
  ASSERT_OK(drape_recording_open_memory(csv.data(), csv.size(), 0, &now));
  RecordingPtr owner(now);
  drape_recording_info info;
  std::memset(&info, 0, sizeof(info));
  info.struct_size = sizeof(info);
  EXPECT_FAILS(DRAPE_ERROR_INVALID_HANDLE, "drape_recording_get_info", drape_recording_get_info(old, &info));
}

// ==========================================================================================
// Tracking ellipsoids and their fidelity.

TEST(Capi, EllipsoidsCallOrderBuffersAndGeometry) {
  for (int32_t rule : {DRAPE_PROXY_RULE_PAPER, DRAPE_PROXY_RULE_DRAPE}) {
    SCOPED_TRACE(rule);
    drape_context_desc d;
    ASSERT_OK(drape_context_desc_init(&d));
    d.proxy_rule = rule;
    ContextPtr ctx = makeContext(&d);
    drape_context* c = ctx.get();
    uint32_t n = 0;
    ASSERT_OK(drape_context_get_ellipsoid_count(c, &n));
    ASSERT_GT(n, 1u);
    std::vector<drape_ellipsoid> ell(n + 1);
    std::vector<float> mats(16 * size_t{n + 1});
    drape_proxy_fidelity fid;
    std::memset(&fid, 0x5A, sizeof(fid));
    fid.struct_size = sizeof(fid);
    const drape_proxy_fidelity fidBefore = fid;
    fillSentinel(ell);
    fillSentinel(mats);
    uint32_t count = 77;
    // Before the first update: CALL_ORDER, nothing written.
    EXPECT_FAILS(DRAPE_ERROR_CALL_ORDER, "drape_context_read_ellipsoids", drape_context_read_ellipsoids(c, ell.data(), n, &count));
    EXPECT_FAILS(DRAPE_ERROR_CALL_ORDER, "drape_context_read_ellipsoid_matrices",
                 drape_context_read_ellipsoid_matrices(c, mats.data(), n, &count));
    EXPECT_FAILS(DRAPE_ERROR_CALL_ORDER, "drape_context_measure_proxy_fidelity", drape_context_measure_proxy_fidelity(c, &fid));
    EXPECT_TRUE(isSentinel(ell));
    EXPECT_TRUE(isSentinel(mats));
    EXPECT_EQ(std::memcmp(&fid, &fidBefore, sizeof(fid)), 0);
    EXPECT_EQ(count, 77u);

    for (int i = 0; i < 35; ++i) pushAndUpdate(c, DRAPE_LAYOUT_KINECT2, i);
    uint32_t n2 = 0;
    ASSERT_OK(drape_context_get_ellipsoid_count(c, &n2));
    EXPECT_EQ(n2, n) << "the count is fixed for a context";
    // Capacity one short: BUFFER_TOO_SMALL, nothing written.
    EXPECT_FAILS(DRAPE_ERROR_BUFFER_TOO_SMALL, "drape_context_read_ellipsoids",
                 drape_context_read_ellipsoids(c, ell.data(), n - 1, &count));
    EXPECT_FAILS(DRAPE_ERROR_BUFFER_TOO_SMALL, "drape_context_read_ellipsoid_matrices",
                 drape_context_read_ellipsoid_matrices(c, mats.data(), n - 1, &count));
    EXPECT_FAILS(DRAPE_ERROR_BUFFER_TOO_SMALL, "drape_context_read_ellipsoids", drape_context_read_ellipsoids(c, ell.data(), 0, nullptr));
    EXPECT_TRUE(isSentinel(ell));
    EXPECT_TRUE(isSentinel(mats));
    EXPECT_EQ(count, 77u);
    // Exact capacity, out_count optional; nothing written past n.
    ASSERT_OK(drape_context_read_ellipsoids(c, ell.data(), n, nullptr));
    ASSERT_OK(drape_context_read_ellipsoid_matrices(c, mats.data(), n, &count));
    EXPECT_EQ(count, n);
    EXPECT_TRUE(isSentinel(std::vector<drape_ellipsoid>(ell.end() - 1, ell.end())));
    EXPECT_TRUE(isSentinel(std::vector<float>(mats.end() - 16, mats.end())));
    const V pelvis = kinect2Pose(34 / 30.0)[0];
    for (uint32_t i = 0; i < n; ++i) {
      SCOPED_TRACE(i);
      const drape_ellipsoid& e = ell[i];
      const drape_vec3 ax[3] = {e.axis_x, e.axis_y, e.axis_z};
      const float r[3] = {e.radii.x, e.radii.y, e.radii.z};
      auto dot = [](drape_vec3 a, drape_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; };
      for (int a = 0; a < 3; ++a) {
        EXPECT_NEAR(dot(ax[a], ax[a]), 1.0f, 1e-4f) << "axis " << a << " not unit";
        for (int b = a + 1; b < 3; ++b) EXPECT_NEAR(dot(ax[a], ax[b]), 0.0f, 1e-4f) << "axes " << a << "," << b;
        EXPECT_GT(r[a], 0.0f);
        EXPECT_LT(r[a], 1.0f) << "a semi-axis of a body part longer than 1 m";
      }
      // axis_z = axis_x x axis_y (a rotation, not a reflection).
      const drape_vec3 cr{ax[0].y * ax[1].z - ax[0].z * ax[1].y, ax[0].z * ax[1].x - ax[0].x * ax[1].z,
                          ax[0].x * ax[1].y - ax[0].y * ax[1].x};
      EXPECT_NEAR(dot(cr, ax[2]), 1.0f, 1e-4f);
      EXPECT_GE(e.chain, 0);
      EXPECT_LE(e.chain, 5);
      EXPECT_GE(e.ring, 0);
      const float dx = e.centre.x - pelvis.x, dy = e.centre.y - pelvis.y, dz = e.centre.z - pelvis.z;
      EXPECT_LT(std::sqrt(dx * dx + dy * dy + dz * dz), 1.2f) << "ellipsoid centre far from the person";
      // The matrix is T * R * S, column-major: columns = radii-scaled axes, then the centre.
      const float* m = &mats[16 * size_t{i}];
      for (int a = 0; a < 3; ++a) {
        EXPECT_NEAR(m[4 * a + 0], ax[a].x * r[a], 1e-5f);
        EXPECT_NEAR(m[4 * a + 1], ax[a].y * r[a], 1e-5f);
        EXPECT_NEAR(m[4 * a + 2], ax[a].z * r[a], 1e-5f);
        EXPECT_EQ(m[4 * a + 3], 0.0f);
      }
      EXPECT_FLOAT_EQ(m[12], e.centre.x);
      EXPECT_FLOAT_EQ(m[13], e.centre.y);
      EXPECT_FLOAT_EQ(m[14], e.centre.z);
      EXPECT_EQ(m[15], 1.0f);
    }
    // Every chain has at least one ellipsoid.
    for (int chain = 0; chain < 6; ++chain) {
      bool found = false;
      for (uint32_t i = 0; i < n; ++i) found = found || ell[i].chain == chain;
      EXPECT_TRUE(found) << "no ellipsoid on chain " << chain;
    }

    // Fidelity: plausible numbers, and measuring changes nothing (twice gives the same report,
    // the mesh and ellipsoids are untouched).
    const Mesh before = readMesh(c);
    ASSERT_OK(drape_context_measure_proxy_fidelity(c, &fid));
    EXPECT_EQ(fid.struct_size, sizeof(fid));
    EXPECT_GT(fid.union_samples, 0u);
    const float* vals = &fid.body_to_proxy_mean_mm;
    for (int k = 0; k < 7; ++k) {
      EXPECT_TRUE(std::isfinite(vals[k])) << k;
      EXPECT_GE(vals[k], 0.0f) << k;
    }
    // (mean <= p95 need not hold: with most vertices inside, a few far ones lift the mean.)
    EXPECT_LE(fid.body_to_proxy_mean_mm, fid.body_to_proxy_max_mm);
    EXPECT_LE(fid.body_to_proxy_p95_mm, fid.body_to_proxy_max_mm);
    EXPECT_LE(fid.proxy_to_body_mean_mm, fid.proxy_to_body_max_mm);
    EXPECT_LE(fid.proxy_to_body_p95_mm, fid.proxy_to_body_max_mm);
    EXPECT_LE(fid.outside_fraction, 1.0f);
    EXPECT_LT(fid.body_to_proxy_max_mm, 200.0f) << "the ellipsoids should follow the body within centimetres";
    drape_proxy_fidelity fid2;
    std::memset(&fid2, 0, sizeof(fid2));
    fid2.struct_size = sizeof(fid2);
    ASSERT_OK(drape_context_measure_proxy_fidelity(c, &fid2));
    EXPECT_EQ(std::memcmp(&fid, &fid2, sizeof(fid)), 0);
    EXPECT_TRUE(bitIdentical(before, readMesh(c)));
  }
}

// drape.h documents `reserved` fields as 0 (drape_skeleton_frame.reserved). A field that must be
// 0 is only reservable for later use if non-zero values are rejected now; otherwise hosts that
// leave garbage there break silently when it gains a meaning. (drape_context_desc's reserved field
// became garment_fit that way: 0 is its default, anything but 0 and 1 is refused.)
TEST(Capi, ReservedFieldsMustBeZero) {
  drape_context_desc d;
  ASSERT_OK(drape_context_desc_init(&d));
  for (int32_t fit : {2, -1, 0x7fffffff}) {
    d.garment_fit = fit;
    drape_context* out = kContextSentinel;
    EXPECT_FAILS(DRAPE_ERROR_OUT_OF_RANGE, "drape_context_create", drape_context_create(&d, &out));
    if (out != kContextSentinel) drape_context_destroy(out);
  }

  ContextPtr ctx = makeContext();
  const std::vector<drape_joint> j = poseJoints(DRAPE_LAYOUT_KINECT2, 0.0);
  drape_skeleton_frame f = makeFrame(DRAPE_LAYOUT_KINECT2, j, 0.0);
  f.reserved = 0xdeadbeefu;
  EXPECT_FAILS(DRAPE_ERROR_INVALID_ARGUMENT, "drape_context_push_skeleton", drape_context_push_skeleton(ctx.get(), &f));
  EXPECT_EQ(stats(ctx.get()).frames_rejected, 1u);
}

}  // namespace
