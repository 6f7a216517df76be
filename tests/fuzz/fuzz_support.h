// Shared by the fuzz targets: the entry-point macro and the checks that turn a silent wrong answer
// into a crash libFuzzer (or the regression test) reports.
//
// A target is written once as
//   DRAPE_FUZZ_TARGET(recording) { ... return 0; }
// and built two ways:
//  - with clang and -fsanitize=fuzzer (DRAPE_FUZZ_LIBFUZZER defined): the function is also
//    LLVMFuzzerTestOneInput, the libFuzzer entry point (tests/fuzz/CMakeLists.txt, tests/fuzz/run.sh);
//  - into drape_fuzz_regressions (any compiler, any build, the ASan one included): a GoogleTest that
//    replays every committed crash input and the generated seed corpus through
//    drape_fuzz_<name>() (tests/fuzz/test_fuzz_regressions.cpp).
// Everything goes through the public C ABI (drape/drape.h) only.
#pragma once

#include "drape/drape.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#ifdef DRAPE_FUZZ_LIBFUZZER
#define DRAPE_FUZZ_ENTRY(name) \
  extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) { return drape_fuzz_##name(data, size); }
#else
#define DRAPE_FUZZ_ENTRY(name)
#endif

#define DRAPE_FUZZ_TARGET(name)                            \
  int drape_fuzz_##name(const uint8_t* data, size_t size); \
  DRAPE_FUZZ_ENTRY(name)                                   \
  int drape_fuzz_##name(const uint8_t* data, size_t size)

int drape_fuzz_recording(const uint8_t* data, size_t size);
int drape_fuzz_obj(const uint8_t* data, size_t size);
int drape_fuzz_capi(const uint8_t* data, size_t size);

namespace drape_fuzz {

// A finding: print what broke (with the library's last error) and abort, so that libFuzzer saves
// the input and the regression test fails.
[[noreturn]] inline void bug(const char* what, const char* detail = "") {
  std::fprintf(stderr, "\n==drape-fuzz== BUG: %s %s\n==drape-fuzz== drape_last_error(): %s\n", what, detail,
               drape_last_error());
  std::fflush(stderr);
  std::abort();
}

#define DRAPE_FUZZ_CHECK(cond, what) \
  do {                               \
    if (!(cond)) ::drape_fuzz::bug(what, "(" #cond ")"); \
  } while (0)

// Every result is allowed except DRAPE_ERROR_INTERNAL ("a bug in Drape") and codes outside the enum.
inline drape_result checked(drape_result r, const char* call) {
  if (r == DRAPE_ERROR_INTERNAL) bug("DRAPE_ERROR_INTERNAL from", call);
  if (r < DRAPE_OK || r > DRAPE_ERROR_INTERNAL) bug("result code outside drape_result from", call);
  if (r != DRAPE_OK) {
    const char* m = drape_last_error();
    if (!m || !*m) bug("failed call left no drape_last_error() message:", call);
  }
  return r;
}
#define DRAPE_FUZZ_CALL(expr) ::drape_fuzz::checked((expr), #expr)

inline bool finite3(const drape_vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
inline bool allFinite(const float* f, size_t n) {
  for (size_t i = 0; i < n; ++i)
    if (!std::isfinite(f[i])) return false;
  return true;
}

// Reads little-endian values from the input; past the end it returns zeros.
class Bytes {
 public:
  Bytes(const uint8_t* d, size_t n) : d_(d), n_(n) {}
  bool empty() const { return i_ >= n_; }
  size_t left() const { return i_ < n_ ? n_ - i_ : 0; }
  uint8_t u8() { return i_ < n_ ? d_[i_++] : 0; }
  uint16_t u16() { return static_cast<uint16_t>(u8() | (u8() << 8)); }
  uint32_t u32() { return static_cast<uint32_t>(u16()) | (static_cast<uint32_t>(u16()) << 16); }
  float rawFloat() {
    const uint32_t b = u32();
    float f;
    std::memcpy(&f, &b, sizeof f);
    return f;
  }
  // One of the values that break numerical code, or a raw float from the input.
  float nasty() {
    static const float kValues[] = {0.0f, -0.0f, 1.0f, -1.0f, 1e30f, -1e30f, 1e-30f, 1e-45f, 1000.0f, 1000.001f,
                                    -1000.001f, 3.4e38f, NAN, INFINITY, -INFINITY, 0.5f};
    const uint8_t k = u8();
    if (k < 16) return kValues[k];
    return rawFloat();
  }
  // A value in [lo, hi] most of the time, a nasty one sometimes.
  float inRange(float lo, float hi) {
    const uint8_t k = u8();
    if (k >= 240) return nasty();
    return lo + (hi - lo) * static_cast<float>(k) / 239.0f;
  }

 private:
  const uint8_t* d_;
  size_t n_;
  size_t i_ = 0;
};

// A person standing 2.5 m from the sensor (Kinect v2 order, metres); `t` animates a sway and, with
// arm_swing_m > 0, the arms swinging back and forth by that much (the C ABI and OBJ targets).
inline void standingPose25(double t, float arm_swing_m, drape_joint* j) {
  static const float p[25][3] = {
      {0.00f, 0.00f, 2.5f},    {0.00f, 0.30f, 2.5f},   {0.00f, 0.60f, 2.5f},   {0.00f, 0.75f, 2.48f},
      {-0.18f, 0.50f, 2.5f},   {-0.24f, 0.24f, 2.5f},  {-0.27f, 0.01f, 2.48f}, {-0.28f, -0.06f, 2.47f},
      {0.18f, 0.50f, 2.5f},    {0.24f, 0.24f, 2.5f},   {0.27f, 0.01f, 2.48f},  {0.28f, -0.06f, 2.47f},
      {-0.08f, -0.02f, 2.5f},  {-0.09f, -0.45f, 2.52f}, {-0.09f, -0.85f, 2.55f}, {-0.09f, -0.92f, 2.45f},
      {0.08f, -0.02f, 2.5f},   {0.09f, -0.45f, 2.52f}, {0.09f, -0.85f, 2.55f}, {0.09f, -0.92f, 2.45f},
      {0.00f, 0.52f, 2.5f},    {-0.29f, -0.14f, 2.47f}, {-0.25f, -0.08f, 2.43f}, {0.29f, -0.14f, 2.47f},
      {0.25f, -0.08f, 2.43f}};
  const float sway = 0.03f * static_cast<float>(std::sin(1.3 * t));
  const float swing = arm_swing_m * static_cast<float>(std::sin(2.1 * t));
  for (int i = 0; i < 25; ++i) {
    const bool left_arm = i == 5 || i == 6 || i == 7 || i == 21 || i == 22;
    const bool right_arm = i == 9 || i == 10 || i == 11 || i == 23 || i == 24;
    j[i].position = drape_vec3{p[i][0] + sway, p[i][1], p[i][2] + (left_arm ? swing : right_arm ? -swing : 0.0f)};
    j[i].tracking_state = DRAPE_TRACKING_TRACKED;
  }
}

}  // namespace drape_fuzz
