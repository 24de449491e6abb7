#pragma once
// Writes encoded telemetry (see sample_encoder.h) into MCAP files, one channel per topic, rotating
// to a new self-contained file when the current one exceeds the configured size.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "daemon/telemetry/recording_options.h"
#include "daemon/telemetry/sample_encoder.h"
#include "io/mcap/mcap_writer.h"

namespace cairn {

struct RecordingReport {
  std::vector<std::string> files;
  std::map<std::string, uint64_t> messages;  // per topic
  uint64_t bytes = 0;
  uint64_t write_errors = 0;
};

class McapRecorder {
 public:
  McapRecorder(std::string directory, RecordingOptions options);
  ~McapRecorder();

  // The sensors' calibration (cairn.msg.Calibration, see drivers/replay/recorded_calibration.h): written
  // on /calibration at the start of every file, so each file replays with estimation on its own.
  void SetCalibration(std::string encoded) { calibration_ = std::move(encoded); }

  Status Write(TelemetryTopic topic, Timestamp time, const std::string& encoded);
  // Closes the current file (writing its summary).
  Status Close();

  const RecordingReport& report() const { return report_; }

 private:
  Status EnsureOpen(Timestamp time);

  std::string directory_;
  RecordingOptions options_;
  std::string calibration_;
  McapWriter writer_;
  int file_index_ = 0;
  uint16_t channel_[kTelemetryTopicCount] = {};
  uint32_t sequence_[kTelemetryTopicCount] = {};
  uint64_t bytes_closed_ = 0;  // in files already rotated out
  RecordingReport report_;
};

}  // namespace cairn
