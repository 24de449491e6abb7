#pragma once
// Wheel odometry from the platform controller over SocketCAN. The reader thread blocks in poll()
// with a short timeout so that Stop() is prompt; a vanished interface is reported as a device
// fault and reopened once a second, a silent bus as a timeout, and the daemon keeps running.

#include <atomic>
#include <thread>

#include "common/clock_interface.h"
#include "common/monotonic_clock.h"
#include "drivers/can_wheel_decoder.h"
#include "hal/wheel_odometry_interface.h"

namespace cairn {

class SocketCanWheelDriver final : public WheelOdometryInterface {
 public:
  explicit SocketCanWheelDriver(CanWheelOptions options);
  // Reads frames from an already open descriptor carrying `struct can_frame` records (a CAN_RAW
  // socket, or a SOCK_SEQPACKET socketpair in tests); takes ownership. It is not reopened.
  SocketCanWheelDriver(CanWheelOptions options, int fd);
  ~SocketCanWheelDriver() override;

  std::string name() const override { return options_.interface; }
  Status Start(SensorSink* sink) override;
  void Stop() override;
  bool finished() const override { return false; }
  WheelCalibration calibration() const override { return decoder_.calibration(); }

  uint64_t frames_received() const { return frames_.load(std::memory_order_relaxed); }

  // Opens and binds a CAN_RAW socket on `interface` with a receive filter for the configured ids.
  static Expected<int> OpenSocket(const CanWheelOptions& options);

 private:
  void Run(std::stop_token stop);
  void Fault(DeviceFaultKind kind, const std::string& detail);

  CanWheelOptions options_;
  CanWheelDecoder decoder_;
  int fd_ = -1;
  bool owns_interface_;  // true: we open (and reopen) the interface ourselves
  SensorSink* sink_ = nullptr;
  MonotonicClock clock_;
  std::jthread thread_;
  std::atomic<uint64_t> frames_{0};
};

}  // namespace cairn
