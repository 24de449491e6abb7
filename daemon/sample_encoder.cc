#include "daemon/sample_encoder.h"

#include <algorithm>

#include "cairn/sensors.pb.h"
#include "foxglove/RawImage.pb.h"

namespace cairn {
namespace {

const char* EncodingOf(PixelFormat f) {
  switch (f) {
    case PixelFormat::kGray8: return "mono8";
    case PixelFormat::kRgb8: return "rgb8";
    case PixelFormat::kBgr8: return "bgr8";
  }
  return "mono8";
}

}  // namespace

const char* TelemetryTopicName(TelemetryTopic topic) {
  switch (topic) {
    case TelemetryTopic::kImu: return "/imu";
    case TelemetryTopic::kWheelOdometry: return "/wheel_odometry";
    case TelemetryTopic::kStereoInfo: return "/stereo/info";
    case TelemetryTopic::kCam0Image: return "/cam0/image";
    case TelemetryTopic::kCam1Image: return "/cam1/image";
  }
  return "";
}

const google::protobuf::Descriptor* TelemetryTopicDescriptor(TelemetryTopic topic) {
  switch (topic) {
    case TelemetryTopic::kImu: return msg::ImuSample::descriptor();
    case TelemetryTopic::kWheelOdometry: return msg::WheelOdometrySample::descriptor();
    case TelemetryTopic::kStereoInfo: return msg::StereoFrameInfo::descriptor();
    case TelemetryTopic::kCam0Image:
    case TelemetryTopic::kCam1Image: return foxglove::RawImage::descriptor();
  }
  return nullptr;
}

const std::string& SampleEncoder::Imu(const ImuSample& s) {
  msg::ImuSample m;
  m.set_time_ns(s.time.nanoseconds());
  m.set_accel_x(s.accel.x());
  m.set_accel_y(s.accel.y());
  m.set_accel_z(s.accel.z());
  m.set_gyro_x(s.gyro.x());
  m.set_gyro_y(s.gyro.y());
  m.set_gyro_z(s.gyro.z());
  m.SerializeToString(&imu_);
  return imu_;
}

const std::string& SampleEncoder::WheelOdometry(const WheelOdometrySample& s) {
  msg::WheelOdometrySample m;
  m.set_time_ns(s.time.nanoseconds());
  m.set_fresh_mask(s.fresh_mask);
  for (int i = 0; i < s.wheel_count; ++i) {
    auto* w = m.add_wheels();
    w->set_speed(s.wheels[static_cast<size_t>(i)].speed);
    w->set_steering_angle(s.wheels[static_cast<size_t>(i)].steering_angle);
  }
  m.SerializeToString(&wheel_);
  return wheel_;
}

const std::string& SampleEncoder::StereoInfo(const StereoFrame& f) {
  msg::StereoFrameInfo m;
  m.set_time_ns(f.time.nanoseconds());
  m.set_exposure_ns(f.exposure.nanoseconds());
  m.set_frame_counter(f.frame_counter);
  m.SerializeToString(&info_);
  return info_;
}

const std::string& SampleEncoder::Image(const cairn::Image& img, Timestamp t, const char* frame_id) {
  foxglove::RawImage m;
  m.mutable_timestamp()->set_seconds(t.nanoseconds() / 1000000000);
  m.mutable_timestamp()->set_nanos(static_cast<int32_t>(t.nanoseconds() % 1000000000));
  m.set_frame_id(frame_id);
  m.set_width(static_cast<uint32_t>(img.width));
  m.set_height(static_cast<uint32_t>(img.height));
  m.set_encoding(EncodingOf(img.format));
  // Rows are stored without padding.
  const int row_bytes = img.width * BytesPerPixel(img.format);
  m.set_step(static_cast<uint32_t>(row_bytes));
  std::string* data = m.mutable_data();
  data->resize(static_cast<size_t>(row_bytes) * static_cast<size_t>(img.height));
  for (int y = 0; y < img.height; ++y) {
    std::copy(img.row(y), img.row(y) + row_bytes,
              data->data() + static_cast<size_t>(y) * static_cast<size_t>(row_bytes));
  }
  m.SerializeToString(&image_);
  return image_;
}

}  // namespace cairn
