#include "daemon/telemetry/sample_encoder.h"

#include <algorithm>

#include <opencv2/core.hpp>

#include "cairn/sensors.pb.h"
#include "daemon/telemetry/foxglove_fields.h"
#include "foxglove/CompressedImage.pb.h"
#include "foxglove/FrameTransform.pb.h"
#include "foxglove/Grid.pb.h"
#include "foxglove/PointCloud.pb.h"
#include "foxglove/PoseInFrame.pb.h"
#include "io/image_codec.h"
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
    case TelemetryTopic::kCam0Compressed: return "/cam0/image/compressed";
    case TelemetryTopic::kCam1Compressed: return "/cam1/image/compressed";
    case TelemetryTopic::kPose: return "/pose";
    case TelemetryTopic::kTransform: return "/tf";
    case TelemetryTopic::kSubmapCloud: return "/map/submaps";
    case TelemetryTopic::kObstacleGrid: return "/map/obstacles";
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
    case TelemetryTopic::kCam0Compressed:
    case TelemetryTopic::kCam1Compressed: return foxglove::CompressedImage::descriptor();
    case TelemetryTopic::kPose: return foxglove::PoseInFrame::descriptor();
    case TelemetryTopic::kTransform: return foxglove::FrameTransform::descriptor();
    case TelemetryTopic::kSubmapCloud: return foxglove::PointCloud::descriptor();
    case TelemetryTopic::kObstacleGrid: return foxglove::Grid::descriptor();
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
  SetFoxgloveTime(t, m.mutable_timestamp());
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

bool SampleEncoder::Compressed(const cairn::Image& img, Timestamp t, const char* frame_id,
                               const ImageEncodingOptions& options, const std::string** encoded) {
  if (img.empty()) return false;
  const int type = img.format == PixelFormat::kGray8 ? CV_8UC1 : CV_8UC3;
  const cv::Mat pixels(img.height, img.width, type, const_cast<uint8_t*>(img.data.get()), static_cast<size_t>(img.stride));
  const ColourOrder order = img.format == PixelFormat::kRgb8 ? ColourOrder::kRgb : ColourOrder::kBgr;
  const bool jpeg = options.format == ImageFormat::kJpeg;
  // PNG at level 1: fast, the telemetry core is shared.
  const Status status = jpeg ? ImageCodec::EncodeJpeg(pixels, static_cast<int>(options.jpeg_quality), &codec_buffer_, order)
                              : ImageCodec::EncodePng(pixels, 1, &codec_buffer_, order);
  if (!status.ok()) return false;
  foxglove::CompressedImage m;
  SetFoxgloveTime(t, m.mutable_timestamp());
  m.set_frame_id(frame_id);
  m.set_format(jpeg ? "jpeg" : "png");
  m.set_data(codec_buffer_.data(), codec_buffer_.size());
  m.SerializeToString(&compressed_);
  *encoded = &compressed_;
  return true;
}

}  // namespace cairn
