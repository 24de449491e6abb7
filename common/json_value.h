#pragma once
// A minimal JSON reader: client requests of the live stream, and tests that check what the tools
// and the daemon write. Numbers are doubles. Parse and type errors throw std::runtime_error; callers
// outside tests catch it at their boundary (never on a real-time path).

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace cairn {

class JsonValue {
 public:
  enum class Type { kNull, kBool, kNumber, kString, kArray, kObject };

  static JsonValue Parse(const std::string& text);
  static JsonValue ParseFile(const std::string& path);

  Type type() const { return type_; }
  bool is_null() const { return type_ == Type::kNull; }
  double number() const;
  bool boolean() const;
  const std::string& string() const;
  const std::vector<JsonValue>& array() const;
  bool has(const std::string& key) const;
  // Object member; throws when missing.
  const JsonValue& operator[](const std::string& key) const;
  const JsonValue& operator[](size_t index) const { return array().at(index); }
  const std::map<std::string, JsonValue>& object() const;

 private:
  friend class JsonParser;
  Type type_ = Type::kNull;
  bool bool_ = false;
  double number_ = 0.0;
  std::string string_;
  std::vector<JsonValue> array_;
  std::map<std::string, JsonValue> object_;
};

}  // namespace cairn
