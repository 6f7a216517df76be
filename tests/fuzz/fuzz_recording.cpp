// Fuzz target: the recording readers (Kinect CSV, BVH, .drec) through drape_recording_open_memory.
// The input is the file's bytes. When the reader accepts it, every frame is read back and checked
// (finite, strictly increasing timestamps from 0, states 0..2), the recording must reopen with its
// own layout as the hint, and a .drec written from it must read back bit-identical.
#include "fuzz_support.h"

#include <string>
#include <unistd.h>
#include <vector>

using namespace drape_fuzz;

namespace {

struct Frames {
  drape_recording_info info{};
  std::vector<drape_joint> joints;
  std::vector<double> times;
};

// Reads and checks every frame of an open recording.
Frames readAll(drape_recording* rec) {
  Frames out;
  out.info.struct_size = sizeof(out.info);
  DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_recording_get_info(rec, &out.info)) == DRAPE_OK, "get_info on a live recording");
  const drape_recording_info& info = out.info;
  DRAPE_FUZZ_CHECK(info.format >= DRAPE_RECORDING_KINECT_CSV && info.format <= DRAPE_RECORDING_DRAPE, "format");
  DRAPE_FUZZ_CHECK((info.layout == DRAPE_LAYOUT_KINECT1 && info.joint_count == 20) ||
                       (info.layout == DRAPE_LAYOUT_KINECT2 && info.joint_count == 25) ||
                       (info.layout == DRAPE_LAYOUT_AZURE && info.joint_count == 32),
                   "layout and joint count agree");
  DRAPE_FUZZ_CHECK(info.frame_count >= 1, "an accepted recording has frames");
  DRAPE_FUZZ_CHECK(std::isfinite(info.nominal_rate_hz) && info.nominal_rate_hz > 0.0f, "nominal rate finite and > 0");
  DRAPE_FUZZ_CHECK(std::isfinite(info.duration_s) && info.duration_s >= 0.0, "duration finite and >= 0");
  const uint32_t n = info.joint_count;
  std::vector<drape_joint> frame(n + 1);
  // Capacity one short: refused, buffer untouched.
  std::memset(frame.data(), 0x5a, sizeof(drape_joint) * frame.size());
  DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_recording_read_frame(rec, 0, frame.data(), n - 1, nullptr)) ==
                       DRAPE_ERROR_BUFFER_TOO_SMALL,
                   "capacity below joint_count is refused");
  DRAPE_FUZZ_CHECK(reinterpret_cast<const uint8_t*>(frame.data())[0] == 0x5a, "refused read left the buffer alone");
  DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_recording_read_frame(rec, info.frame_count, frame.data(), n, nullptr)) ==
                       DRAPE_ERROR_OUT_OF_RANGE,
                   "index == frame_count is refused");
  double prev = -1.0;
  for (uint32_t i = 0; i < info.frame_count; ++i) {
    double t = -2.0;
    DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_recording_read_frame(rec, i, frame.data(), n + 1, &t)) == DRAPE_OK,
                     "read_frame of a valid index");
    DRAPE_FUZZ_CHECK(std::isfinite(t), "timestamp finite");
    if (i == 0) DRAPE_FUZZ_CHECK(t == 0.0, "recording timestamps start at 0");
    else DRAPE_FUZZ_CHECK(t > prev, "timestamps strictly increasing");
    prev = t;
    for (uint32_t j = 0; j < n; ++j) {
      DRAPE_FUZZ_CHECK(finite3(frame[j].position), "joint position finite");
      DRAPE_FUZZ_CHECK(frame[j].tracking_state >= 0 && frame[j].tracking_state <= 2, "tracking state 0..2");
    }
    out.joints.insert(out.joints.end(), frame.begin(), frame.begin() + n);
    out.times.push_back(t);
  }
  DRAPE_FUZZ_CHECK(info.duration_s == prev, "duration is the last timestamp");
  return out;
}

}  // namespace

DRAPE_FUZZ_TARGET(recording) {
  if (size > (1u << 20)) return 0;  // the readers are linear; bigger inputs only slow the fuzzer down
  drape_recording* rec = nullptr;
  const drape_result r = DRAPE_FUZZ_CALL(drape_recording_open_memory(data, size, DRAPE_LAYOUT_AUTO, &rec));
  if (r != DRAPE_OK) {
    DRAPE_FUZZ_CHECK(rec == nullptr, "a failed open leaves *out_recording alone");
    return 0;
  }
  DRAPE_FUZZ_CHECK(rec != nullptr, "open returned OK and a handle");
  const Frames a = readAll(rec);

  // The content's own layout as the hint is accepted; another layout is refused.
  drape_recording* again = nullptr;
  DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_recording_open_memory(data, size, a.info.layout, &again)) == DRAPE_OK,
                   "reopening with the detected layout as the hint");
  DRAPE_FUZZ_CALL(drape_recording_destroy(again));
  const int32_t other = a.info.layout == DRAPE_LAYOUT_KINECT2 ? DRAPE_LAYOUT_AZURE : DRAPE_LAYOUT_KINECT2;
  again = nullptr;
  DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_recording_open_memory(data, size, other, &again)) != DRAPE_OK,
                   "another layout as the hint is refused");
  DRAPE_FUZZ_CHECK(again == nullptr, "refused open leaves the out pointer alone");

  // Save as .drec and read it back: the same frames, bit for bit.
  if (a.info.frame_count <= 2000) {
    const std::string path = "/tmp/drape_fuzz_recording_" + std::to_string(getpid()) + ".drec";
    if (DRAPE_FUZZ_CALL(drape_recording_save(rec, path.c_str())) == DRAPE_OK) {
      drape_recording* back = nullptr;
      DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_recording_open(path.c_str(), DRAPE_LAYOUT_AUTO, &back)) == DRAPE_OK,
                       "a saved .drec reopens");
      const Frames b = readAll(back);
      DRAPE_FUZZ_CHECK(b.info.format == DRAPE_RECORDING_DRAPE, "saved file is a .drec");
      DRAPE_FUZZ_CHECK(b.info.layout == a.info.layout && b.info.frame_count == a.info.frame_count,
                       ".drec keeps layout and frame count");
      for (size_t i = 0; i < a.joints.size(); ++i) {
        DRAPE_FUZZ_CHECK(std::memcmp(&a.joints[i].position, &b.joints[i].position, sizeof(drape_vec3)) == 0 &&
                             a.joints[i].tracking_state == b.joints[i].tracking_state,
                         ".drec round trip keeps every joint bit for bit");
      }
      for (size_t i = 0; i < a.times.size(); ++i)
        DRAPE_FUZZ_CHECK(a.times[i] == b.times[i], ".drec round trip keeps every timestamp");
      DRAPE_FUZZ_CALL(drape_recording_destroy(back));
    }
    std::remove(path.c_str());
  }
  DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_recording_destroy(rec)) == DRAPE_OK, "destroy");
  DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_recording_destroy(rec)) == DRAPE_ERROR_INVALID_HANDLE,
                   "second destroy is INVALID_HANDLE");
  return 0;
}
