#include "json_writer.h"

#include <cmath>
#include <cstdio>

namespace replay {

std::string JsonWriter::escape(const std::string& s) {
  std::string o;
  o.reserve(s.size() + 2);
  o += '"';
  for (unsigned char c : s) {
    switch (c) {
      case '"': o += "\\\""; break;
      case '\\': o += "\\\\"; break;
      case '\b': o += "\\b"; break;
      case '\f': o += "\\f"; break;
      case '\n': o += "\\n"; break;
      case '\r': o += "\\r"; break;
      case '\t': o += "\\t"; break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          o += buf;
        } else {
          o += static_cast<char>(c);  // UTF-8 bytes pass through unchanged
        }
    }
  }
  o += '"';
  return o;
}

void JsonWriter::newline() {
  out_ += '\n';
  out_.append(2 * counts_.size(), ' ');
}

void JsonWriter::beforeValue() {
  if (after_key_) {
    after_key_ = false;
    return;
  }
  if (!counts_.empty()) {  // array element
    if (counts_.back()++ > 0) out_ += ',';
    newline();
  }
}

JsonWriter& JsonWriter::key(const std::string& name) {
  if (counts_.back()++ > 0) out_ += ',';
  newline();
  out_ += escape(name);
  out_ += ": ";
  after_key_ = true;
  return *this;
}

JsonWriter& JsonWriter::beginObject() {
  beforeValue();
  out_ += '{';
  counts_.push_back(0);
  return *this;
}

JsonWriter& JsonWriter::endObject() {
  const bool empty = counts_.back() == 0;
  counts_.pop_back();
  if (!empty) newline();
  out_ += '}';
  if (counts_.empty()) out_ += '\n';
  return *this;
}

JsonWriter& JsonWriter::beginArray() {
  beforeValue();
  out_ += '[';
  counts_.push_back(0);
  return *this;
}

JsonWriter& JsonWriter::endArray() {
  const bool empty = counts_.back() == 0;
  counts_.pop_back();
  if (!empty) newline();
  out_ += ']';
  return *this;
}

JsonWriter& JsonWriter::value(const std::string& s) {
  beforeValue();
  out_ += escape(s);
  return *this;
}

JsonWriter& JsonWriter::value(const char* s) { return s ? value(std::string(s)) : null(); }

JsonWriter& JsonWriter::value(double v) {
  if (!std::isfinite(v)) return null();
  beforeValue();
  char buf[32];
  // 6 significant digits: plenty for timings and volumes, and always a valid JSON number
  // (%g never yields "inf"/"nan" for finite values and prints e.g. 1e-05 or 0.78).
  std::snprintf(buf, sizeof buf, "%.6g", v);
  out_ += buf;
  return *this;
}

JsonWriter& JsonWriter::value(int64_t v) {
  beforeValue();
  out_ += std::to_string(v);
  return *this;
}

JsonWriter& JsonWriter::value(bool v) {
  beforeValue();
  out_ += v ? "true" : "false";
  return *this;
}

JsonWriter& JsonWriter::null() {
  beforeValue();
  out_ += "null";
  return *this;
}

}  // namespace replay
