#pragma once
// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320, as zlib and MCAP use it), incremental.

#include <cstddef>
#include <cstdint>
#include <span>

namespace cairn {

class Crc32 {
 public:
  void Update(std::span<const uint8_t> bytes);
  void Update(const void* data, size_t size) {
    Update(std::span<const uint8_t>(static_cast<const uint8_t*>(data), size));
  }
  uint32_t value() const { return ~state_; }
  void Reset() { state_ = 0xFFFFFFFFu; }

  static uint32_t Of(std::span<const uint8_t> bytes) {
    Crc32 c;
    c.Update(bytes);
    return c.value();
  }

 private:
  uint32_t state_ = 0xFFFFFFFFu;
};

}  // namespace cairn
