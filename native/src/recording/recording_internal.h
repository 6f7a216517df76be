// Helpers shared by the recording readers (not part of the public interface).
//
// Everything here is locale independent (std::from_chars / std::to_chars) and bounded: no
// recursion, no allocation proportional to a number read from the input.
#pragma once

#include "recording/recording.h"

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace drape::recording_detail {

// Splits text into lines ending in "\n", "\r\n" or a lone "\r" (the CMU BVH files mix the first
// two). `number` is the 1-based line number of the line last returned.
class LineReader {
 public:
  explicit LineReader(std::string_view text, int firstLineNumber = 1)
      : text_(text), number_(firstLineNumber - 1) {}
  bool next(std::string_view& line);
  int number() const { return number_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  int number_ = 0;
};

inline bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }
std::string_view trim(std::string_view s);
// `s` without a leading UTF-8 byte order mark.
std::string_view stripBom(std::string_view s);

// Next whitespace-separated token of `s` starting at `pos` (updated); empty at the end.
std::string_view nextToken(std::string_view s, std::size_t& pos);

// Whole-token numbers. Doubles/floats must be finite ("nan", "inf", 1e999 are rejected); a
// leading '+' is accepted. Floats must also fit a float.
bool parseDouble(std::string_view tok, double& v);
bool parseFloat(std::string_view tok, float& v);
bool parseInt64(std::string_view tok, int64_t& v);
bool parseInt(std::string_view tok, int& v);

// Token quoted for an error message: at most 24 characters, non-printable bytes as \xNN.
std::string quoted(std::string_view tok);

bool equalsIgnoreCase(std::string_view a, std::string_view b);

// 1 / median frame interval, or `fallback` with fewer than two frames.
float nominalRate(const std::vector<RecordingFrame>& frames, float fallback);

// "kinect1", "kinect2", "azure" (or "unknown").
const char* layoutKeyword(Layout layout);

// Checks `hint` (0 or a valid layout) against the layout the content carries.
bool checkLayoutHint(int hint, Layout actual, std::string_view source, std::string& err);

// The per-format readers: `text` is non-empty, the hint is 0 or a valid layout. They fill `out`
// completely (format included) or return false with `err` set; they may throw std::bad_alloc.
bool parseKinectCsv(std::string_view text, int layoutHint, Recording& out, std::string& err);
bool parseBvh(std::string_view text, int layoutHint, Recording& out, std::string& err, BvhImportInfo* info);
bool parseDrape(std::string_view text, int layoutHint, Recording& out, std::string& err);

// Formatting for messages: "line 12: ..." and the like.
std::string lineMsg(int line, std::string_view what);

}  // namespace drape::recording_detail
