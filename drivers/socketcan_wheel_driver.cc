#include "drivers/socketcan_wheel_driver.h"

#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

namespace cairn {

SocketCanWheelDriver::SocketCanWheelDriver(CanWheelOptions options)
    : options_(std::move(options)), decoder_(options_), owns_interface_(true) {}

SocketCanWheelDriver::SocketCanWheelDriver(CanWheelOptions options, int fd)
    : options_(std::move(options)), decoder_(options_), fd_(fd), owns_interface_(false) {}

SocketCanWheelDriver::~SocketCanWheelDriver() {
  Stop();
  if (fd_ >= 0) close(fd_);
}

Expected<int> SocketCanWheelDriver::OpenSocket(const CanWheelOptions& options) {
  if (options.interface.size() >= IFNAMSIZ) {
    return InvalidArgumentError("CAN interface name '" + options.interface + "' is too long");
  }
  const int fd = socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    return UnavailableError("CAN interface '" + options.interface + "': socket(PF_CAN): " + std::strerror(errno));
  }
  ifreq ifr{};
  std::strncpy(ifr.ifr_name, options.interface.c_str(), IFNAMSIZ - 1);
  if (ioctl(fd, SIOCGIFINDEX, &ifr) < 0) {
    const int e = errno;
    close(fd);
    return UnavailableError("CAN interface '" + options.interface + "': " + std::strerror(e));
  }
  // Only the frames we decode reach user space.
  std::vector<can_filter> filters;
  for (const WheelCanOptions* w : {&options.front_left, &options.front_right, &options.rear_left,
                                   &options.rear_right}) {
    for (const CanSignalOptions* s : {&w->speed, &w->steering}) {
      if (s == &w->steering && !w->steered) continue;
      const canid_t flag = s->extended_id ? CAN_EFF_FLAG : 0;
      filters.push_back({static_cast<canid_t>(s->id) | flag,
                         (s->extended_id ? CAN_EFF_MASK : CAN_SFF_MASK) | CAN_EFF_FLAG});
    }
  }
  if (options.sync_id >= 0) {
    filters.push_back({static_cast<canid_t>(options.sync_id), CAN_EFF_MASK});
  }
  if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(),
                 static_cast<socklen_t>(filters.size() * sizeof(can_filter))) < 0) {
    const int e = errno;
    close(fd);
    return UnavailableError("CAN_RAW_FILTER on '" + options.interface + "': " + std::strerror(e));
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) < 0) {
    const int e = errno;
    close(fd);
    return UnavailableError("bind to CAN interface '" + options.interface + "': " + std::strerror(e));
  }
  return fd;
}

Status SocketCanWheelDriver::Start(SensorSink* sink) {
  if (thread_.joinable()) return FailedPreconditionError(name() + ": already started");
  sink_ = sink;
  if (owns_interface_ && fd_ < 0) {
    auto fd = OpenSocket(options_);
    if (!fd.ok()) {
      // Degrade: keep trying in the reader thread, the rest of the daemon runs meanwhile.
      Fault(DeviceFaultKind::kDisconnected, fd.status().message() + " (retrying every second)");
    } else {
      fd_ = *fd;
    }
  }
  thread_ = std::jthread([this](std::stop_token stop) { Run(stop); });
  return Status::Ok();
}

void SocketCanWheelDriver::Stop() {
  if (thread_.joinable()) {
    thread_.request_stop();
    thread_.join();
  }
}

void SocketCanWheelDriver::Fault(DeviceFaultKind kind, const std::string& detail) {
  if (sink_ != nullptr) sink_->OnDeviceFault(DeviceFault{clock_.Now(), name(), kind, detail});
}

void SocketCanWheelDriver::Run(std::stop_token stop) {
  constexpr int kPollMs = 50;
  Timestamp last_frame = clock_.Now();
  Timestamp last_reopen = last_frame;
  bool timed_out = false;
  while (!stop.stop_requested()) {
    if (fd_ < 0) {
      if (!owns_interface_) return;  // a handed-in descriptor that closed is gone for good
      const Timestamp now = clock_.Now();
      if (now - last_reopen >= Duration::Seconds(1.0)) {
        last_reopen = now;
        if (auto fd = OpenSocket(options_); fd.ok()) {
          fd_ = *fd;
          last_frame = now;
        }
      }
      usleep(kPollMs * 1000);
      continue;
    }
    pollfd p{fd_, POLLIN, 0};
    const int r = poll(&p, 1, kPollMs);
    const Timestamp now = clock_.Now();
    if (r == 0 || (r < 0 && errno == EINTR)) {
      if (!timed_out && now - last_frame > Duration::Seconds(options_.timeout)) {
        timed_out = true;
        Fault(DeviceFaultKind::kTimeout, "no CAN frames for " + std::to_string(options_.timeout) + " s");
      }
      continue;
    }
    can_frame frame{};
    const ssize_t n = (p.revents & POLLIN) ? read(fd_, &frame, sizeof(frame)) : -1;
    if (n == static_cast<ssize_t>(sizeof(frame))) {
      last_frame = now;
      timed_out = false;
      frames_.fetch_add(1, std::memory_order_relaxed);
      WheelOdometrySample sample;
      switch (decoder_.Feed(frame, now, &sample)) {
        case CanWheelDecoder::Result::kSampleReady: sink_->OnWheelOdometry(sample); break;
        case CanWheelDecoder::Result::kMalformed:
          Fault(DeviceFaultKind::kCorruptSample,
                "frame id " + std::to_string(frame.can_id & CAN_EFF_MASK) +
                    " is too short for its configured signals");
          break;
        case CanWheelDecoder::Result::kErrorFrame:
          Fault(DeviceFaultKind::kOverrun, "CAN error frame (bus error or controller problem)");
          break;
        default: break;
      }
      continue;
    }
    if (n > 0) {
      Fault(DeviceFaultKind::kCorruptSample, "short CAN record of " + std::to_string(n) + " bytes");
      continue;
    }
    // n == 0 (peer closed) or a hard error (ENETDOWN, ENODEV): the device is gone.
    const std::string why = n == 0 ? "end of stream" : std::strerror(errno);
    Fault(DeviceFaultKind::kDisconnected, "CAN read failed: " + why);
    close(fd_);
    fd_ = -1;
    last_reopen = now;
  }
}

}  // namespace cairn
