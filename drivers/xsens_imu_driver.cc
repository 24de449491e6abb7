#include "drivers/xsens_imu_driver.h"

#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "drivers/serial_port.h"

namespace cairn {
namespace {

constexpr uint8_t kGoToConfig = 0x30;
constexpr uint8_t kGoToMeasurement = 0x10;
constexpr uint8_t kSetOutputConfiguration = 0xC0;
constexpr uint8_t kError = 0x42;
constexpr int kPollMs = 50;
constexpr uint16_t kEveryPacket = 0xFFFF;  // output frequency of counters and status: with every packet

void PutBigEndian16(std::vector<uint8_t>* out, uint16_t v) {
  out->push_back(static_cast<uint8_t>(v >> 8));
  out->push_back(static_cast<uint8_t>(v & 0xFF));
}

}  // namespace

Status XsensImuOptions::Validate() const {
  if (!SerialPort::IsStandardBaud(baud))
    return InvalidArgumentError("baud " + std::to_string(baud) + " is not a standard serial rate");
  if (device.empty()) return InvalidArgumentError("device must name the serial port");
  return Status::Ok();
}

XsensImuDriver::XsensImuDriver(XsensImuOptions options, ImuCalibration calibration)
    : options_(std::move(options)), calibration_(calibration), read_buffer_(512) {
  calibration_.rate_hz = options_.rate_hz;
}

XsensImuDriver::~XsensImuDriver() { Stop(); }  // Stop() closes the device

XsensImuCounts XsensImuDriver::counts() const {
  return {samples_.load(), corrupt_.load(), lost_.load(), reconnections_.load(), configurations_.load()};
}

Status XsensImuDriver::Start(SensorSink* sink) {
  if (thread_.joinable()) return FailedPreconditionError(name() + ": already started");
  CAIRN_RETURN_IF_ERROR(options_.Validate());
  sink_ = sink;
  thread_ = std::jthread([this](std::stop_token stop) { Run(stop); });
  return Status::Ok();
}

void XsensImuDriver::Stop() {
  if (thread_.joinable()) {
    thread_.request_stop();
    thread_.join();
  }
  Close();  // the reader thread owned the device until now
}

void XsensImuDriver::Close() {
  if (fd_ >= 0) close(fd_);
  fd_ = -1;
}

void XsensImuDriver::Fault(DeviceFaultKind kind, const std::string& detail) {
  if (sink_ != nullptr) sink_->OnDeviceFault(DeviceFault{clock_.Now(), name(), kind, detail});
}

void XsensImuDriver::FormatFault(const std::string& detail, Timestamp now) {
  const uint64_t count = format_faults_.Add(1, now);
  if (count == 0) return;
  Fault(DeviceFaultKind::kCorruptSample,
        count > 1 ? detail + " (" + std::to_string(count) + " messages since the last report)" : detail);
}

Status XsensImuDriver::Command(std::stop_token stop, uint8_t mid, std::span<const uint8_t> payload) {
  const std::vector<uint8_t> bytes = XbusFramer::Encode(mid, payload);
  size_t written = 0;
  const Timestamp deadline = clock_.Now() + Duration::Seconds(options_.command_timeout);
  while (written < bytes.size()) {
    const ssize_t n = write(fd_, bytes.data() + written, bytes.size() - written);
    if (n > 0) {
      written += static_cast<size_t>(n);
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EINTR) return UnavailableError(std::string("write: ") + std::strerror(errno));
    if (clock_.Now() > deadline) return TimeoutError("the port did not take the message in time");
    pollfd p{fd_, POLLOUT, 0};
    poll(&p, 1, kPollMs);
  }
  awaited_ack_ = mid + 1;
  acked_ = false;
  device_error_.clear();
  while (!acked_ && device_error_.empty() && !stop.stop_requested()) {
    if (clock_.Now() > deadline) {
      awaited_ack_ = -1;
      char what[64];
      std::snprintf(what, sizeof what, "no acknowledgement of message 0x%02X within %.2f s", mid, options_.command_timeout);
      return TimeoutError(what);
    }
    pollfd p{fd_, POLLIN, 0};
    if (poll(&p, 1, kPollMs) <= 0) continue;
    if ((p.revents & (POLLHUP | POLLERR)) != 0 && (p.revents & POLLIN) == 0) return UnavailableError("the port hung up");
    const ssize_t n = read(fd_, read_buffer_.data(), read_buffer_.size());
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
    if (n <= 0) return UnavailableError(n == 0 ? "end of stream" : std::string("read: ") + std::strerror(errno));
    const Timestamp arrival = clock_.Now();
    framer_.Feed(std::span<const uint8_t>(read_buffer_.data(), static_cast<size_t>(n)),
                 [&](const XbusMessage& m) { OnMessage(m, arrival); });
  }
  awaited_ack_ = -1;
  if (!device_error_.empty()) return FailedPreconditionError(device_error_);
  if (!acked_) return Status(StatusCode::kCancelled, "stopped while configuring");
  return Status::Ok();
}

Status XsensImuDriver::Configure(std::stop_token stop) {
  CAIRN_RETURN_IF_ERROR(Command(stop, kGoToConfig, {}).WithContext("go to configuration"));
  const uint16_t rate = static_cast<uint16_t>(std::lround(options_.rate_hz));
  std::vector<uint8_t> output;
  for (const auto& [xdi, hz] : {std::pair<uint16_t, uint16_t>{Mtdata2Decoder::kPacketCounter, kEveryPacket},
                                {Mtdata2Decoder::kSampleTimeFine, kEveryPacket},
                                {Mtdata2Decoder::kAcceleration, rate},
                                {Mtdata2Decoder::kRateOfTurn, rate},
                                {Mtdata2Decoder::kStatusWord, kEveryPacket}}) {
    PutBigEndian16(&output, xdi);
    PutBigEndian16(&output, hz);
  }
  CAIRN_RETURN_IF_ERROR(Command(stop, kSetOutputConfiguration, output).WithContext("set output configuration"));
  CAIRN_RETURN_IF_ERROR(Command(stop, kGoToMeasurement, {}).WithContext("go to measurement"));
  configurations_.fetch_add(1, std::memory_order_relaxed);
  return Status::Ok();
}

void XsensImuDriver::OnMessage(const XbusMessage& m, Timestamp arrival) {
  if (awaited_ack_ >= 0 && m.mid == awaited_ack_) {
    acked_ = true;
    return;
  }
  if (m.mid == kError) {
    const std::string what = "the device reports error " + std::to_string(m.payload.empty() ? -1 : m.payload[0]);
    if (awaited_ack_ >= 0) {
      device_error_ = what;
    } else {
      Fault(DeviceFaultKind::kOther, what);
    }
    return;
  }
  if (m.mid != Mtdata2Decoder::kMid) return;  // acknowledgements of nothing we sent, wake-ups
  auto s = Mtdata2Decoder::Decode(m.payload);
  if (!s.ok()) {
    corrupt_.fetch_add(1, std::memory_order_relaxed);
    // A format this driver does not read comes with every message: say so once a second.
    if (s.status().code() == StatusCode::kFailedPrecondition) {
      FormatFault(s.status().message() + " (set configure: true)", arrival);
    } else {
      Fault(DeviceFaultKind::kCorruptSample, s.status().message());
    }
    return;
  }
  if (s->has_counter) {
    if (have_counter_) {
      const uint16_t missing = static_cast<uint16_t>(s->counter - last_counter_ - 1);
      if (missing != 0 && missing < 0x8000) {
        lost_.fetch_add(missing, std::memory_order_relaxed);
        Fault(DeviceFaultKind::kOverrun, std::to_string(missing) + " samples lost (packet counter " +
                                             std::to_string(last_counter_) + " -> " + std::to_string(s->counter) + ")");
      }
    }
    have_counter_ = true;
    last_counter_ = s->counter;
  }
  if (!s->has_acceleration || !s->has_rate_of_turn) {
    corrupt_.fetch_add(1, std::memory_order_relaxed);
    FormatFault("MTData2 without acceleration and rate of turn (check the device's output configuration, or set "
                "configure: true)",
                arrival);
    return;
  }
  ImuSample sample;
  sample.accel = s->acceleration;
  sample.gyro = s->rate_of_turn;
  sample.time = arrival;
  if (s->has_sample_time) {
    if (have_ticks_) {
      ticks_ += static_cast<uint32_t>(s->sample_time_fine - last_ticks_);  // modulo 2^32: wraps after 5 days
    } else {
      ticks_ = s->sample_time_fine;
    }
    have_ticks_ = true;
    last_ticks_ = s->sample_time_fine;
    constexpr int64_t kNanosecondsPerTick = 100'000;  // 10 kHz
    sample.time = time_map_.Map(ticks_ * kNanosecondsPerTick, arrival);
  }
  samples_.fetch_add(1, std::memory_order_relaxed);
  sink_->OnImu(sample);
}

void XsensImuDriver::Run(std::stop_token stop) {
  Timestamp last_sample = clock_.Now();
  Timestamp last_open = last_sample - Duration::Seconds(options_.reopen_interval);
  bool ever_open = false, timed_out = false, reported_closed = false;
  uint64_t bad_before = 0;
  while (!stop.stop_requested()) {
    if (fd_ < 0) {
      const Timestamp now = clock_.Now();
      if (now - last_open < Duration::Seconds(options_.reopen_interval)) {
        usleep(kPollMs * 1000);
        continue;
      }
      last_open = now;
      auto fd = SerialPort::Open(options_.device, options_.baud);
      if (!fd.ok()) {
        if (!reported_closed) Fault(DeviceFaultKind::kDisconnected, fd.status().message() + " (retrying)");
        reported_closed = true;
        continue;
      }
      fd_ = *fd;
      framer_.Reset();
      have_counter_ = have_ticks_ = false;
      if (ever_open) reconnections_.fetch_add(1, std::memory_order_relaxed);
      ever_open = true;
      if (options_.configure) {
        if (Status s = Configure(stop); !s.ok()) {
          if (stop.stop_requested()) break;
          Fault(DeviceFaultKind::kOther, "configuring " + options_.device + ": " + s.message() + " (retrying)");
          Close();
          continue;
        }
      }
      reported_closed = false;
      last_sample = clock_.Now();
      timed_out = false;
      bad_before = framer_.counts().checksum_errors + framer_.counts().length_errors;
    }
    pollfd p{fd_, POLLIN, 0};
    const int r = poll(&p, 1, kPollMs);
    const Timestamp now = clock_.Now();
    bool gone = false;
    std::string why;
    if (r > 0 && (p.revents & POLLIN) != 0) {
      const ssize_t n = read(fd_, read_buffer_.data(), read_buffer_.size());
      if (n > 0) {
        const uint64_t samples_before = samples_.load(std::memory_order_relaxed);
        framer_.Feed(std::span<const uint8_t>(read_buffer_.data(), static_cast<size_t>(n)),
                     [&](const XbusMessage& m) { OnMessage(m, now); });
        const uint64_t bad = framer_.counts().checksum_errors + framer_.counts().length_errors;
        if (bad != bad_before) {
          corrupt_.fetch_add(bad - bad_before, std::memory_order_relaxed);
          Fault(DeviceFaultKind::kCorruptSample,
                std::to_string(bad - bad_before) + " corrupt Xbus messages skipped (checksum or length)");
          bad_before = bad;
        }
        if (samples_.load(std::memory_order_relaxed) != samples_before) {
          last_sample = now;
          timed_out = false;
        }
      } else if (n == 0 || (errno != EAGAIN && errno != EINTR)) {
        gone = true;
        why = n == 0 ? "end of stream" : std::strerror(errno);
      }
    } else if (r > 0 && (p.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0) {
      gone = true;
      why = "hang-up";
    }
    if (gone) {
      Fault(DeviceFaultKind::kDisconnected, options_.device + " vanished (" + why + "); reopening");
      reported_closed = true;
      Close();
      last_open = now;
      continue;
    }
    if (!timed_out && now - last_sample > Duration::Seconds(options_.timeout)) {
      timed_out = true;
      Fault(DeviceFaultKind::kTimeout, "no IMU sample for " + std::to_string(options_.timeout) + " s");
    }
  }
}

}  // namespace cairn
