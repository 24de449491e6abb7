#pragma once
// The record layout of a Linux IIO buffer (Documentation/ABI/testing/sysfs-bus-iio): each enabled
// channel of scan_elements/ has an index (its order in the record) and a type such as
// "le:s16/16>>0" (endianness, signedness, significant bits / storage bits, shift). A channel sits
// at the next multiple of its own storage size; the record is padded to a multiple of the largest.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "common/status.h"

namespace cairn {

struct IioChannelType {
  bool big_endian = false;
  bool is_signed = true;
  int bits = 16;          // significant
  int storage_bits = 16;  // 8, 16, 32 or 64
  int shift = 0;

  // "le:s16/16>>0", "be:u12/16>>4", "le:s64/64>>0" (a repeat count "X2" is refused).
  static Expected<IioChannelType> Parse(const std::string& text);
};

struct IioChannel {
  std::string name;  // e.g. "in_accel_x"
  int index = 0;
  IioChannelType type;
  size_t offset = 0;  // bytes into the record, set by IioScanLayout
};

class IioScanLayout {
 public:
  // Orders `channels` by index and places them; fails on duplicate indices.
  static Expected<IioScanLayout> Create(std::vector<IioChannel> channels);

  size_t record_size() const { return record_size_; }
  const std::vector<IioChannel>& channels() const { return channels_; }
  // The position of `name` in channels(), or -1.
  int Find(const std::string& name) const;

  // Channel `i`'s value in `record` (record_size() bytes): shifted, masked, sign-extended.
  int64_t Value(std::span<const uint8_t> record, int i) const;

 private:
  std::vector<IioChannel> channels_;
  size_t record_size_ = 0;
};

}  // namespace cairn
