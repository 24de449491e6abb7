#pragma once
// Framing of Xsens' Xbus protocol on a byte stream (serial line): each message is
//   0xFA (preamble), BID (bus id, 0xFF), MID (message id), LEN, [LEN_HI, LEN_LO if LEN = 0xFF],
//   payload, checksum
// where the checksum makes the sum of every byte after the preamble 0 modulo 256. A checksum that
// does not add up, or a length beyond the protocol's maximum, means the preamble was a payload
// byte or the line lost bytes: the framer skips that 0xFA and searches again, so it resynchronizes
// within one message after any corruption. Bytes skipped and messages refused are counted.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace cairn {

struct XbusMessage {
  uint8_t bus_id = 0xFF;
  uint8_t mid = 0;
  std::span<const uint8_t> payload;  // valid during the callback only
};

struct XbusFramerCounts {
  uint64_t messages = 0;
  uint64_t checksum_errors = 0;
  uint64_t length_errors = 0;  // declared length beyond the maximum
  uint64_t skipped_bytes = 0;  // bytes not part of a valid message
};

class XbusFramer {
 public:
  static constexpr uint8_t kPreamble = 0xFA;
  static constexpr uint8_t kMasterBusId = 0xFF;
  static constexpr size_t kMaxPayload = 2048;

  XbusFramer() { buffer_.reserve(2 * (kMaxPayload + 8)); }

  // Appends `bytes` and calls on_message(const XbusMessage&) for every complete valid message.
  template <class OnMessage>
  void Feed(std::span<const uint8_t> bytes, const OnMessage& on_message) {
    buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
    size_t pos = 0;
    XbusMessage m;
    while (Next(&pos, &m)) on_message(m);
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(pos));
  }

  const XbusFramerCounts& counts() const { return counts_; }
  // Bytes held that do not yet form a message (at most one message's worth).
  size_t pending() const { return buffer_.size(); }
  void Reset() { buffer_.clear(); }

  // One message, ready to write to the device.
  static std::vector<uint8_t> Encode(uint8_t mid, std::span<const uint8_t> payload, uint8_t bus_id = kMasterBusId);

 private:
  // The next message from `*pos` on; false when the buffer holds no complete one (then *pos is
  // where the next search starts: at a preamble that may begin one, or at the end).
  bool Next(size_t* pos, XbusMessage* out);

  std::vector<uint8_t> buffer_;
  XbusFramerCounts counts_;
};

}  // namespace cairn
