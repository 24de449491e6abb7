#include "drivers/iio_imu_driver.h"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace cairn {
namespace {

constexpr int kIioPollMs = 50;
constexpr const char* kAccel[3] = {"in_accel_x", "in_accel_y", "in_accel_z"};
constexpr const char* kGyro[3] = {"in_anglvel_x", "in_anglvel_y", "in_anglvel_z"};
constexpr const char* kTimestamp = "in_timestamp";

Expected<std::string> ReadText(const std::string& path) {
  std::ifstream in(path);
  if (!in) return NotFoundError(path + ": cannot read");
  std::stringstream s;
  s << in.rdbuf();
  std::string text = s.str();
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text;
}

Status WriteText(const std::string& path, const std::string& value) {
  std::ofstream out(path);
  if (!out) return IoError(path + ": cannot write (" + std::strerror(errno) + ")");
  out << value << '\n';
  out.flush();
  if (!out) return IoError(path + ": the kernel refused '" + value + "'");
  return Status::Ok();
}

Expected<double> ReadNumber(const std::string& path) {
  auto text = ReadText(path);
  if (!text.ok()) return text.status();
  char* end = nullptr;
  const double v = std::strtod(text->c_str(), &end);
  if (end == text->c_str() || !std::isfinite(v)) return DataLossError(path + ": '" + *text + "' is not a number");
  return v;
}

// in_accel_x_scale, else the shared in_accel_scale.
Expected<double> ReadScale(const std::string& dir, const std::string& channel) {
  const std::string own = dir + "/" + channel + "_scale";
  if (std::filesystem::exists(own)) return ReadNumber(own);
  return ReadNumber(dir + "/" + channel.substr(0, channel.rfind('_')) + "_scale");
}

}  // namespace

IioImuDriver::IioImuDriver(IioImuOptions options, ImuCalibration calibration)
    : options_(std::move(options)), calibration_(calibration) {
  if (options_.rate_hz > 0.0) calibration_.rate_hz = options_.rate_hz;
}

IioImuDriver::~IioImuDriver() { Stop(); }  // Stop() closes the device

Expected<std::string> IioImuDriver::FindDevice(const std::string& sysfs_root, const std::string& name) {
  std::error_code ec;
  std::vector<std::string> seen;
  for (const auto& e : std::filesystem::directory_iterator(sysfs_root, ec)) {
    auto device_name = ReadText(e.path().string() + "/name");
    if (!device_name.ok()) continue;
    if (*device_name == name) return e.path().string();
    seen.push_back(*device_name);
  }
  if (ec) return UnavailableError(sysfs_root + ": " + ec.message() + " (no IIO subsystem?)");
  std::string others;
  for (const std::string& s : seen) others += (others.empty() ? "" : ", ") + s;
  return UnavailableError("no IIO device named '" + name + "' under " + sysfs_root +
                          (others.empty() ? std::string(" (none there)") : " (there: " + others + ")"));
}

Status IioImuDriver::Open() {
  auto dir = FindDevice(options_.sysfs_root, options_.name);
  if (!dir.ok()) return dir.status();
  sysfs_dir_ = *dir;
  const std::string& d = sysfs_dir_;
  const std::string scan = d + "/scan_elements";
  // The buffer must be off while its channels and length change.
  CAIRN_RETURN_IF_ERROR(WriteText(d + "/buffer/enable", "0"));
  // Timestamps on the clock every driver stamps with; kernels without the choice stamp with the
  // wall clock, and then the arrival time is used instead.
  const bool monotonic = std::filesystem::exists(d + "/current_timestamp_clock");
  if (monotonic) CAIRN_RETURN_IF_ERROR(WriteText(d + "/current_timestamp_clock", "monotonic"));
  std::vector<IioChannel> channels;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(scan, ec)) {
    const std::string file = e.path().filename().string();
    if (file.size() < 4 || file.compare(file.size() - 3, 3, "_en") != 0) continue;
    const std::string channel = file.substr(0, file.size() - 3);
    bool wanted = channel == kTimestamp;
    for (int i = 0; i < 3; ++i) wanted = wanted || channel == kAccel[i] || channel == kGyro[i];
    CAIRN_RETURN_IF_ERROR(WriteText(e.path().string(), wanted ? "1" : "0"));
    if (!wanted) continue;
    auto index = ReadNumber(scan + "/" + channel + "_index");
    if (!index.ok()) return index.status();
    auto type_text = ReadText(scan + "/" + channel + "_type");
    if (!type_text.ok()) return type_text.status();
    auto type = IioChannelType::Parse(*type_text);
    if (!type.ok()) return type.status().WithContext(scan + "/" + channel + "_type");
    channels.push_back({channel, static_cast<int>(*index), *type, 0});
  }
  if (ec) return UnavailableError(scan + ": " + ec.message() + " (no buffered interface?)");
  auto layout = IioScanLayout::Create(std::move(channels));
  if (!layout.ok()) return layout.status();
  layout_ = std::move(*layout);
  for (int i = 0; i < 3; ++i) {
    accel_[i] = layout_.Find(kAccel[i]);
    gyro_[i] = layout_.Find(kGyro[i]);
    if (accel_[i] < 0 || gyro_[i] < 0)
      return FailedPreconditionError(d + " has no " + (accel_[i] < 0 ? kAccel[i] : kGyro[i]) +
                                     " channel: not an IMU this driver reads");
    auto a = ReadScale(d, kAccel[i]);
    if (!a.ok()) return a.status();
    auto g = ReadScale(d, kGyro[i]);
    if (!g.ok()) return g.status();
    accel_scale_[i] = *a;
    gyro_scale_[i] = *g;
  }
  timestamp_ = monotonic ? layout_.Find(kTimestamp) : -1;
  if (options_.rate_hz > 0.0) {
    char rate[32];
    std::snprintf(rate, sizeof rate, "%g", options_.rate_hz);
    CAIRN_RETURN_IF_ERROR(WriteText(d + "/sampling_frequency", rate));
  }
  CAIRN_RETURN_IF_ERROR(WriteText(d + "/buffer/length", std::to_string(options_.buffer_length)));
  CAIRN_RETURN_IF_ERROR(WriteText(d + "/buffer/enable", "1"));
  const std::string dev = options_.dev_root + "/" + std::filesystem::path(d).filename().string();
  fd_ = open(dev.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    const int e = errno;
    (void)WriteText(d + "/buffer/enable", "0");  // nobody will read it
    return UnavailableError(dev + ": " + std::strerror(e));
  }
  buffer_.assign(layout_.record_size() * 64, 0);
  buffered_ = 0;
  last_timestamp_ = 0;
  return Status::Ok();
}

void IioImuDriver::Close() {
  if (fd_ >= 0) {
    close(fd_);
    fd_ = -1;
    (void)WriteText(sysfs_dir_ + "/buffer/enable", "0");  // best effort: the device may be gone
  }
}

Status IioImuDriver::Start(SensorSink* sink) {
  if (thread_.joinable()) return FailedPreconditionError(name() + ": already started");
  sink_ = sink;
  thread_ = std::jthread([this](std::stop_token stop) { Run(stop); });
  return Status::Ok();
}

void IioImuDriver::Stop() {
  if (thread_.joinable()) {
    thread_.request_stop();
    thread_.join();
  }
  Close();  // the reader thread owned the device until now
}

void IioImuDriver::Fault(DeviceFaultKind kind, const std::string& detail) {
  if (sink_ != nullptr) sink_->OnDeviceFault(DeviceFault{clock_.Now(), name(), kind, detail});
}

void IioImuDriver::Run(std::stop_token stop) {
  Timestamp last_sample = clock_.Now();
  Timestamp last_open = last_sample - Duration::Seconds(options_.reopen_interval);
  bool ever_open = false, timed_out = false, reported = false;
  while (!stop.stop_requested()) {
    if (fd_ < 0) {
      const Timestamp now = clock_.Now();
      if (now - last_open < Duration::Seconds(options_.reopen_interval)) {
        usleep(kIioPollMs * 1000);
        continue;
      }
      last_open = now;
      if (Status s = Open(); !s.ok()) {
        Close();
        if (!reported)
          Fault(s.code() == StatusCode::kUnavailable ? DeviceFaultKind::kDisconnected : DeviceFaultKind::kOther,
                s.message() + " (retrying)");
        reported = true;
        continue;
      }
      if (ever_open) reconnections_.fetch_add(1, std::memory_order_relaxed);
      ever_open = true;
      reported = false;
      timed_out = false;
      last_sample = now;
    }
    pollfd p{fd_, POLLIN, 0};
    const int r = poll(&p, 1, kIioPollMs);
    const Timestamp now = clock_.Now();
    if (r > 0 && (p.revents & (POLLIN | POLLHUP | POLLERR)) != 0) {
      const ssize_t n = read(fd_, buffer_.data() + buffered_, buffer_.size() - buffered_);
      if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
      if (n <= 0) {
        Fault(DeviceFaultKind::kDisconnected, "iio:" + options_.name + " (" + sysfs_dir_ + ") vanished (" +
                                                  (n == 0 ? std::string("end of stream") : std::strerror(errno)) +
                                                  "); searching again");
        reported = true;
        Close();
        last_open = now;
        continue;
      }
      buffered_ += static_cast<size_t>(n);
      const size_t size = layout_.record_size();
      size_t at = 0;
      for (; buffered_ - at >= size; at += size) {
        const std::span<const uint8_t> record(buffer_.data() + at, size);
        ImuSample s;
        for (int i = 0; i < 3; ++i) {
          s.accel[i] = static_cast<double>(layout_.Value(record, accel_[i])) * accel_scale_[i];
          s.gyro[i] = static_cast<double>(layout_.Value(record, gyro_[i])) * gyro_scale_[i];
        }
        s.time = now;
        if (timestamp_ >= 0) {
          const int64_t t = layout_.Value(record, timestamp_);
          if (t <= last_timestamp_) {
            corrupt_.fetch_add(1, std::memory_order_relaxed);
            Fault(DeviceFaultKind::kCorruptSample, "timestamp " + std::to_string(t) + " ns not after the previous " +
                                                       std::to_string(last_timestamp_) + " ns; sample dropped");
            continue;
          }
          last_timestamp_ = t;
          s.time = Timestamp::FromNanoseconds(t);
        }
        samples_.fetch_add(1, std::memory_order_relaxed);
        sink_->OnImu(s);
        last_sample = now;
        timed_out = false;
      }
      // A partial record (the kernel hands out whole ones; a pipe may not) waits for the rest.
      std::memmove(buffer_.data(), buffer_.data() + at, buffered_ - at);
      buffered_ -= at;
      continue;
    }
    if (!timed_out && now - last_sample > Duration::Seconds(options_.timeout)) {
      timed_out = true;
      Fault(DeviceFaultKind::kTimeout, "no IMU sample for " + std::to_string(options_.timeout) + " s");
    }
  }
}

}  // namespace cairn
