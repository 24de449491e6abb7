#pragma once
// A GNSS receiver that speaks NMEA 0183 on a serial line (nmea_gnss_options.h). The reader thread
// opens the port (raw 8N1 at the configured baud, as the Xsens driver does) and feeds what it reads,
// stamped with the host's monotonic arrival time, to an NmeaParser, which turns the GGA and GST of
// each epoch into a GnssFix (its time and covariance are described there).
//
// Faults, each reported to the sink and counted, never fatal: refused sentences and stray bytes
// (kCorruptSample, at most one report a second with the count; the parser resynchronizes on the
// next sentence), no fix for longer than `timeout` (kTimeout, once per outage), and a port that
// cannot be opened or vanishes (kDisconnected; reopened every `reopen_interval`, and fixes resume).

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "common/monotonic_clock.h"
#include "drivers/fault_throttle.h"
#include "drivers/nmea_gnss_options.h"
#include "drivers/nmea_parser.h"
#include "hal/gnss_interface.h"

namespace cairn {

struct NmeaGnssCounts {
  uint64_t fixes = 0;
  uint64_t corrupt = 0;         // sentences, lines and runs of stray bytes refused
  uint64_t no_fix = 0;          // GGA without a position
  uint64_t hdop_fallbacks = 0;  // fixes whose covariance came from HDOP instead of GST
  uint64_t reconnections = 0;
};

class NmeaGnssDriver final : public GnssInterface {
 public:
  explicit NmeaGnssDriver(NmeaGnssOptions options);
  ~NmeaGnssDriver() override;

  std::string name() const override { return options_.device; }
  Status Start(SensorSink* sink) override;
  void Stop() override;
  bool finished() const override { return false; }

  // Written by the reader thread; a snapshot for reports.
  NmeaGnssCounts counts() const;

 private:
  void Run(std::stop_token stop);
  void Fault(DeviceFaultKind kind, const std::string& detail);
  // A refused sentence, or none (an empty detail) to report the ones held back once a second has passed.
  void CorruptFault(const std::string& detail, Timestamp now);
  void PublishCounts();
  void Close();

  NmeaGnssOptions options_;
  SensorSink* sink_ = nullptr;
  MonotonicClock clock_;
  int fd_ = -1;
  NmeaParser parser_;
  std::vector<uint8_t> read_buffer_;
  FaultThrottle corrupt_faults_;
  std::string last_refusal_;  // the latest of the refusals held back by the throttle
  std::atomic<uint64_t> fixes_{0}, corrupt_{0}, no_fix_{0}, hdop_fallbacks_{0}, reconnections_{0};
  std::jthread thread_;
};

}  // namespace cairn
