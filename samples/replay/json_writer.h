// A tiny streaming JSON writer: objects, arrays, strings (escaped per RFC 8259), integers and
// doubles (non-finite doubles are written as null; JSON has no NaN). Pretty-printed, 2 spaces.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace replay {

class JsonWriter {
 public:
  JsonWriter& beginObject();
  JsonWriter& endObject();
  JsonWriter& beginArray();
  JsonWriter& endArray();
  JsonWriter& key(const std::string& name);  // inside an object, before each value
  JsonWriter& value(const std::string& s);
  JsonWriter& value(const char* s);
  JsonWriter& value(double v);
  JsonWriter& value(int64_t v);
  JsonWriter& value(uint32_t v) { return value(static_cast<int64_t>(v)); }
  JsonWriter& value(int v) { return value(static_cast<int64_t>(v)); }
  JsonWriter& value(bool v);
  JsonWriter& null();

  const std::string& str() const { return out_; }

  static std::string escape(const std::string& s);  // quoted and escaped

 private:
  void beforeValue();
  void newline();

  std::string out_;
  // One entry per open container: number of members written so far.
  std::vector<int> counts_;
  bool after_key_ = false;
};

}  // namespace replay
