#include "io/byte_writer.h"

namespace cairn {

void ByteWriter::StringMap(const std::map<std::string, std::string>& m) {
  const size_t at = buf_.size();
  U32(0);
  for (const auto& [k, v] : m) {
    String(k);
    String(v);
  }
  PatchU32Length(at);
}

void ByteWriter::EndRecord(size_t length_at) {
  const uint64_t len = buf_.size() - length_at - 8;
  for (int i = 0; i < 8; ++i) buf_[length_at + static_cast<size_t>(i)] = static_cast<uint8_t>(len >> (8 * i));
}

void ByteWriter::PatchU32Length(size_t at) {
  const uint32_t len = static_cast<uint32_t>(buf_.size() - at - 4);
  for (int i = 0; i < 4; ++i) buf_[at + static_cast<size_t>(i)] = static_cast<uint8_t>(len >> (8 * i));
}

}  // namespace cairn
