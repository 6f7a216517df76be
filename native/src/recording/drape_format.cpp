// Our own text format ".drec" (grammar in docs/recording-format.md):
//   drape-recording 1
//   layout kinect2            (kinect1 | kinect2 | azure)
//   joints 25                 (must match the layout)
//   rate 30                   (optional; default: 1 / median frame interval)
//   f <time_s> x y z s x y z s ...
// '#' starts a comment line; blank lines are ignored; CRLF or LF.
#include "recording/recording_internal.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <new>
#include <string>

namespace drape {
namespace recording_detail {

namespace {

bool layoutFromKeyword(std::string_view word, Layout& layout) {
  for (const Layout l : {Layout::Kinect1, Layout::Kinect2, Layout::Azure}) {
    if (word == layoutKeyword(l)) {
      layout = l;
      return true;
    }
  }
  return false;
}

// Expects exactly one value token after the keyword.
bool singleValue(std::string_view row, std::size_t pos, int ln, std::string_view key, std::string_view& value,
                 std::string& err) {
  value = nextToken(row, pos);
  if (value.empty() || !nextToken(row, pos).empty()) {
    err = lineMsg(ln, "'" + std::string(key) + "' takes exactly one value");
    return false;
  }
  return true;
}

}  // namespace

bool parseDrape(std::string_view text, int layoutHint, Recording& out, std::string& err) {
  out = Recording{};
  out.format = RecordingFormat::Drape;

  LineReader lines(text);
  std::string_view line;
  bool sawMagic = false, sawLayout = false, sawRate = false;
  int declaredJoints = -1;
  float rate = 0;

  while (lines.next(line)) {
    const int ln = lines.number();
    if (ln == 1) line = stripBom(line);
    const std::string_view row = trim(line);
    if (row.empty() || row[0] == '#') continue;
    std::size_t pos = 0;
    const std::string_view key = nextToken(row, pos);

    if (!sawMagic) {
      std::string_view version;
      if (key != "drape-recording") {
        err = lineMsg(ln, "expected 'drape-recording 1' first");
        return false;
      }
      if (!singleValue(row, pos, ln, key, version, err)) return false;
      if (version != "1") {
        err = lineMsg(ln, "unsupported drape-recording version " + quoted(version) + " (this reader knows version 1)");
        return false;
      }
      sawMagic = true;
      continue;
    }

    if (key == "f") {
      if (!sawLayout || declaredJoints < 0) {
        err = lineMsg(ln, "frame line before the 'layout' and 'joints' header lines");
        return false;
      }
      if (out.frames.size() >= static_cast<std::size_t>(kRecordingMaxFrames)) {
        err = lineMsg(ln, "more than " + std::to_string(kRecordingMaxFrames) + " frames");
        return false;
      }
      RecordingFrame frame;
      const std::string_view t = nextToken(row, pos);
      if (!parseDouble(t, frame.time_s)) {
        err = lineMsg(ln, "frame time " + quoted(t) + " is not a finite number");
        return false;
      }
      if (!out.frames.empty() && !(frame.time_s > out.frames.back().time_s)) {
        err = lineMsg(ln, "frame time " + std::string(t) + " is not after the previous frame's; times must increase");
        return false;
      }
      frame.joints.resize(static_cast<std::size_t>(declaredJoints));
      for (int j = 0; j < declaredJoints; ++j) {
        JointSample& s = frame.joints[static_cast<std::size_t>(j)];
        for (int a = 0; a < 4; ++a) {
          const std::string_view tok = nextToken(row, pos);
          if (tok.empty()) {
            err = lineMsg(ln, "frame has " + std::to_string(4 * j + a) + " joint values, expected " +
                                  std::to_string(4 * declaredJoints) + " (" + std::to_string(declaredJoints) +
                                  " joints x 4)");
            return false;
          }
          if (a < 3) {
            if (!parseFloat(tok, s.position[a])) {
              err = lineMsg(ln, "joint " + std::to_string(j) + ": " + quoted(tok) + " is not a finite number");
              return false;
            }
          } else {
            int state = -1;
            if (!parseInt(tok, state) || state < 0 || state > 2) {
              err = lineMsg(ln, "joint " + std::to_string(j) + ": tracking state " + quoted(tok) + " is not 0, 1 or 2");
              return false;
            }
            s.state = static_cast<TrackingState>(state);
          }
        }
      }
      if (!nextToken(row, pos).empty()) {
        err = lineMsg(ln, "more than " + std::to_string(4 * declaredJoints) + " joint values (" +
                              std::to_string(declaredJoints) + " joints x 4)");
        return false;
      }
      out.frames.push_back(std::move(frame));
      continue;
    }

    if (!out.frames.empty()) {
      err = lineMsg(ln, "header line " + quoted(key) + " after the first frame");
      return false;
    }
    std::string_view value;
    if (key == "layout") {
      if (sawLayout) {
        err = lineMsg(ln, "duplicate 'layout' line");
        return false;
      }
      if (!singleValue(row, pos, ln, key, value, err)) return false;
      if (!layoutFromKeyword(value, out.layout)) {
        err = lineMsg(ln, "unknown layout " + quoted(value) + " (expected kinect1, kinect2 or azure)");
        return false;
      }
      if (!checkLayoutHint(layoutHint, out.layout, "line " + std::to_string(ln) + " of the drape recording", err))
        return false;
      sawLayout = true;
    } else if (key == "joints") {
      if (!sawLayout) {
        err = lineMsg(ln, "'joints' before 'layout'");
        return false;
      }
      if (declaredJoints >= 0) {
        err = lineMsg(ln, "duplicate 'joints' line");
        return false;
      }
      if (!singleValue(row, pos, ln, key, value, err)) return false;
      if (!parseInt(value, declaredJoints) || declaredJoints != layoutJointCount(out.layout)) {
        err = lineMsg(ln, "joints " + quoted(value) + " does not match layout " + layoutKeyword(out.layout) + " (" +
                              std::to_string(layoutJointCount(out.layout)) + " joints)");
        return false;
      }
    } else if (key == "rate") {
      if (sawRate) {
        err = lineMsg(ln, "duplicate 'rate' line");
        return false;
      }
      if (!singleValue(row, pos, ln, key, value, err)) return false;
      if (!parseFloat(value, rate) || !(rate > 0) || rate > 1e5f) {
        err = lineMsg(ln, "rate " + quoted(value) + " is not a frame rate in Hz (0 < rate <= 100000)");
        return false;
      }
      sawRate = true;
    } else {
      err = lineMsg(ln, "unknown line type " + quoted(key) + " (expected layout, joints, rate, f or a # comment)");
      return false;
    }
  }

  if (!sawMagic) {
    err = "no 'drape-recording 1' line";
    return false;
  }
  if (!sawLayout || declaredJoints < 0) {
    err = "drape recording header lacks the 'layout' or 'joints' line";
    return false;
  }
  if (out.frames.empty()) {
    err = "no frames in the drape recording";
    return false;
  }
  out.nominal_rate_hz = sawRate ? rate : nominalRate(out.frames, 30.0f);
  return true;
}

}  // namespace recording_detail

namespace rd = recording_detail;

namespace {

template <typename T>
void appendNumber(std::string& s, T v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);  // shortest form that round-trips
  s.append(buf, r.ptr);
}

bool validateForWriting(const Recording& rec, std::string& err) {
  if (!isValidLayout(static_cast<int>(rec.layout))) {
    err = "invalid layout " + std::to_string(static_cast<int>(rec.layout));
    return false;
  }
  if (!std::isfinite(rec.nominal_rate_hz) || !(rec.nominal_rate_hz > 0) || rec.nominal_rate_hz > 1e5f) {
    err = "nominal_rate_hz is not a frame rate in Hz";
    return false;
  }
  const auto n = static_cast<std::size_t>(layoutJointCount(rec.layout));
  for (std::size_t i = 0; i < rec.frames.size(); ++i) {
    const RecordingFrame& f = rec.frames[i];
    const std::string where = "frame " + std::to_string(i);
    if (f.joints.size() != n) {
      err = where + " has " + std::to_string(f.joints.size()) + " joints, layout " + rd::layoutKeyword(rec.layout) +
            " has " + std::to_string(n);
      return false;
    }
    if (!std::isfinite(f.time_s) || (i > 0 && !(f.time_s > rec.frames[i - 1].time_s))) {
      err = where + ": time is not finite or not after the previous frame's";
      return false;
    }
    for (const JointSample& s : f.joints) {
      if (!isFinite(s.position) || static_cast<int>(s.state) > 2) {
        err = where + ": a joint has a non-finite position or a tracking state outside 0..2";
        return false;
      }
    }
  }
  return true;
}

}  // namespace

std::string writeDrapeRecording(const Recording& rec) {
  try {
    std::string s;
    const int n = layoutJointCount(rec.layout);
    s.reserve(64 + rec.frames.size() * (16 + static_cast<std::size_t>(n) * 40));
    s += "drape-recording 1\n# ";
    s += std::to_string(rec.frames.size());
    s += " frames, source format ";
    s += recordingFormatName(rec.format);
    s += "\nlayout ";
    s += rd::layoutKeyword(rec.layout);
    s += "\njoints ";
    s += std::to_string(n);
    s += "\nrate ";
    appendNumber(s, rec.nominal_rate_hz);
    s += '\n';
    for (const RecordingFrame& f : rec.frames) {
      s += "f ";
      appendNumber(s, f.time_s);
      for (const JointSample& j : f.joints) {
        for (int a = 0; a < 3; ++a) {
          s += ' ';
          appendNumber(s, j.position[a]);
        }
        s += ' ';
        appendNumber(s, static_cast<int>(j.state));
      }
      s += '\n';
    }
    return s;
  } catch (...) {
    return std::string();
  }
}

bool writeDrapeRecordingFile(const Recording& rec, const std::string& path, std::string& err,
                             RecordingError* errorKind) {
  RecordingError kind = RecordingError::None;
  const bool ok = [&]() noexcept -> bool {
    try {
      err.clear();
      std::string why;
      if (!validateForWriting(rec, why)) {
        err = "'" + path + "': not written: " + why;
        kind = RecordingError::InvalidArgument;
        return false;
      }
      const std::string text = writeDrapeRecording(rec);
      if (text.empty()) {
        err = "'" + path + "': out of memory";
        kind = RecordingError::OutOfMemory;
        return false;
      }
      kind = RecordingError::Io;
      std::ofstream outFile(path, std::ios::binary | std::ios::trunc);
      if (!outFile) {
        err = "'" + path + "': cannot open for writing";
        return false;
      }
      outFile.write(text.data(), static_cast<std::streamsize>(text.size()));
      outFile.close();
      if (!outFile) {
        err = "'" + path + "': write error";
        return false;
      }
      kind = RecordingError::None;
      return true;
    } catch (const std::bad_alloc&) {
      kind = RecordingError::OutOfMemory;
    } catch (...) {
      kind = RecordingError::Internal;
    }
    try {
      err = "'" + path + "': " + (kind == RecordingError::OutOfMemory ? "out of memory" : "internal error") +
            " while writing";
    } catch (...) {
    }
    return false;
  }();
  if (errorKind) *errorKind = kind;
  return ok;
}

}  // namespace drape
