// What an IIO device's sysfs says of its buffer and the records it then hands out: up to eight
// lines of channel types (the channel's index is its line), then record bytes, decoded with the
// layout those types give.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "drivers/iio_scan_layout.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<cairn::IioChannel> channels;
  size_t at = 0;
  while (at < size && channels.size() < 8) {
    size_t end = at;
    while (end < size && data[end] != '\n') ++end;
    if (end == at) break;  // an empty line ends the types
    const std::string text(reinterpret_cast<const char*>(data + at), end - at);
    auto type = cairn::IioChannelType::Parse(text);
    if (type.ok()) channels.push_back({"c" + std::to_string(channels.size()), static_cast<int>(channels.size()), *type, 0});
    at = end + 1;
  }
  auto layout = cairn::IioScanLayout::Create(channels);
  if (!layout.ok() || layout->record_size() == 0) return 0;
  for (at = at < size ? at : size; at + layout->record_size() <= size; at += layout->record_size()) {
    const std::span<const uint8_t> record(data + at, layout->record_size());
    for (int i = 0; i < static_cast<int>(layout->channels().size()); ++i) (void)layout->Value(record, i);
  }
  return 0;
}
