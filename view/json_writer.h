#pragma once
/// @file json_writer.h
/// @brief A small streaming JSON writer for the view's snapshots: objects, arrays, strings
/// (escaped per RFC 8259), numbers (a non-finite number is written as null, never as the invalid
/// tokens nan / inf) and booleans. Commas are placed by the writer; the caller only nests.
///
///   JsonWriter w;
///   w.beginObject().key("t").number(1.5).key("ids").beginArray().number(3).endArray().endObject();
///   w.str() == R"({"t":1.5,"ids":[3]})"

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace meshnav::view {

class JsonWriter {
 public:
  JsonWriter& beginObject();
  JsonWriter& endObject();
  JsonWriter& beginArray();
  JsonWriter& endArray();
  /// An object member's name; the value follows.
  JsonWriter& key(std::string_view name);
  JsonWriter& string(std::string_view value);
  /// `digits` significant digits (%.*g); NaN and ±inf are written as null.
  JsonWriter& number(double value, int digits = 7);
  JsonWriter& integer(int64_t value);
  JsonWriter& boolean(bool value);
  JsonWriter& null();
  /// key(name) followed by the value.
  template <class T>
  JsonWriter& field(std::string_view name, const T& value) {
    key(name);
    return value_(value);
  }

  const std::string& str() const { return out_; }

  /// `s` as a JSON string literal with its quotes.
  static std::string quoted(std::string_view s);

 private:
  JsonWriter& value_(double v) { return number(v); }
  JsonWriter& value_(int v) { return integer(v); }
  JsonWriter& value_(int64_t v) { return integer(v); }
  JsonWriter& value_(bool v) { return boolean(v); }
  JsonWriter& value_(const std::string& v) { return string(v); }
  JsonWriter& value_(const char* v) { return string(v); }
  /// The comma before a value or member, unless it is the first of its container or follows a key.
  void separate();

  std::string out_;
  std::vector<bool> first_;  ///< per open container: no member written yet
  bool after_key_ = false;
};

}  // namespace meshnav::view
