#pragma once
// Little-endian serialization of MCAP's field types into a growing byte buffer.

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace cairn {

class ByteWriter {
 public:
  void U8(uint8_t v) { buf_.push_back(v); }
  void U16(uint16_t v) { Le(v, 2); }
  void U32(uint32_t v) { Le(v, 4); }
  void U64(uint64_t v) { Le(v, 8); }
  void Bytes(std::span<const uint8_t> b) { buf_.insert(buf_.end(), b.begin(), b.end()); }
  void String(std::string_view s) {
    U32(static_cast<uint32_t>(s.size()));
    buf_.insert(buf_.end(), s.begin(), s.end());
  }
  void StringMap(const std::map<std::string, std::string>& m);
  // Starts a record (opcode + length placeholder); EndRecord patches the length.
  size_t BeginRecord(uint8_t opcode) {
    U8(opcode);
    const size_t at = buf_.size();
    U64(0);
    return at;
  }
  void EndRecord(size_t length_at);
  // Patches a uint32 byte length written by a placeholder U32(0) at `at`.
  void PatchU32Length(size_t at);

  std::vector<uint8_t>& buffer() { return buf_; }
  const std::vector<uint8_t>& buffer() const { return buf_; }
  size_t size() const { return buf_.size(); }
  void Clear() { buf_.clear(); }

 private:
  void Le(uint64_t v, int n) {
    for (int i = 0; i < n; ++i) buf_.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  std::vector<uint8_t> buf_;
};

}  // namespace cairn
