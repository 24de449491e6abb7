#include "drivers/iio_scan_layout.h"

#include <algorithm>
#include <cstdio>

namespace cairn {

Expected<IioChannelType> IioChannelType::Parse(const std::string& text) {
  char endian[3] = {0}, sign = 0;
  int bits = 0, storage = 0, shift = 0, consumed = 0;
  if (std::sscanf(text.c_str(), "%2[bl]e:%c%d/%d>>%d%n", endian, &sign, &bits, &storage, &shift, &consumed) != 5 ||
      (endian[0] != 'b' && endian[0] != 'l') || (sign != 's' && sign != 'u'))
    return DataLossError("IIO channel type '" + text + "' is not of the form le:s16/16>>0");
  for (size_t i = static_cast<size_t>(consumed); i < text.size(); ++i) {
    if (text[i] != '\n' && text[i] != ' ')
      return DataLossError("IIO channel type '" + text + "': repeated or unknown suffix");
  }
  if (storage != 8 && storage != 16 && storage != 32 && storage != 64)
    return DataLossError("IIO channel type '" + text + "': storage of " + std::to_string(storage) + " bits");
  if (bits < 1 || bits > storage || shift < 0 || shift + bits > storage)
    return DataLossError("IIO channel type '" + text + "': bits and shift do not fit the storage");
  IioChannelType t;
  t.big_endian = endian[0] == 'b';
  t.is_signed = sign == 's';
  t.bits = bits;
  t.storage_bits = storage;
  t.shift = shift;
  return t;
}

Expected<IioScanLayout> IioScanLayout::Create(std::vector<IioChannel> channels) {
  std::sort(channels.begin(), channels.end(), [](const IioChannel& a, const IioChannel& b) { return a.index < b.index; });
  IioScanLayout layout;
  size_t offset = 0, largest = 1;
  for (size_t i = 0; i < channels.size(); ++i) {
    if (i > 0 && channels[i].index == channels[i - 1].index)
      return DataLossError("IIO channels " + channels[i - 1].name + " and " + channels[i].name + " share index " +
                           std::to_string(channels[i].index));
    const size_t size = static_cast<size_t>(channels[i].type.storage_bits / 8);
    offset = (offset + size - 1) / size * size;
    channels[i].offset = offset;
    offset += size;
    largest = std::max(largest, size);
  }
  layout.record_size_ = (offset + largest - 1) / largest * largest;
  layout.channels_ = std::move(channels);
  return layout;
}

int IioScanLayout::Find(const std::string& name) const {
  for (size_t i = 0; i < channels_.size(); ++i) {
    if (channels_[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

int64_t IioScanLayout::Value(std::span<const uint8_t> record, int i) const {
  const IioChannel& c = channels_[static_cast<size_t>(i)];
  const size_t size = static_cast<size_t>(c.type.storage_bits / 8);
  uint64_t raw = 0;
  for (size_t b = 0; b < size; ++b) {
    const uint8_t byte = record[c.offset + (c.type.big_endian ? b : size - 1 - b)];
    raw = raw << 8 | byte;
  }
  raw >>= c.type.shift;
  if (c.type.bits < 64) {
    const uint64_t mask = (uint64_t{1} << c.type.bits) - 1;
    raw &= mask;
    if (c.type.is_signed && (raw >> (c.type.bits - 1)) != 0) raw |= ~mask;
  }
  return static_cast<int64_t>(raw);
}

}  // namespace cairn
