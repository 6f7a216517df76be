// Kinect CSV (the Microsoft Labanotation KinectReader captures):
//   ticks, X0, Y0, Z0, state0, X1, ... , state(N-1),      <- trailing comma optional
// no header, N = 20 / 25 / 32 joints (Kinect1 / Kinect2 / Azure order), ticks in 100 ns units,
// positions in metres (camera space), states 0 = NotTracked, 1 = Inferred, 2 = Tracked.
// The whole file is rejected on the first bad row, with its line number.
#include "recording/recording_internal.h"

#include <string>
#include <vector>

namespace drape::recording_detail {

namespace {

bool layoutForJointCount(int joints, Layout& layout) {
  for (const Layout l : {Layout::Kinect1, Layout::Kinect2, Layout::Azure}) {
    if (layoutJointCount(l) == joints) {
      layout = l;
      return true;
    }
  }
  return false;
}

const char* kAxis[3] = {"x", "y", "z"};

}  // namespace

bool parseKinectCsv(std::string_view text, int layoutHint, Recording& out, std::string& err) {
  out = Recording{};
  out.format = RecordingFormat::KinectCsv;

  LineReader lines(text);
  std::string_view line;
  std::vector<std::string_view> fields;
  std::size_t expectedFields = 0;  // set by the first row
  int jointCount = 0;
  int64_t firstTicks = 0, prevTicks = 0;
  bool first = true;

  while (lines.next(line)) {
    const int ln = lines.number();
    if (ln == 1) line = stripBom(line);
    const std::string_view row = trim(line);
    if (row.empty()) continue;  // blank lines (e.g. the one after the last newline) are ignored

    // Split on commas; a single trailing comma ends the row.
    fields.clear();
    std::size_t start = 0;
    for (;;) {
      const std::size_t comma = row.find(',', start);
      if (comma == std::string_view::npos) {
        fields.push_back(trim(row.substr(start)));
        break;
      }
      fields.push_back(trim(row.substr(start, comma - start)));
      start = comma + 1;
      if (fields.size() > 1 + 4 * 32 + 1) break;  // already too many for any layout
    }
    if (fields.size() > 1 && fields.back().empty()) fields.pop_back();

    if (first) {
      const std::size_t n = fields.size();
      Layout layout = Layout::Kinect2;
      if (n < 5 || (n - 1) % 4 != 0 || !layoutForJointCount(static_cast<int>((n - 1) / 4), layout)) {
        err = lineMsg(ln, std::to_string(n) + (n > 1 + 4 * 32 ? "+" : "") +
                              " fields; a Kinect CSV row is a timestamp followed by N x (X, Y, Z, state) with N = 20, "
                              "25 or 32 joints (81, 101 or 129 fields)");
        return false;
      }
      if (!checkLayoutHint(layoutHint, layout, "line " + std::to_string(ln) + " has " +
                                                   std::to_string(layoutJointCount(layout)) + " joints, so the file",
                           err))
        return false;
      out.layout = layout;
      expectedFields = n;
      jointCount = layoutJointCount(layout);
    } else if (fields.size() != expectedFields) {
      err = lineMsg(ln, std::to_string(fields.size()) + (fields.size() > 1 + 4 * 32 ? "+" : "") + " fields, expected " +
                            std::to_string(expectedFields) + " like line 1 (" + std::to_string(jointCount) + " joints)");
      return false;
    }

    int64_t ticks = 0;
    if (!parseInt64(fields[0], ticks) || ticks < 0) {
      err = lineMsg(ln, "timestamp " + quoted(fields[0]) + " is not a non-negative integer tick count");
      return false;
    }
    if (first) {
      firstTicks = ticks;
    } else if (ticks <= prevTicks) {
      err = lineMsg(ln, "timestamp " + std::to_string(ticks) + (ticks == prevTicks ? " repeats" : " goes backwards from") +
                            " the previous frame's " + std::to_string(prevTicks) + "; timestamps must increase");
      return false;
    }
    prevTicks = ticks;

    if (out.frames.size() >= static_cast<std::size_t>(kRecordingMaxFrames)) {
      err = lineMsg(ln, "more than " + std::to_string(kRecordingMaxFrames) + " frames");
      return false;
    }
    RecordingFrame frame;
    frame.time_s = static_cast<double>(ticks - firstTicks) * 1e-7;
    frame.joints.resize(static_cast<std::size_t>(jointCount));
    for (int j = 0; j < jointCount; ++j) {
      JointSample& s = frame.joints[static_cast<std::size_t>(j)];
      for (int a = 0; a < 3; ++a) {
        const std::size_t f = 1 + 4 * static_cast<std::size_t>(j) + static_cast<std::size_t>(a);
        if (!parseFloat(fields[f], s.position[a])) {
          err = lineMsg(ln, "field " + std::to_string(f + 1) + " (joint " + std::to_string(j) + " " + kAxis[a] + "): " +
                                quoted(fields[f]) + " is not a finite number");
          return false;
        }
      }
      const std::size_t f = 4 + 4 * static_cast<std::size_t>(j);
      int state = -1;
      if (!parseInt(fields[f], state) || state < 0 || state > 2) {
        err = lineMsg(ln, "field " + std::to_string(f + 1) + " (joint " + std::to_string(j) + " tracking state): " +
                              quoted(fields[f]) + " is not 0, 1 or 2");
        return false;
      }
      s.state = static_cast<TrackingState>(state);
    }
    out.frames.push_back(std::move(frame));
    first = false;
  }

  if (out.frames.empty()) {
    err = "no frames in the Kinect CSV";
    return false;
  }
  out.nominal_rate_hz = nominalRate(out.frames, 30.0f);
  return true;
}

}  // namespace drape::recording_detail
