// Recorded skeleton streams: Kinect v2 CSV (the Microsoft Labanotation captures), CMU BVH motion
// capture (mapped onto the Kinect v2 layout) and our own text format ".drec".
//
// Formats, units, axes and the BVH joint mapping are described in docs/recording-format.md.
// Every function here is called behind the C ABI: none throws (std::bad_alloc included) and none
// aborts, whatever bytes it is given. On failure `out` is left untouched and `err` says why.
#pragma once

#include "skeleton/joints.h"

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace drape {

enum class RecordingFormat : int { Unknown = 0, KinectCsv = 1, Bvh = 2, Drape = 3 };  // ABI-visible

struct RecordingFrame {
  double time_s = 0;               // seconds; strictly increasing within a recording
  std::vector<JointSample> joints;  // layoutJointCount(layout) samples, in the layout's order
};

struct Recording {
  RecordingFormat format = RecordingFormat::Unknown;
  Layout layout = Layout::Kinect2;
  float nominal_rate_hz = 30;  // 1 / median frame interval (a .drec `rate` line, a BVH Frame Time)
  std::vector<RecordingFrame> frames;
};

// Why a reader or writer failed, for callers that map failures onto error codes (the C ABI's
// DRAPE_ERROR_IO / _PARSE / _OUT_OF_MEMORY / _INVALID_ARGUMENT). Every function below that takes
// an optional `RecordingError*` sets it to None on success.
enum class RecordingError : int {
  None = 0,
  Io = 1,               // the file could not be opened, read or written (missing, a directory, too large)
  Parse = 2,            // the content is not a recording we read, or contradicts the layout hint
  OutOfMemory = 3,
  InvalidArgument = 4,  // a layout hint outside 0..3; a recording that cannot be written as is
  Internal = 5,         // an unexpected exception (a bug)
};
const char* recordingErrorName(RecordingError e);  // "none", "io", "parse", ...

// Limits that keep the readers safe on hostile input.
constexpr int kRecordingMaxFrames = 10'000'000;
constexpr std::size_t kRecordingMaxFileBytes = std::size_t{512} << 20;  // readRecordingFile
constexpr int kBvhMaxJoints = 256;  // ROOT + JOINT nodes (End Sites have their own cap of the same size)
constexpr int kBvhMaxDepth = 64;

// "unknown", "kinect-csv", "bvh", "drape".
const char* recordingFormatName(RecordingFormat format);

// Format from the content alone: a first token "drape-recording" -> Drape, "HIERARCHY" -> Bvh,
// a number -> KinectCsv, anything else -> Unknown (a UTF-8 BOM and leading whitespace are skipped).
RecordingFormat detectRecordingFormat(std::string_view text);

// Parses any supported format. `layoutHint`: 0 = take the layout from the content; 1/2/3 = the
// caller expects Kinect1/Kinect2/Azure, and content of another layout is an error.
bool parseRecording(std::string_view text, int layoutHint, Recording& out, std::string& err,
                    RecordingError* errorKind = nullptr);

// Reads and parses a file (at most kRecordingMaxFileBytes). Every message names the path.
bool readRecordingFile(const std::string& path, int layoutHint, Recording& out, std::string& err,
                       RecordingError* errorKind = nullptr);

// Our own text format (see docs/recording-format.md). Floats are written in their shortest
// round-trip form, so write -> parse reproduces every value exactly. Returns "" only when out of
// memory; an inconsistent recording is written as is (the reader then rejects it).
std::string writeDrapeRecording(const Recording& rec);
// Checks the recording first (valid layout, joint counts, finite values, states 0..2, increasing
// times); false with a message naming the path on a bad recording or an IO error.
bool writeDrapeRecordingFile(const Recording& rec, const std::string& path, std::string& err,
                             RecordingError* errorKind = nullptr);

// What the BVH importer decided, for diagnostics and tests.
struct BvhImportInfo {
  double metres_per_unit = 1;       // detected unit (see docs: CMU/cgspeed units = 0.0254/0.45 m)
  const char* unit_name = "";       // "metre", "cmu-unit", "inch", "centimetre", "millimetre"
  double rest_extent_units = 0;     // largest axis extent of the rest pose, in file units
  int joint_count = 0;              // ROOT + JOINT nodes
  int channel_count = 0;            // numbers per frame line
  double frame_time_s = 0;
};

// BVH only (the path parseRecording takes for BVH content); `info` may be null.
bool parseBvhRecording(std::string_view text, int layoutHint, Recording& out, std::string& err,
                       BvhImportInfo* info = nullptr);

// BVH subjects are placed this far in front of the virtual Kinect (camera z = 3 m - BVH z).
constexpr double kBvhSensorDistanceM = 3.0;

}  // namespace drape
