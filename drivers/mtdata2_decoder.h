#pragma once
// Decoding of Xsens' MTData2 message (Xbus MID 0x36): a sequence of packets, each a 16-bit data
// identifier (XDI), a one-byte size and big-endian data. What an IMU driver needs is kept: the
// packet counter (XDI 0x1020), the sample time in 10 kHz ticks (0x1060), calibrated acceleration
// (0x402x, m/s^2) and rate of turn (0x802x, rad/s) in the sensor frame, and the status word
// (0xE020). Other packets are skipped and counted. The low bits of an XDI give the number format
// (float32, fixed-point 12.20, or float64; fixed-point 16.32 is refused) and the coordinate frame;
// only the default, the sensor's own axes, is accepted, since the other choices rotate the vectors.

#include <cstdint>
#include <span>

#include <Eigen/Core>

#include "common/status.h"

namespace cairn {

struct Mtdata2Sample {
  bool has_counter = false;
  uint16_t counter = 0;
  bool has_sample_time = false;
  uint32_t sample_time_fine = 0;  // 10 kHz ticks since the device started
  bool has_acceleration = false;
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();  // m/s^2
  bool has_rate_of_turn = false;
  Eigen::Vector3d rate_of_turn = Eigen::Vector3d::Zero();  // rad/s
  bool has_status = false;
  uint32_t status = 0;
  int skipped_packets = 0;  // packets of other XDIs
};

class Mtdata2Decoder {
 public:
  static constexpr uint8_t kMid = 0x36;
  static constexpr uint16_t kPacketCounter = 0x1020;
  static constexpr uint16_t kSampleTimeFine = 0x1060;
  static constexpr uint16_t kAcceleration = 0x4020;
  static constexpr uint16_t kRateOfTurn = 0x8020;
  static constexpr uint16_t kStatusWord = 0xE020;
  static constexpr double kTicksPerSecond = 10000.0;

  // kDataLoss for a payload that ends inside a packet, a packet whose size does not fit its XDI
  // or a non-finite value; kFailedPrecondition for a number format or frame that is not supported.
  static Expected<Mtdata2Sample> Decode(std::span<const uint8_t> payload);
};

}  // namespace cairn
