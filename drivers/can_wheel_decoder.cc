#include "drivers/can_wheel_decoder.h"

#include <cmath>

namespace cairn {

bool CanIdMatches(const CanSignalOptions& signal, const can_frame& frame) {
  const bool extended = (frame.can_id & CAN_EFF_FLAG) != 0;
  if (extended != signal.extended_id) return false;
  const canid_t id = frame.can_id & (extended ? CAN_EFF_MASK : CAN_SFF_MASK);
  return static_cast<int64_t>(id) == signal.id;
}

std::optional<double> DecodeCanSignal(const CanSignalOptions& s, const can_frame& frame) {
  const int start = static_cast<int>(s.start_byte), len = static_cast<int>(s.length);
  if (start + len > frame.len || frame.len > CAN_MAX_DLEN) return std::nullopt;
  uint32_t raw = 0;
  for (int i = 0; i < len; ++i) {
    const int byte = s.byte_order == ByteOrder::kLittleEndian ? start + i : start + len - 1 - i;
    raw |= static_cast<uint32_t>(frame.data[byte]) << (8 * i);
  }
  double value;
  if (s.is_signed && len < 4 && (raw & (1u << (8 * len - 1)))) {
    value = static_cast<double>(static_cast<int64_t>(raw) - (int64_t{1} << (8 * len)));
  } else if (s.is_signed && len == 4) {
    value = static_cast<double>(static_cast<int32_t>(raw));
  } else {
    value = static_cast<double>(raw);
  }
  return value * s.scale + s.offset;
}

void EncodeCanSignal(const CanSignalOptions& s, double value, can_frame* frame) {
  const int start = static_cast<int>(s.start_byte), len = static_cast<int>(s.length);
  const int64_t raw = std::llround((value - s.offset) / s.scale);
  const uint32_t bits = static_cast<uint32_t>(raw);
  for (int i = 0; i < len; ++i) {
    const int byte = s.byte_order == ByteOrder::kLittleEndian ? start + i : start + len - 1 - i;
    frame->data[byte] = static_cast<uint8_t>((bits >> (8 * i)) & 0xFF);
  }
  if (frame->len < start + len) frame->len = static_cast<uint8_t>(start + len);
  frame->can_id = static_cast<canid_t>(s.id) | (s.extended_id ? CAN_EFF_FLAG : 0);
}

CanWheelDecoder::CanWheelDecoder(const CanWheelOptions& options) : options_(options) {
  wheels_ = {&options_.front_left, &options_.front_right, &options_.rear_left, &options_.rear_right};
  state_.wheel_count = kMaxWheels;
}

WheelCalibration CanWheelDecoder::calibration() const {
  WheelCalibration c;
  c.wheel_count = kMaxWheels;
  c.speed_noise = options_.speed_noise;
  for (int i = 0; i < kMaxWheels; ++i) {
    c.p_body_wheel[static_cast<size_t>(i)] = {wheels_[static_cast<size_t>(i)]->position[0],
                                              wheels_[static_cast<size_t>(i)]->position[1]};
  }
  return c;
}

CanWheelDecoder::Result CanWheelDecoder::Feed(const can_frame& frame, Timestamp time,
                                              WheelOdometrySample* out) {
  if (frame.can_id & CAN_ERR_FLAG) return Result::kErrorFrame;
  if (frame.can_id & CAN_RTR_FLAG) return Result::kIgnored;
  bool updated = false, speed_updated = false, malformed = false;
  for (size_t i = 0; i < wheels_.size(); ++i) {
    const WheelCanOptions& w = *wheels_[i];
    if (CanIdMatches(w.speed, frame)) {
      if (auto v = DecodeCanSignal(w.speed, frame)) {
        state_.wheels[i].speed = *v;
        state_.fresh_mask = static_cast<uint8_t>(state_.fresh_mask | (1u << i));
        updated = speed_updated = true;
      } else {
        malformed = true;
      }
    }
    if (w.steered && CanIdMatches(w.steering, frame)) {
      if (auto v = DecodeCanSignal(w.steering, frame)) {
        state_.wheels[i].steering_angle = *v;
        updated = true;
      } else {
        malformed = true;
      }
    }
  }
  if (malformed) return Result::kMalformed;
  const bool is_sync = options_.sync_id >= 0 &&
                       static_cast<int64_t>(frame.can_id & CAN_EFF_MASK) == options_.sync_id;
  if ((options_.sync_id < 0 && speed_updated) || is_sync) {
    state_.time = time;
    *out = state_;
    state_.fresh_mask = 0;
    return Result::kSampleReady;
  }
  return updated ? Result::kUpdated : Result::kIgnored;
}

}  // namespace cairn
