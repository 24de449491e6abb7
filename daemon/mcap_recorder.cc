#include "daemon/mcap_recorder.h"

#include <algorithm>
#include <cstdio>

#include "cairn/sensors.pb.h"
#include "daemon/protobuf_schema.h"
#include "foxglove/RawImage.pb.h"

namespace cairn {
namespace {

constexpr const char* kTopicNames[] = {"/imu", "/wheel_odometry", "/stereo/info", "/cam0/image", "/cam1/image"};

const char* EncodingOf(PixelFormat f) {
  switch (f) {
    case PixelFormat::kGray8: return "mono8";
    case PixelFormat::kRgb8: return "rgb8";
    case PixelFormat::kBgr8: return "bgr8";
  }
  return "mono8";
}

void FillImage(const Image& img, Timestamp t, const char* frame, foxglove::RawImage* out) {
  out->mutable_timestamp()->set_seconds(t.nanoseconds() / 1000000000);
  out->mutable_timestamp()->set_nanos(static_cast<int32_t>(t.nanoseconds() % 1000000000));
  out->set_frame_id(frame);
  out->set_width(static_cast<uint32_t>(img.width));
  out->set_height(static_cast<uint32_t>(img.height));
  out->set_encoding(EncodingOf(img.format));
  // Rows are stored without padding.
  const int row_bytes = img.width * BytesPerPixel(img.format);
  out->set_step(static_cast<uint32_t>(row_bytes));
  std::string* data = out->mutable_data();
  data->resize(static_cast<size_t>(row_bytes) * static_cast<size_t>(img.height));
  for (int y = 0; y < img.height; ++y) {
    std::copy(img.row(y), img.row(y) + row_bytes, data->data() + static_cast<size_t>(y) * static_cast<size_t>(row_bytes));
  }
}

}  // namespace

McapRecorder::McapRecorder(std::string directory, RecordingOptions options)
    : directory_(std::move(directory)), options_(options) {}

McapRecorder::~McapRecorder() { (void)Close(); }

Status McapRecorder::EnsureOpen() {
  if (writer_.is_open()) return Status::Ok();
  char name[32];
  std::snprintf(name, sizeof(name), "recording-%03d.mcap", file_index_++);
  const std::string path = directory_ + "/" + name;
  McapWriterOptions o;
  o.compression = options_.compression;
  o.chunk_size = static_cast<size_t>(options_.chunk_size);
  o.library = "cairn";
  CAIRN_RETURN_IF_ERROR(writer_.Open(path, o));
  report_.files.push_back(path);
  // Every file is self-contained: schemas and channels again after each rotation.
  const google::protobuf::Descriptor* descriptor[kTopicCount] = {
      msg::ImuSample::descriptor(), msg::WheelOdometrySample::descriptor(),
      msg::StereoFrameInfo::descriptor(), foxglove::RawImage::descriptor(),
      foxglove::RawImage::descriptor()};
  std::map<const google::protobuf::Descriptor*, uint16_t> schema_ids;
  for (int t = 0; t < kTopicCount; ++t) {
    const auto* d = descriptor[t];
    if (schema_ids.count(d) == 0) {
      const std::string set = ProtobufFileDescriptorSet(d);
      auto id = writer_.AddSchema(d->full_name(), "protobuf",
                                  {reinterpret_cast<const uint8_t*>(set.data()), set.size()});
      if (!id.ok()) return id.status();
      schema_ids[d] = *id;
    }
    auto ch = writer_.AddChannel(kTopicNames[t], "protobuf", schema_ids[d]);
    if (!ch.ok()) return ch.status();
    channel_[t] = *ch;
  }
  return Status::Ok();
}

Status McapRecorder::Write(Topic topic, Timestamp time, const std::string& bytes) {
  Status s = EnsureOpen();
  if (s.ok()) {
    const uint64_t t = static_cast<uint64_t>(time.nanoseconds());
    s = writer_.Write(channel_[topic], sequence_[topic]++, t, t,
                      {reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()});
  }
  if (!s.ok()) {
    ++report_.write_errors;
    return s;
  }
  ++report_.messages[kTopicNames[topic]];
  report_.bytes = bytes_closed_ + writer_.bytes_written();
  if (writer_.bytes_written() >= static_cast<uint64_t>(options_.rotate_size)) {
    CAIRN_RETURN_IF_ERROR(writer_.Close());
    bytes_closed_ += writer_.bytes_written();
    report_.bytes = bytes_closed_;
  }
  return Status::Ok();
}

Status McapRecorder::RecordImu(const ImuSample& s) {
  msg::ImuSample m;
  m.set_time_ns(s.time.nanoseconds());
  m.set_accel_x(s.accel.x());
  m.set_accel_y(s.accel.y());
  m.set_accel_z(s.accel.z());
  m.set_gyro_x(s.gyro.x());
  m.set_gyro_y(s.gyro.y());
  m.set_gyro_z(s.gyro.z());
  m.SerializeToString(&scratch_);
  return Write(kImu, s.time, scratch_);
}

Status McapRecorder::RecordWheelOdometry(const WheelOdometrySample& s) {
  msg::WheelOdometrySample m;
  m.set_time_ns(s.time.nanoseconds());
  m.set_fresh_mask(s.fresh_mask);
  for (int i = 0; i < s.wheel_count; ++i) {
    auto* w = m.add_wheels();
    w->set_speed(s.wheels[static_cast<size_t>(i)].speed);
    w->set_steering_angle(s.wheels[static_cast<size_t>(i)].steering_angle);
  }
  m.SerializeToString(&scratch_);
  return Write(kWheel, s.time, scratch_);
}

Status McapRecorder::RecordStereo(const StereoFrame& f) {
  msg::StereoFrameInfo info;
  info.set_time_ns(f.time.nanoseconds());
  info.set_exposure_ns(f.exposure.nanoseconds());
  info.set_frame_counter(f.frame_counter);
  info.SerializeToString(&scratch_);
  CAIRN_RETURN_IF_ERROR(Write(kStereoInfo, f.time, scratch_));
  foxglove::RawImage img;
  FillImage(f.left, f.time, "cam0", &img);
  img.SerializeToString(&scratch_);
  CAIRN_RETURN_IF_ERROR(Write(kCam0, f.time, scratch_));
  FillImage(f.right, f.time, "cam1", &img);
  img.SerializeToString(&scratch_);
  return Write(kCam1, f.time, scratch_);
}

Status McapRecorder::Close() {
  if (!writer_.is_open()) return Status::Ok();
  const Status s = writer_.Close();
  bytes_closed_ += writer_.bytes_written();
  report_.bytes = bytes_closed_;
  return s;
}

}  // namespace cairn
