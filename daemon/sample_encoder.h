#pragma once
// Encodes HAL samples as the protobuf messages that recordings and the live stream carry. One
// encoding serves both. Topics: /imu (cairn.msg.ImuSample), /wheel_odometry
// (cairn.msg.WheelOdometrySample), /stereo/info (cairn.msg.StereoFrameInfo), /cam0/image and
// /cam1/image (foxglove.RawImage, viewable in Foxglove as they are).

#include <string>

#include <google/protobuf/descriptor.h>

#include "hal/imu_sample.h"
#include "hal/stereo_frame.h"
#include "hal/wheel_odometry_sample.h"

namespace cairn {

enum class TelemetryTopic { kImu, kWheelOdometry, kStereoInfo, kCam0Image, kCam1Image };
inline constexpr int kTelemetryTopicCount = 5;

const char* TelemetryTopicName(TelemetryTopic topic);
const google::protobuf::Descriptor* TelemetryTopicDescriptor(TelemetryTopic topic);

class SampleEncoder {
 public:
  // Each returns the encoded message, valid until the next call of the same method.
  const std::string& Imu(const ImuSample& s);
  const std::string& WheelOdometry(const WheelOdometrySample& s);
  const std::string& StereoInfo(const StereoFrame& f);
  const std::string& Image(const Image& img, Timestamp time, const char* frame_id);

 private:
  std::string imu_, wheel_, info_, image_;
};

}  // namespace cairn
