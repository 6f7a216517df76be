// Format detection, dispatch, file IO and the helpers the three readers share.
#include "recording/recording.h"

#include "recording/recording_internal.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <new>

namespace drape {
namespace recording_detail {

bool LineReader::next(std::string_view& line) {
  if (pos_ >= text_.size()) return false;
  const std::size_t start = pos_;
  std::size_t end = start;
  while (end < text_.size() && text_[end] != '\n' && text_[end] != '\r') ++end;
  line = text_.substr(start, end - start);
  pos_ = end;
  if (pos_ < text_.size()) {
    if (text_[pos_] == '\r' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '\n') ++pos_;
    ++pos_;
  }
  ++number_;
  return true;
}

std::string_view trim(std::string_view s) {
  std::size_t b = 0, e = s.size();
  while (b < e && isSpace(s[b])) ++b;
  while (e > b && isSpace(s[e - 1])) --e;
  return s.substr(b, e - b);
}

std::string_view stripBom(std::string_view s) {
  if (s.size() >= 3 && static_cast<unsigned char>(s[0]) == 0xEF && static_cast<unsigned char>(s[1]) == 0xBB &&
      static_cast<unsigned char>(s[2]) == 0xBF)
    s.remove_prefix(3);
  return s;
}

std::string_view nextToken(std::string_view s, std::size_t& pos) {
  while (pos < s.size() && isSpace(s[pos])) ++pos;
  const std::size_t start = pos;
  while (pos < s.size() && !isSpace(s[pos])) ++pos;
  return s.substr(start, pos - start);
}

namespace {
std::string_view stripPlus(std::string_view tok) {
  // from_chars rejects a leading '+'; accept it, but not "+-1" or "++1".
  if (tok.size() > 1 && tok[0] == '+' && tok[1] != '-' && tok[1] != '+') return tok.substr(1);
  return tok;
}
}  // namespace

bool parseDouble(std::string_view tok, double& v) {
  tok = stripPlus(tok);
  if (tok.empty()) return false;
  double x = 0;
  const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), x);
  if (r.ec != std::errc() || r.ptr != tok.data() + tok.size() || !std::isfinite(x)) return false;
  v = x;
  return true;
}

bool parseFloat(std::string_view tok, float& v) {
  // Parsed as float directly (no double rounding), so the shortest text a float was written as
  // reads back as exactly that float.
  tok = stripPlus(tok);
  if (tok.empty()) return false;
  float x = 0;
  const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), x);
  if (r.ptr != tok.data() + tok.size()) return false;
  if (r.ec == std::errc::result_out_of_range) {
    // Underflow (e.g. 1e-50) reads as the nearest float; overflow is an error.
    double d = 0;
    if (!parseDouble(tok, d) || std::fabs(d) >= 1) return false;
    x = static_cast<float>(d);
  } else if (r.ec != std::errc() || !std::isfinite(x)) {
    return false;
  }
  v = x;
  return true;
}

bool parseInt64(std::string_view tok, int64_t& v) {
  tok = stripPlus(tok);
  if (tok.empty()) return false;
  int64_t x = 0;
  const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), x);
  if (r.ec != std::errc() || r.ptr != tok.data() + tok.size()) return false;
  v = x;
  return true;
}

bool parseInt(std::string_view tok, int& v) {
  int64_t x = 0;
  if (!parseInt64(tok, x) || x < std::numeric_limits<int>::min() || x > std::numeric_limits<int>::max()) return false;
  v = static_cast<int>(x);
  return true;
}

std::string quoted(std::string_view tok) {
  static const char* const kHex = "0123456789abcdef";
  std::string s = "'";
  const std::size_t n = std::min<std::size_t>(tok.size(), 24);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(tok[i]);
    if (c >= 0x20 && c < 0x7f) {
      s += static_cast<char>(c);
    } else {
      s += "\\x";
      s += kHex[c >> 4];
      s += kHex[c & 15];
    }
  }
  if (tok.size() > n) s += "...";
  s += "'";
  return s;
}

bool equalsIgnoreCase(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    char x = a[i], y = b[i];
    if (x >= 'A' && x <= 'Z') x = static_cast<char>(x - 'A' + 'a');
    if (y >= 'A' && y <= 'Z') y = static_cast<char>(y - 'A' + 'a');
    if (x != y) return false;
  }
  return true;
}

float nominalRate(const std::vector<RecordingFrame>& frames, float fallback) {
  if (frames.size() < 2) return fallback;
  std::vector<double> dt(frames.size() - 1);
  for (std::size_t i = 1; i < frames.size(); ++i) dt[i - 1] = frames[i].time_s - frames[i - 1].time_s;
  const std::size_t mid = dt.size() / 2;
  std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(mid), dt.end());
  double median = dt[mid];
  if (dt.size() % 2 == 0) {
    const double lower = *std::max_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(mid));
    median = 0.5 * (median + lower);
  }
  if (!(median > 0) || !std::isfinite(1.0 / median)) return fallback;
  const double rate = 1.0 / median;
  return rate > static_cast<double>(std::numeric_limits<float>::max()) ? fallback : static_cast<float>(rate);
}

const char* layoutKeyword(Layout layout) {
  switch (layout) {
    case Layout::Kinect1: return "kinect1";
    case Layout::Kinect2: return "kinect2";
    case Layout::Azure: return "azure";
  }
  return "unknown";
}

bool checkLayoutHint(int hint, Layout actual, std::string_view source, std::string& err) {
  if (hint == 0 || hint == static_cast<int>(actual)) return true;
  const auto expected = static_cast<Layout>(hint);
  err = "layout hint " + std::string(layoutKeyword(expected)) + " (" +
        std::to_string(layoutJointCount(expected)) + " joints) contradicts the data: " + std::string(source) +
        " is " + layoutKeyword(actual) + " (" + std::to_string(layoutJointCount(actual)) + " joints)";
  return false;
}

std::string lineMsg(int line, std::string_view what) { return "line " + std::to_string(line) + ": " + std::string(what); }

}  // namespace recording_detail

namespace rd = recording_detail;

namespace {

// Assigns without letting an allocation failure escape.
void setError(std::string& err, const char* msg) noexcept {
  try {
    err = msg;
  } catch (...) {
  }
}

std::string_view skipBomAndSpace(std::string_view text) {
  text = rd::stripBom(text);
  std::size_t i = 0;
  while (i < text.size() && rd::isSpace(text[i])) ++i;
  return text.substr(i);
}

bool startsWithWord(std::string_view s, std::string_view word) {
  return s.size() >= word.size() && s.substr(0, word.size()) == word &&
         (s.size() == word.size() || rd::isSpace(s[word.size()]));
}

// Runs `body` (which sets `kind` itself when it fails) with every exception turned into false +
// message; sets *errorKind (if given).
template <typename F>
bool guarded(std::string& err, RecordingError* errorKind, F&& body) noexcept {
  RecordingError kind = RecordingError::None;
  bool ok = false;
  try {
    ok = body(kind);
    if (!ok && kind == RecordingError::None) kind = RecordingError::Parse;
  } catch (const std::bad_alloc&) {
    kind = RecordingError::OutOfMemory;
    setError(err, "out of memory while reading the recording");
  } catch (const std::exception& e) {
    kind = RecordingError::Internal;
    try {
      err = std::string("internal error while reading the recording: ") + e.what();
    } catch (...) {
      setError(err, "internal error while reading the recording");
    }
  } catch (...) {
    kind = RecordingError::Internal;
    setError(err, "internal error while reading the recording");
  }
  if (ok) kind = RecordingError::None;
  if (errorKind) *errorKind = kind;
  return ok;
}

bool checkHintValue(int layoutHint, std::string& err, RecordingError& kind) {
  if (layoutHint == 0 || isValidLayout(layoutHint)) return true;
  err = "invalid layout hint " + std::to_string(layoutHint) + " (expected 0 = auto, 1 = kinect1, 2 = kinect2, 3 = azure)";
  kind = RecordingError::InvalidArgument;
  return false;
}

}  // namespace

const char* recordingFormatName(RecordingFormat format) {
  switch (format) {
    case RecordingFormat::KinectCsv: return "kinect-csv";
    case RecordingFormat::Bvh: return "bvh";
    case RecordingFormat::Drape: return "drape";
    case RecordingFormat::Unknown: break;
  }
  return "unknown";
}

const char* recordingErrorName(RecordingError e) {
  switch (e) {
    case RecordingError::None: return "none";
    case RecordingError::Io: return "io";
    case RecordingError::Parse: return "parse";
    case RecordingError::OutOfMemory: return "out-of-memory";
    case RecordingError::InvalidArgument: return "invalid-argument";
    case RecordingError::Internal: return "internal";
  }
  return "unknown";
}

RecordingFormat detectRecordingFormat(std::string_view text) {
  const std::string_view s = skipBomAndSpace(text);
  if (s.empty()) return RecordingFormat::Unknown;
  if (startsWithWord(s, "drape-recording")) return RecordingFormat::Drape;
  if (startsWithWord(s, "HIERARCHY")) return RecordingFormat::Bvh;
  const char c = s[0];
  if ((c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.') return RecordingFormat::KinectCsv;
  return RecordingFormat::Unknown;
}

bool parseRecording(std::string_view text, int layoutHint, Recording& out, std::string& err,
                    RecordingError* errorKind) {
  return guarded(err, errorKind, [&](RecordingError& kind) -> bool {
    err.clear();
    if (!checkHintValue(layoutHint, err, kind)) return false;
    const std::string_view body = skipBomAndSpace(text);
    if (body.empty()) {
      err = text.empty() ? "empty input: no recording data" : "input holds only whitespace: no recording data";
      return false;
    }
    Recording rec;
    bool ok = false;
    switch (detectRecordingFormat(text)) {
      case RecordingFormat::Drape: ok = rd::parseDrape(text, layoutHint, rec, err); break;
      case RecordingFormat::Bvh: ok = rd::parseBvh(text, layoutHint, rec, err, nullptr); break;
      case RecordingFormat::KinectCsv: ok = rd::parseKinectCsv(text, layoutHint, rec, err); break;
      case RecordingFormat::Unknown:
        err = "unrecognised recording format (expected a Kinect CSV, a BVH file or a drape recording); it starts with " +
              rd::quoted(body);
        return false;
    }
    if (ok) out = std::move(rec);
    return ok;
  });
}

bool parseBvhRecording(std::string_view text, int layoutHint, Recording& out, std::string& err, BvhImportInfo* info) {
  return guarded(err, nullptr, [&](RecordingError& kind) -> bool {
    err.clear();
    if (!checkHintValue(layoutHint, err, kind)) return false;
    if (detectRecordingFormat(text) != RecordingFormat::Bvh) {
      err = skipBomAndSpace(text).empty() ? "empty input: no BVH data" : "not a BVH file: it does not start with HIERARCHY";
      return false;
    }
    Recording rec;
    BvhImportInfo tmp;
    if (!rd::parseBvh(text, layoutHint, rec, err, &tmp)) return false;
    out = std::move(rec);
    if (info) *info = tmp;
    return true;
  });
}

bool readRecordingFile(const std::string& path, int layoutHint, Recording& out, std::string& err,
                       RecordingError* errorKind) {
  return guarded(err, errorKind, [&](RecordingError& kind) -> bool {
    err.clear();
    kind = RecordingError::Io;  // until the text is in memory
    std::error_code ec;
    const std::filesystem::path p(path);
    const std::filesystem::file_status st = std::filesystem::status(p, ec);
    if (!std::filesystem::exists(st)) {
      err = "'" + path + "': " + (ec && ec != std::errc::no_such_file_or_directory ? "cannot access: " + ec.message()
                                                                                 : std::string("no such file"));
      return false;
    }
    if (!std::filesystem::is_regular_file(st)) {
      err = "'" + path + "': not a regular file";
      return false;
    }
    std::ifstream in(p, std::ios::binary);
    if (!in) {
      err = "'" + path + "': cannot open: " + std::strerror(errno);
      return false;
    }
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0) {
      err = "'" + path + "': cannot determine the file size";
      return false;
    }
    if (static_cast<unsigned long long>(size) > kRecordingMaxFileBytes) {
      err = "'" + path + "': file too large (" + std::to_string(size) + " bytes; the limit is " +
            std::to_string(kRecordingMaxFileBytes) + ")";
      return false;
    }
    in.seekg(0, std::ios::beg);
    std::string text(static_cast<std::size_t>(size), '\0');
    if (size > 0 && !in.read(text.data(), size)) {
      err = "'" + path + "': read error";
      return false;
    }
    std::string perr;
    if (!parseRecording(text, layoutHint, out, perr, &kind)) {
      err = "'" + path + "': " + perr;
      return false;
    }
    return true;
  });
}

}  // namespace drape
