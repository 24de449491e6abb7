#pragma once
// A small streaming JSON writer for summaries and command-line reports: correct escaping, no
// trailing commas, and non-finite numbers written as null (JSON has no NaN).

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace cairn {

class JsonWriter {
 public:
  explicit JsonWriter(bool pretty = true) : pretty_(pretty) {}

  JsonWriter& BeginObject();
  JsonWriter& EndObject();
  JsonWriter& BeginArray();
  JsonWriter& EndArray();
  JsonWriter& Key(std::string_view key);

  JsonWriter& String(std::string_view value);
  JsonWriter& Number(double value);
  JsonWriter& Int(int64_t value);
  JsonWriter& Uint(uint64_t value);
  JsonWriter& Bool(bool value);
  JsonWriter& Null();

  // Key + value in one call.
  template <class T>
  JsonWriter& Field(std::string_view key, const T& value) {
    Key(key);
    return Value(value);
  }

  const std::string& str() const { return out_; }

  static std::string Escape(std::string_view s);

 private:
  JsonWriter& Value(double v) { return Number(v); }
  JsonWriter& Value(float v) { return Number(v); }
  JsonWriter& Value(bool v) { return Bool(v); }
  JsonWriter& Value(int v) { return Int(v); }
  JsonWriter& Value(long v) { return Int(v); }
  JsonWriter& Value(long long v) { return Int(v); }
  JsonWriter& Value(unsigned v) { return Uint(v); }
  JsonWriter& Value(unsigned long v) { return Uint(v); }
  JsonWriter& Value(unsigned long long v) { return Uint(v); }
  JsonWriter& Value(const std::string& v) { return String(v); }
  JsonWriter& Value(std::string_view v) { return String(v); }
  JsonWriter& Value(const char* v) { return String(v); }

  void BeforeValue();
  void Newline();

  bool pretty_;
  std::string out_;
  std::vector<bool> has_items_;  // per open container
  bool after_key_ = false;
};

}  // namespace cairn
