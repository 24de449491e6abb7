#include "drivers/xbus_framer.h"

#include <algorithm>

namespace cairn {

bool XbusFramer::Next(size_t* pos, XbusMessage* out) {
  size_t p = *pos;
  const size_t n = buffer_.size();
  while (true) {
    const auto preamble = std::find(buffer_.begin() + static_cast<std::ptrdiff_t>(p), buffer_.end(), kPreamble);
    const size_t start = static_cast<size_t>(preamble - buffer_.begin());
    counts_.skipped_bytes += start - p;
    p = start;
    *pos = p;
    if (n - p < 4) return false;
    size_t header = 4;
    size_t length = buffer_[p + 3];
    if (length == 0xFF) {
      if (n - p < 6) return false;
      header = 6;
      length = static_cast<size_t>(buffer_[p + 4]) << 8 | buffer_[p + 5];
      if (length > kMaxPayload) {
        ++counts_.length_errors;
        ++counts_.skipped_bytes;
        ++p;
        continue;
      }
    }
    const size_t total = header + length + 1;
    if (n - p < total) return false;
    uint8_t sum = 0;
    for (size_t i = p + 1; i < p + total; ++i) sum = static_cast<uint8_t>(sum + buffer_[i]);
    if (sum != 0) {
      // A payload byte that looked like a preamble, or a damaged message: search on after it.
      ++counts_.checksum_errors;
      ++counts_.skipped_bytes;
      ++p;
      continue;
    }
    out->bus_id = buffer_[p + 1];
    out->mid = buffer_[p + 2];
    out->payload = std::span<const uint8_t>(buffer_.data() + p + header, length);
    ++counts_.messages;
    *pos = p + total;
    return true;
  }
}

std::vector<uint8_t> XbusFramer::Encode(uint8_t mid, std::span<const uint8_t> payload, uint8_t bus_id) {
  std::vector<uint8_t> out;
  out.reserve(payload.size() + 7);
  out.push_back(kPreamble);
  out.push_back(bus_id);
  out.push_back(mid);
  if (payload.size() >= 0xFF) {
    out.push_back(0xFF);
    out.push_back(static_cast<uint8_t>(payload.size() >> 8));
    out.push_back(static_cast<uint8_t>(payload.size() & 0xFF));
  } else {
    out.push_back(static_cast<uint8_t>(payload.size()));
  }
  out.insert(out.end(), payload.begin(), payload.end());
  uint8_t sum = 0;
  for (size_t i = 1; i < out.size(); ++i) sum = static_cast<uint8_t>(sum + out[i]);
  out.push_back(static_cast<uint8_t>(-sum));
  return out;
}

}  // namespace cairn
