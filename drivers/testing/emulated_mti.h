#pragma once
// An Xsens MTi on a pseudo-terminal, for the driver's tests: the device side of the pty is reached
// through a symlink (as udev names a real one), so the device can vanish and come back under the
// same path. A thread answers GoToConfig, SetOutputConfiguration and GoToMeasurement like the
// device, and in measurement streams MTData2 at the configured rate: packet counter, sample time
// (10 kHz), acceleration (0.01 * n, -0.02, 9.81) and rate of turn (0.1, -0.2, 0.001 * n) for sample
// n, status word. Tests can inject raw bytes, skip packets, fall silent, refuse configuration or
// vanish.

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "common/status.h"

namespace cairn::testing {

class EmulatedMti {
 public:
  // A new pty; `link` is (re)pointed at its device side.
  static Expected<std::unique_ptr<EmulatedMti>> Create(const std::string& link);
  ~EmulatedMti();

  void SendRaw(std::span<const uint8_t> bytes);  // between two samples
  void SkipPackets(int count);                  // the counter jumps as if they were lost
  void SetSilent(bool silent);                  // stops streaming without closing
  void RefuseConfiguration(bool refuse);        // answer SetOutputConfiguration with an error
  void Vanish();                                // closes the pty: the port hangs up
  void StartMeasuring();                        // as a device that kept its stored configuration
  void SendOrientationOnly(bool only);          // a quaternion instead of the inertial data

  uint64_t samples_sent() const { return samples_.load(); }
  uint64_t configurations() const { return configurations_.load(); }
  std::vector<uint8_t> output_configuration() const;  // the last SetOutputConfiguration payload
  double rate_hz() const { return rate_hz_.load(); }

 private:
  EmulatedMti() = default;
  void Run(std::stop_token stop);
  void Write(std::span<const uint8_t> bytes);

  int master_ = -1;
  std::atomic<bool> silent_{false}, refuse_{false}, measuring_{false}, orientation_only_{false};
  std::atomic<int> skip_{0};
  std::atomic<double> rate_hz_{100.0};
  std::atomic<uint64_t> samples_{0}, configurations_{0};
  mutable std::mutex mutex_;  // the pending raw bytes and the output configuration
  std::vector<uint8_t> raw_;
  std::vector<uint8_t> output_configuration_;
  std::jthread thread_;
};

}  // namespace cairn::testing
