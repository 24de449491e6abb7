#include "drivers/replay/mcap_replay.h"

#include <algorithm>
#include <filesystem>
#include <memory>

#include <opencv2/core.hpp>

#include "cairn/sensors.pb.h"
#include "foxglove/CompressedImage.pb.h"
#include "foxglove/RawImage.pb.h"
#include "io/image_codec.h"
#include "io/mcap/mcap_reader.h"

namespace cairn {
namespace {

namespace fs = std::filesystem;

bool IsMcapFile(const fs::path& p) { return p.extension() == ".mcap" && fs::is_regular_file(p); }

Expected<Image> ToImage(const foxglove::RawImage& m, const std::string& where) {
  PixelFormat format;
  if (m.encoding() == "mono8") format = PixelFormat::kGray8;
  else if (m.encoding() == "bgr8") format = PixelFormat::kBgr8;
  else if (m.encoding() == "rgb8") format = PixelFormat::kRgb8;
  else return DataLossError(where + ": unsupported image encoding '" + m.encoding() + "'");
  const uint64_t needed = static_cast<uint64_t>(m.step()) * m.height();
  if (m.width() == 0 || m.height() == 0 || m.step() < m.width() * static_cast<uint32_t>(BytesPerPixel(format)) ||
      m.data().size() < needed) {
    return DataLossError(where + ": image geometry does not match its data");
  }
  auto holder = std::make_shared<std::string>(m.data());
  Image img;
  img.data = std::shared_ptr<const uint8_t[]>(holder, reinterpret_cast<const uint8_t*>(holder->data()));
  img.width = static_cast<int>(m.width());
  img.height = static_cast<int>(m.height());
  img.stride = static_cast<int>(m.step());
  img.format = format;
  return img;
}

Expected<Image> ToImage(const foxglove::CompressedImage& m, const std::string& where) {
  if (m.format() != "jpeg" && m.format() != "png") {
    return DataLossError(where + ": unsupported compressed image format '" + m.format() + "'");
  }
  const auto result = ImageCodec::Decode({reinterpret_cast<const uint8_t*>(m.data().data()), m.data().size()},
                                         ImageReadMode::kUnchanged, where);
  if (!result.ok()) return result.status();
  const cv::Mat& decoded = *result;
  if (decoded.depth() != CV_8U || (decoded.channels() != 1 && decoded.channels() != 3)) {
    return DataLossError(where + ": " + m.format() + " image does not decode to 8-bit gray or colour");
  }
  const int row_bytes = decoded.cols * decoded.channels();
  auto holder = std::shared_ptr<uint8_t[]>(new uint8_t[static_cast<size_t>(row_bytes) * static_cast<size_t>(decoded.rows)]);
  for (int y = 0; y < decoded.rows; ++y) {
    std::copy(decoded.ptr<uint8_t>(y), decoded.ptr<uint8_t>(y) + row_bytes, holder.get() + static_cast<ptrdiff_t>(y) * row_bytes);
  }
  Image img;
  img.data = holder;
  img.width = decoded.cols;
  img.height = decoded.rows;
  img.stride = row_bytes;
  img.format = decoded.channels() == 1 ? PixelFormat::kGray8 : PixelFormat::kBgr8;
  return img;
}

}  // namespace

bool McapReplay::IsRecording(const std::string& path) {
  if (IsMcapFile(path)) return true;
  if (!fs::is_directory(path)) return false;
  for (const auto& e : fs::directory_iterator(path)) {
    if (IsMcapFile(e.path())) return true;
  }
  return false;
}

Expected<std::vector<std::string>> McapReplay::FindRecordings(const std::string& path) {
  std::vector<std::string> files;
  if (IsMcapFile(path)) {
    files.push_back(path);
  } else if (fs::is_directory(path)) {
    for (const auto& e : fs::directory_iterator(path)) {
      if (IsMcapFile(e.path())) files.push_back(e.path().string());
    }
    std::sort(files.begin(), files.end());  // recording-000, -001, ... in order
  }
  if (files.empty()) return NotFoundError(path + ": no .mcap recording there");
  for (const std::string& f : files) {
    // Channels come first in every file cairn writes: a scan stopped at the first message checks
    // the file's framing and tells whether it carries cairn's sensor channels.
    McapReader reader(f);
    auto scan = reader.Scan(nullptr, [] { return true; });
    if (!scan.ok()) return scan.status();
    bool has_sensor = false;
    for (const auto& [id, c] : reader.channels()) {
      has_sensor = has_sensor || c.topic == "/imu" || c.topic == "/stereo/info";
    }
    if (!has_sensor) return DataLossError(f + ": no cairn sensor channels (/imu, /stereo/info) in this MCAP file");
  }
  return files;
}

Expected<std::optional<RecordedCalibration>> McapReplay::ReadCalibration(const std::string& file) {
  McapReader reader(file);
  std::optional<RecordedCalibration> calibration;
  Status decode = Status::Ok();
  auto scan = reader.Scan(
      [&](const McapChannel& c, const McapMessageView& m) {
        if (c.topic != "/calibration") return;
        auto decoded = RecordedCalibration::Decode(m.data, file + " /calibration");
        if (decoded.ok()) {
          calibration = std::move(*decoded);
        } else {
          decode = decoded.status();
        }
      },
      [] { return true; });  // it is the first message when there is one
  if (!scan.ok()) return scan.status();
  if (!decode.ok()) return decode;
  return calibration;
}

McapReplay::McapReplay(std::vector<std::string> files, ReplayOptions options)
    : files_(std::move(files)), options_(std::move(options)), clock_(options_) {}

McapReplay::~McapReplay() { Stop(); }

Status McapReplay::Start(SensorSink* sink) {
  if (thread_.joinable()) return FailedPreconditionError("replay already started");
  sink_ = sink;
  thread_ = std::jthread([this](std::stop_token stop) { Run(stop); });
  return Status::Ok();
}

void McapReplay::Stop() {
  if (!thread_.joinable()) return;
  thread_.request_stop();
  clock_.Interrupt();
  thread_.join();
}

void McapReplay::Run(std::stop_token stop) {
  bool clock_started = false;
  StereoFrame pending;      // assembled from /stereo/info, /cam0/image, /cam1/image
  int pending_parts = 0;
  bool stopped = false;
  for (const std::string& file : files_) {
    McapReader reader(file);
    msg::ImuSample imu;
    msg::WheelOdometrySample wheel;
    msg::StereoFrameInfo info;
    foxglove::RawImage raw;
    foxglove::CompressedImage compressed;
    const auto fault = [&](const std::string& detail) {
      sink_->OnDeviceFault(DeviceFault{pending.time, "replay/mcap", DeviceFaultKind::kCorruptSample, detail});
    };
    auto scan = reader.Scan(
        [&](const McapChannel& c, const McapMessageView& m) {
          const Timestamp t = Timestamp::FromNanoseconds(static_cast<int64_t>(m.log_time));
          if (!clock_started) {
            clock_.Start(t);
            clock_started = true;
          }
          if (!clock_.WaitUntilDue(stop, t)) {
            stopped = true;
            return;
          }
          const std::string where = file + " " + c.topic + " #" + std::to_string(m.sequence);
          const auto parse = [&](google::protobuf::MessageLite& msg) {
            const bool ok = msg.ParseFromArray(m.data.data(), static_cast<int>(m.data.size()));
            if (!ok) fault(where + ": message does not decode");
            return ok;
          };
          if (c.topic == "/imu" && parse(imu)) {
            ImuSample s;
            s.time = Timestamp::FromNanoseconds(imu.time_ns());
            s.accel = {imu.accel_x(), imu.accel_y(), imu.accel_z()};
            s.gyro = {imu.gyro_x(), imu.gyro_y(), imu.gyro_z()};
            sink_->OnImu(s);
          } else if (c.topic == "/wheel_odometry" && parse(wheel)) {
            WheelOdometrySample s;
            s.time = Timestamp::FromNanoseconds(wheel.time_ns());
            s.fresh_mask = static_cast<uint8_t>(wheel.fresh_mask());
            s.wheel_count = static_cast<uint8_t>(std::min<int>(wheel.wheels_size(), kMaxWheels));
            for (int i = 0; i < s.wheel_count; ++i) {
              s.wheels[static_cast<size_t>(i)] = {wheel.wheels(i).speed(), wheel.wheels(i).steering_angle()};
            }
            sink_->OnWheelOdometry(s);
          } else if (c.topic == "/stereo/info" && parse(info)) {
            if (pending_parts != 0) fault(where + ": previous stereo pair incomplete, dropped");
            pending = StereoFrame{};
            pending.time = Timestamp::FromNanoseconds(info.time_ns());
            pending.exposure = Duration::Nanoseconds(info.exposure_ns());
            pending.frame_counter = info.frame_counter();
            pending_parts = 1;
          } else if (c.topic == "/cam0/image" || c.topic == "/cam1/image" || c.topic == "/cam0/image/compressed" ||
                     c.topic == "/cam1/image/compressed") {
            const bool left = c.topic.starts_with("/cam0/");
            const bool is_compressed = c.topic.ends_with("/compressed");
            if (!(is_compressed ? parse(compressed) : parse(raw))) return;
            if (pending_parts != (left ? 1 : 2) || static_cast<int64_t>(m.log_time) != pending.time.nanoseconds()) {
              fault(where + ": image without its stereo pair info, dropped");
              pending_parts = 0;
              return;
            }
            auto img = is_compressed ? ToImage(compressed, where) : ToImage(raw, where);
            if (!img.ok()) {
              fault(img.status().message());
              pending_parts = 0;
              return;
            }
            (left ? pending.left : pending.right) = *img;
            if (++pending_parts == 3) {
              sink_->OnStereo(pending);
              pending = StereoFrame{};
              pending_parts = 0;
            }
          }
        },
        [&] { return stopped; });
    if (!scan.ok()) {
      // Corruption found mid-file: report, keep what came before, go on with the next file.
      sink_->OnDeviceFault(DeviceFault{pending.time, "replay/mcap", DeviceFaultKind::kCorruptSample,
                                       scan.status().message()});
    } else if (scan->truncated) {
      sink_->OnDeviceFault(DeviceFault{pending.time, "replay/mcap", DeviceFaultKind::kOther,
                                       file + ": recording ends without a footer (cut short); replayed what it holds"});
    }
    if (stopped) return;
  }
  finished_.store(true, std::memory_order_release);
}

}  // namespace cairn
