#pragma once
// Encodes HAL samples as the protobuf messages that recordings and the live stream carry. One
// encoding serves both. Topics: /imu (cairn.msg.ImuSample), /wheel_odometry
// (cairn.msg.WheelOdometrySample), /stereo/info (cairn.msg.StereoFrameInfo), /cam0/image and
// /cam1/image (foxglove.RawImage), or /cam0/image/compressed and /cam1/image/compressed
// (foxglove.CompressedImage, PNG or JPEG); Foxglove shows all of them as they are.

#include <string>
#include <vector>

#include <google/protobuf/descriptor.h>

#include "daemon/telemetry/image_encoding_options.h"
#include "hal/imu_sample.h"
#include "hal/stereo_frame.h"
#include "hal/wheel_odometry_sample.h"

namespace cairn {

// Raw sensor samples first (what a recording replays), then what the daemon estimated.
enum class TelemetryTopic {
  kImu, kWheelOdometry, kStereoInfo, kCam0Image, kCam1Image, kCam0Compressed, kCam1Compressed,
  kPose, kTransform, kSubmapCloud, kObstacleGrid
};
inline constexpr int kTelemetryTopicCount = 11;

const char* TelemetryTopicName(TelemetryTopic topic);
const google::protobuf::Descriptor* TelemetryTopicDescriptor(TelemetryTopic topic);

class SampleEncoder {
 public:
  // Each returns the encoded message, valid until the next call of the same method.
  const std::string& Imu(const ImuSample& s);
  const std::string& WheelOdometry(const WheelOdometrySample& s);
  const std::string& StereoInfo(const StereoFrame& f);
  const std::string& Image(const Image& img, Timestamp time, const char* frame_id);
  // PNG or JPEG as foxglove.CompressedImage; false (and nothing valid) if the codec fails.
  bool Compressed(const cairn::Image& img, Timestamp time, const char* frame_id,
                       const ImageEncodingOptions& options, const std::string** encoded);

 private:
  std::string imu_, wheel_, info_, image_, compressed_;
  std::vector<uint8_t> codec_buffer_;
};

}  // namespace cairn
