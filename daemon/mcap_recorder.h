#pragma once
// Writes HAL samples as protobuf messages into MCAP files, rotating to a new file when the current
// one exceeds the configured size. Channels: /imu (cairn.ImuSample), /wheel_odometry
// (cairn.WheelOdometrySample), /stereo/info (cairn.StereoFrameInfo), /cam0/image and /cam1/image
// (foxglove.RawImage, viewable in Foxglove as they are).

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "drivers/mcap/mcap_writer.h"
#include "daemon/recording_options.h"
#include "hal/imu_sample.h"
#include "hal/stereo_frame.h"
#include "hal/wheel_odometry_sample.h"

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

  Status RecordImu(const ImuSample& s);
  Status RecordWheelOdometry(const WheelOdometrySample& s);
  Status RecordStereo(const StereoFrame& f);
  // Closes the current file (writing its summary).
  Status Close();

  const RecordingReport& report() const { return report_; }

 private:
  enum Topic { kImu, kWheel, kStereoInfo, kCam0, kCam1, kTopicCount };
  Status EnsureOpen();
  Status Write(Topic topic, Timestamp time, const std::string& bytes);

  std::string directory_;
  RecordingOptions options_;
  McapWriter writer_;
  int file_index_ = 0;
  uint16_t channel_[kTopicCount] = {};
  uint32_t sequence_[kTopicCount] = {};
  uint64_t bytes_closed_ = 0;  // in files already rotated out
  RecordingReport report_;
  std::string scratch_;
};

}  // namespace cairn
