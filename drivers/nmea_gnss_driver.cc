#include "drivers/nmea_gnss_driver.h"

#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "drivers/serial_port.h"

namespace cairn {
namespace {

constexpr int kNmeaPollMs = 50;  // how promptly Stop() is noticed

}  // namespace

Status NmeaGnssOptions::Validate() const {
  if (!SerialPort::IsStandardBaud(baud))
    return InvalidArgumentError("baud " + std::to_string(baud) + " is not a standard serial rate");
  if (device.empty()) return InvalidArgumentError("device must name the serial port");
  return Status::Ok();
}

NmeaGnssDriver::NmeaGnssDriver(NmeaGnssOptions options)
    : options_(std::move(options)), parser_(options_), read_buffer_(512) {}

NmeaGnssDriver::~NmeaGnssDriver() { Stop(); }  // Stop() closes the device

NmeaGnssCounts NmeaGnssDriver::counts() const {
  return {fixes_.load(), corrupt_.load(), no_fix_.load(), hdop_fallbacks_.load(), reconnections_.load()};
}

Status NmeaGnssDriver::Start(SensorSink* sink) {
  if (thread_.joinable()) return FailedPreconditionError(name() + ": already started");
  CAIRN_RETURN_IF_ERROR(options_.Validate());
  sink_ = sink;
  thread_ = std::jthread([this](std::stop_token stop) { Run(stop); });
  return Status::Ok();
}

void NmeaGnssDriver::Stop() {
  if (thread_.joinable()) {
    thread_.request_stop();
    thread_.join();
  }
  Close();  // the reader thread owned the device until now
}

void NmeaGnssDriver::Close() {
  if (fd_ >= 0) close(fd_);
  fd_ = -1;
}

void NmeaGnssDriver::Fault(DeviceFaultKind kind, const std::string& detail) {
  if (sink_ != nullptr) sink_->OnDeviceFault(DeviceFault{clock_.Now(), name(), kind, detail});
}

void NmeaGnssDriver::CorruptFault(const std::string& detail, Timestamp now) {
  if (!detail.empty()) last_refusal_ = detail;
  const uint64_t count = corrupt_faults_.Add(detail.empty() ? 0 : 1, now);
  if (count == 0) return;
  Fault(DeviceFaultKind::kCorruptSample,
        count > 1 ? std::to_string(count) +
                        " NMEA sentences refused since the last report, the latest: " + last_refusal_
                  : last_refusal_);
}

void NmeaGnssDriver::PublishCounts() {
  const NmeaParserCounts& c = parser_.counts();
  fixes_.store(c.fixes, std::memory_order_relaxed);
  corrupt_.store(c.corrupt, std::memory_order_relaxed);
  no_fix_.store(c.no_fix, std::memory_order_relaxed);
  hdop_fallbacks_.store(c.hdop_fallbacks, std::memory_order_relaxed);
}

void NmeaGnssDriver::Run(std::stop_token stop) {
  Timestamp last_fix = clock_.Now();
  Timestamp last_open = last_fix - Duration::Seconds(options_.reopen_interval);
  bool ever_open = false, timed_out = false, reported_closed = false;
  while (!stop.stop_requested()) {
    if (fd_ < 0) {
      const Timestamp now = clock_.Now();
      if (now - last_open < Duration::Seconds(options_.reopen_interval)) {
        usleep(kNmeaPollMs * 1000);
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
      parser_.Reset();  // a partial sentence or epoch of the old connection
      if (ever_open) reconnections_.fetch_add(1, std::memory_order_relaxed);
      ever_open = true;
      reported_closed = false;
      last_fix = clock_.Now();
      timed_out = false;
    }
    pollfd p{fd_, POLLIN, 0};
    const int r = poll(&p, 1, kNmeaPollMs);
    const Timestamp now = clock_.Now();
    bool gone = false;
    std::string why;
    if (r > 0 && (p.revents & POLLIN) != 0) {
      const ssize_t n = read(fd_, read_buffer_.data(), read_buffer_.size());
      if (n > 0) {
        parser_.Feed(
            std::span<const uint8_t>(read_buffer_.data(), static_cast<size_t>(n)), now,
            [&](const GnssFix& fix) {
              last_fix = now;
              timed_out = false;
              PublishCounts();  // before the sink sees the fix, so that counts() never lags it
              sink_->OnGnss(fix);
            },
            [&](const Status& refused) { CorruptFault(refused.message(), now); });
        PublishCounts();
      } else if (n == 0 || (errno != EAGAIN && errno != EINTR)) {
        gone = true;
        why = n == 0 ? "end of stream" : std::strerror(errno);
      }
    } else if (r > 0 && (p.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0) {
      gone = true;
      why = "hang-up";
    }
    CorruptFault("", now);
    if (gone) {
      Fault(DeviceFaultKind::kDisconnected, options_.device + " vanished (" + why + "); reopening");
      reported_closed = true;
      Close();
      last_open = now;
      continue;
    }
    if (!timed_out && now - last_fix > Duration::Seconds(options_.timeout)) {
      timed_out = true;
      char what[96];
      std::snprintf(what, sizeof what, "no GNSS fix for %.2f s (%llu sentences without a position so far)",
                    options_.timeout, static_cast<unsigned long long>(parser_.counts().no_fix));
      Fault(DeviceFaultKind::kTimeout, what);
    }
  }
}

}  // namespace cairn
