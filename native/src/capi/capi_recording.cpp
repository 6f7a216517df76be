// C entry points for recordings: open from file or memory, query, read frames, save.
#include "capi/api_support.h"
#include "recording/recording.h"

#include <cstring>
#include <memory>

using namespace drape::api;

namespace {

// Resolves the handle into `self` (declared by the macro) or returns the error.
#define DRAPE_CHECK_RECORDING(fn, handle)                                                        \
  if (!(handle)) return fail(DRAPE_ERROR_NULL_ARGUMENT, fn ": recording is NULL");               \
  drape::Recording* const self =                                                                 \
      static_cast<drape::Recording*>(resolveHandle(HandleKind::Recording, handle));              \
  if (!self) return fail(DRAPE_ERROR_INVALID_HANDLE, fn ": recording is not a live drape_recording")

drape_result checkLayoutHint(const char* fn, int32_t layout) {
  if (layout < DRAPE_LAYOUT_AUTO || layout > DRAPE_LAYOUT_AZURE)
    return fail(DRAPE_ERROR_OUT_OF_RANGE, std::string(fn) + ": layout " + std::to_string(layout) +
                                              " is not 0 (auto), 1, 2 or 3");
  return DRAPE_OK;
}

drape_result codeFor(drape::RecordingError kind) {
  switch (kind) {
    case drape::RecordingError::Io: return DRAPE_ERROR_IO;
    case drape::RecordingError::OutOfMemory: return DRAPE_ERROR_OUT_OF_MEMORY;
    case drape::RecordingError::InvalidArgument: return DRAPE_ERROR_INVALID_ARGUMENT;
    case drape::RecordingError::Internal: return DRAPE_ERROR_INTERNAL;
    default: return DRAPE_ERROR_PARSE;
  }
}

drape_result adopt(std::unique_ptr<drape::Recording> rec, drape_recording** out) {
  void* token = registerHandle(HandleKind::Recording, rec.get());
  rec.release();  // owned by the registry entry until drape_recording_destroy
  *out = static_cast<drape_recording*>(token);
  return DRAPE_OK;
}

}  // namespace

extern "C" {

DRAPE_API drape_result DRAPE_CALL drape_recording_open(const char* path, int32_t layout,
                                                       drape_recording** out_recording) {
  return guarded("drape_recording_open", [&]() -> drape_result {
    if (!path) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_recording_open: path is NULL");
    if (!out_recording) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_recording_open: out_recording is NULL");
    if (drape_result r = checkLayoutHint("drape_recording_open", layout)) return r;
    auto rec = std::make_unique<drape::Recording>();
    std::string err;
    drape::RecordingError kind = drape::RecordingError::None;
    if (!drape::readRecordingFile(path, layout, *rec, err, &kind))
      return fail(codeFor(kind), "drape_recording_open: " + err);
    return adopt(std::move(rec), out_recording);
  });
}

DRAPE_API drape_result DRAPE_CALL drape_recording_open_memory(const void* data, size_t size, int32_t layout,
                                                              drape_recording** out_recording) {
  return guarded("drape_recording_open_memory", [&]() -> drape_result {
    if (!data && size > 0) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_recording_open_memory: data is NULL");
    if (!out_recording) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_recording_open_memory: out_recording is NULL");
    if (drape_result r = checkLayoutHint("drape_recording_open_memory", layout)) return r;
    auto rec = std::make_unique<drape::Recording>();
    std::string err;
    const std::string_view text(static_cast<const char*>(data), data ? size : 0);
    drape::RecordingError kind = drape::RecordingError::None;
    if (!drape::parseRecording(text, layout, *rec, err, &kind))
      return fail(codeFor(kind), "drape_recording_open_memory: " + err);
    return adopt(std::move(rec), out_recording);
  });
}

DRAPE_API drape_result DRAPE_CALL drape_recording_destroy(drape_recording* recording) {
  return guarded("drape_recording_destroy", [&]() -> drape_result {
    if (!recording) return DRAPE_OK;
    auto* rec = static_cast<drape::Recording*>(unregisterHandle(HandleKind::Recording, recording));
    if (!rec) return fail(DRAPE_ERROR_INVALID_HANDLE, "drape_recording_destroy: recording is not a live drape_recording");
    delete rec;
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_recording_get_info(drape_recording* recording, drape_recording_info* out_info) {
  return guarded("drape_recording_get_info", [&]() -> drape_result {
    DRAPE_CHECK_RECORDING("drape_recording_get_info", recording);
    if (!out_info) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_recording_get_info: out_info is NULL");
    if (drape_result r = checkStructSize(out_info->struct_size, sizeof(drape_recording_info), "drape_recording_info"))
      return r;
    const drape::Recording& rec = *self;
    drape_recording_info info;
    std::memset(&info, 0, sizeof(info));
    info.struct_size = sizeof(info);
    info.format = static_cast<int32_t>(rec.format);
    info.layout = static_cast<int32_t>(rec.layout);
    info.joint_count = static_cast<uint32_t>(drape::layoutJointCount(rec.layout));
    info.frame_count = static_cast<uint32_t>(rec.frames.size());
    info.nominal_rate_hz = rec.nominal_rate_hz;
    info.duration_s = rec.frames.empty() ? 0.0 : rec.frames.back().time_s - rec.frames.front().time_s;
    *out_info = info;
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_recording_read_frame(drape_recording* recording, uint32_t index,
                                                             drape_joint* joints, uint32_t capacity,
                                                             double* out_timestamp_s) {
  return guarded("drape_recording_read_frame", [&]() -> drape_result {
    DRAPE_CHECK_RECORDING("drape_recording_read_frame", recording);
    if (!joints) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_recording_read_frame: joints is NULL");
    const drape::Recording& rec = *self;
    if (index >= rec.frames.size())
      return fail(DRAPE_ERROR_OUT_OF_RANGE, "drape_recording_read_frame: index " + std::to_string(index) +
                                                " >= frame count " + std::to_string(rec.frames.size()));
    const drape::RecordingFrame& f = rec.frames[index];
    if (capacity < f.joints.size())
      return fail(DRAPE_ERROR_BUFFER_TOO_SMALL, "drape_recording_read_frame: capacity " + std::to_string(capacity) +
                                                    " < " + std::to_string(f.joints.size()) + " joints");
    for (size_t j = 0; j < f.joints.size(); ++j) {
      const auto& s = f.joints[j];
      joints[j].position = drape_vec3{s.position.x(), s.position.y(), s.position.z()};
      joints[j].tracking_state = static_cast<int32_t>(s.state);
    }
    if (out_timestamp_s) *out_timestamp_s = f.time_s - rec.frames.front().time_s;
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_recording_save(drape_recording* recording, const char* path) {
  return guarded("drape_recording_save", [&]() -> drape_result {
    DRAPE_CHECK_RECORDING("drape_recording_save", recording);
    if (!path) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_recording_save: path is NULL");
    std::string err;
    drape::RecordingError kind = drape::RecordingError::None;
    if (!drape::writeDrapeRecordingFile(*self, path, err, &kind))
      return fail(kind == drape::RecordingError::Io ? DRAPE_ERROR_IO : codeFor(kind), "drape_recording_save: " + err);
    return DRAPE_OK;
  });
}

}  // extern "C"
