#pragma once
// Where the platform controller puts each wheel's speed and steering angle in its CAN frames.
// A signal is `length` bytes at `start_byte` of frame `id`, integer, scaled to SI units:
// value = raw * scale + offset.

#include <string>

#include "common/options_visitor.h"

namespace cairn {

enum class ByteOrder { kLittleEndian, kBigEndian };

struct CanSignalOptions {
  int64_t id = 0;
  bool extended_id = false;
  int64_t start_byte = 0;
  int64_t length = 2;
  bool is_signed = true;
  ByteOrder byte_order = ByteOrder::kLittleEndian;
  double scale = 1.0;
  double offset = 0.0;

  void Visit(OptionsVisitor& v) {
    v.Integer("id", id, 0, 0x1FFFFFFF, "");
    v.Flag("extended_id", extended_id);
    v.Integer("start_byte", start_byte, 0, 7, "byte");
    v.Integer("length", length, 1, 4, "bytes");
    v.Flag("signed", is_signed);
    v.Choice("byte_order", byte_order, {{"little", ByteOrder::kLittleEndian},
                                        {"big", ByteOrder::kBigEndian}});
    v.Number("scale", scale, -1e6, 1e6, "SI unit per count");
    v.Number("offset", offset, -1e6, 1e6, "SI unit");
  }
  Status Validate() const {
    if (start_byte + length > 8) return InvalidArgumentError("start_byte + length exceeds the 8-byte CAN payload");
    if (!extended_id && id > 0x7FF) return InvalidArgumentError("id does not fit an 11-bit standard identifier (set extended_id)");
    if (scale == 0.0) return InvalidArgumentError("scale must not be zero");
    return Status::Ok();
  }
};

struct WheelCanOptions {
  CanSignalOptions speed;             // m/s at the contact point, positive forward
  bool steered = true;
  CanSignalOptions steering;          // rad, positive turns left; ignored when not steered
  std::vector<double> position = {0.0, 0.0};  // contact point x, y in the body frame

  void Visit(OptionsVisitor& v) {
    v.Section("speed", speed);
    v.Flag("steered", steered);
    v.Section("steering", steering);
    v.Numbers("position", position, 2, 2, -10.0, 10.0, "m");
  }
};

struct CanWheelOptions {
  bool enabled = false;
  std::string interface = "can0";
  // The frame whose arrival completes one odometry sample; -1 publishes after every frame that
  // carries a speed.
  int64_t sync_id = -1;
  // No frames for this long is reported as a device timeout (once per outage).
  double timeout = 0.5;
  double speed_noise = 0.02;
  WheelCanOptions front_left, front_right, rear_left, rear_right;

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Text("interface", interface);
    v.Integer("sync_id", sync_id, -1, 0x1FFFFFFF, "");
    v.Number("timeout", timeout, 0.01, 60.0, "s");
    v.Number("speed_noise", speed_noise, 0.0, 10.0, "m/s");
    v.Section("front_left", front_left);
    v.Section("front_right", front_right);
    v.Section("rear_left", rear_left);
    v.Section("rear_right", rear_right);
  }
  Status Validate() const {
    if (enabled && interface.empty()) return InvalidArgumentError("interface must name a CAN interface");
    return Status::Ok();
  }
};

}  // namespace cairn
