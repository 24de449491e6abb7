#pragma once
// An Xsens MTi IMU on a serial line (Xbus protocol, MTData2 output; thesis 7.1: the rovers'
// MTi-10). The reader thread opens the port (raw 8N1 at the configured baud), configures the output
// (xsens_imu_options.h), then decodes every MTData2 message into an ImuSample. Its time is the
// device's sample time (10 kHz ticks) mapped to the host clock (device_clock_mapper.h), or the
// arrival time when the device sends none.
//
// Faults, each reported to the sink and counted, never fatal: corrupt bytes and messages
// (checksum, length, undecodable MTData2: kCorruptSample; the framer resynchronizes on the next
// message), samples the packet counter says were lost (kOverrun), silence beyond `timeout`
// (kTimeout), a port that cannot be opened or vanishes (kDisconnected; reopened every
// `reopen_interval`, reconfigured, and samples resume), and a device that refuses or does not
// acknowledge its configuration (kOther, retried on the next reopen).

#include <atomic>
#include <cstdint>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "common/monotonic_clock.h"
#include "drivers/device_clock_mapper.h"
#include "drivers/fault_throttle.h"
#include "drivers/mtdata2_decoder.h"
#include "drivers/xbus_framer.h"
#include "drivers/xsens_imu_options.h"
#include "hal/imu_interface.h"

namespace cairn {

struct XsensImuCounts {
  uint64_t samples = 0;
  uint64_t corrupt = 0;       // messages or bytes refused
  uint64_t lost = 0;          // samples missing by the packet counter
  uint64_t reconnections = 0;
  uint64_t configurations = 0;  // completed
};

class XsensImuDriver final : public ImuInterface {
 public:
  XsensImuDriver(XsensImuOptions options, ImuCalibration calibration);
  ~XsensImuDriver() override;

  std::string name() const override { return options_.device; }
  Status Start(SensorSink* sink) override;
  void Stop() override;
  bool finished() const override { return false; }
  ImuCalibration calibration() const override { return calibration_; }

  // Read from the reader thread; a snapshot for reports.
  XsensImuCounts counts() const;

 private:
  void Run(std::stop_token stop);
  // GoToConfig, SetOutputConfiguration, GoToMeasurement, each acknowledged in time.
  Status Configure(std::stop_token stop);
  Status Command(std::stop_token stop, uint8_t mid, std::span<const uint8_t> payload);
  void OnMessage(const XbusMessage& m, Timestamp arrival);
  void Fault(DeviceFaultKind kind, const std::string& detail);
  // Messages the driver cannot use at all (a format or output it does not read) arrive with every
  // sample: reported at most once a second, with the count.
  void FormatFault(const std::string& detail, Timestamp now);
  void Close();

  XsensImuOptions options_;
  ImuCalibration calibration_;
  SensorSink* sink_ = nullptr;
  MonotonicClock clock_;
  int fd_ = -1;
  XbusFramer framer_;
  DeviceClockMapper time_map_;
  std::vector<uint8_t> read_buffer_;
  // Packet counter and sample-time unwrapping of the current connection.
  bool have_counter_ = false;
  uint16_t last_counter_ = 0;
  bool have_ticks_ = false;
  uint32_t last_ticks_ = 0;
  int64_t ticks_ = 0;
  // While configuring: the acknowledgement awaited, and an error message if the device sent one.
  int awaited_ack_ = -1;
  bool acked_ = false;
  std::string device_error_;
  FaultThrottle format_faults_;
  std::atomic<uint64_t> samples_{0}, corrupt_{0}, lost_{0}, reconnections_{0}, configurations_{0};
  std::jthread thread_;
};

}  // namespace cairn
