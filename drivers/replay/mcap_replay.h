#pragma once
// Replays cairnd's own MCAP recordings (one file, or a folder of recording-NNN.mcap) through the
// same SensorSink as live drivers: IMU, wheel odometry and stereo pairs in the order the recorded
// pipeline consumed them, so a deterministic recording replays to the same results.

#include <atomic>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "drivers/replay/recorded_calibration.h"
#include "drivers/replay/replay_clock.h"
#include "drivers/replay/replay_options.h"
#include "hal/sensor_source_interface.h"

namespace cairn {

class McapReplay final : public SensorSourceInterface {
 public:
  // Lists and checks the files (each must be MCAP with cairn's sensor channels) before anything runs.
  static Expected<std::vector<std::string>> FindRecordings(const std::string& path);

  McapReplay(std::vector<std::string> files, ReplayOptions options);
  ~McapReplay() override;

  std::string name() const override { return "replay"; }
  Status Start(SensorSink* sink) override;
  void Stop() override;
  bool finished() const override { return finished_.load(std::memory_order_acquire); }

  // True for a file or folder that looks like an MCAP recording rather than an EuRoC folder.
  static bool IsRecording(const std::string& path);

  // The calibration a recording file starts with (cairnd writes it on /calibration before any
  // sample); none for recordings made without one. A calibration that does not decode is an error.
  static Expected<std::optional<RecordedCalibration>> ReadCalibration(const std::string& file);

 private:
  void Run(std::stop_token stop);

  std::vector<std::string> files_;
  ReplayOptions options_;
  ReplayClock clock_;
  SensorSink* sink_ = nullptr;
  std::jthread thread_;
  std::atomic<bool> finished_{false};
};

}  // namespace cairn
