#pragma once
// Bounds-checked little-endian reading of MCAP fields from a record body; any overrun sets
// `failed()` instead of reading past the end.

#include <cstdint>
#include <map>
#include <span>
#include <string>

namespace cairn {

class ByteReader {
 public:
  explicit ByteReader(std::span<const uint8_t> b) : b_(b) {}

  uint8_t U8() { return static_cast<uint8_t>(Le(1)); }
  uint16_t U16() { return static_cast<uint16_t>(Le(2)); }
  uint32_t U32() { return static_cast<uint32_t>(Le(4)); }
  uint64_t U64() { return Le(8); }
  std::string String() {
    const uint32_t n = U32();
    const auto s = Take(n);
    return std::string(s.begin(), s.end());
  }
  std::span<const uint8_t> Take(uint64_t n) {
    if (failed_ || n > b_.size() - pos_) {
      failed_ = true;
      return {};
    }
    const auto s = b_.subspan(pos_, static_cast<size_t>(n));
    pos_ += static_cast<size_t>(n);
    return s;
  }
  std::map<std::string, std::string> StringMap() {
    std::map<std::string, std::string> m;
    ByteReader r(Take(U32()));
    while (!r.failed() && r.remaining() > 0) {
      std::string k = r.String();
      m[k] = r.String();
    }
    if (r.failed()) failed_ = true;
    return m;
  }
  template <class V>
  std::map<uint16_t, V> U16Map(V (ByteReader::*value)()) {
    std::map<uint16_t, V> m;
    ByteReader r(Take(U32()));
    while (!r.failed() && r.remaining() > 0) {
      const uint16_t k = r.U16();
      m[k] = (r.*value)();
    }
    if (r.failed()) failed_ = true;
    return m;
  }
  size_t remaining() const { return b_.size() - pos_; }
  size_t position() const { return pos_; }
  bool failed() const { return failed_; }

 private:
  uint64_t Le(int n) {
    const auto s = Take(static_cast<uint64_t>(n));
    uint64_t v = 0;
    for (size_t i = 0; i < s.size(); ++i) v |= static_cast<uint64_t>(s[i]) << (8 * i);
    return v;
  }
  std::span<const uint8_t> b_;
  size_t pos_ = 0;
  bool failed_ = false;
};

}  // namespace cairn
