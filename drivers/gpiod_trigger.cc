#include "drivers/gpiod_trigger.h"

#include <fcntl.h>
#include <gpiod.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/stat.h>
#include <sys/timerfd.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace cairn {
namespace {

// The kernel queues at most 16 edges per line (v1 interface), and libgpiod 1.6 reads at most as
// many at once.
constexpr unsigned kGpiodEdgeBatch = 16;
// How often an idle thread checks that the chip is still there and the line not silent.
constexpr int kGpiodWatchMs = 100;
constexpr const char* kGpiodConsumer = "cairnd";

bool IsOffset(const std::string& s) {
  return !s.empty() && s.size() < 10 && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// Every chip with its label, for messages about one that is not found.
std::string GpioChipList() {
  std::string list;
  if (gpiod_chip_iter* it = gpiod_chip_iter_new()) {
    gpiod_chip* c = nullptr;
    gpiod_foreach_chip(it, c) {
      list += (list.empty() ? "" : ", ") + std::string(gpiod_chip_name(c)) + " [" + gpiod_chip_label(c) + "]";
    }
    gpiod_chip_iter_free(it);
  }
  return list.empty() ? "no GPIO chip on this machine" : "there: " + list;
}

Expected<gpiod_line*> FindGpioLine(gpiod_chip* chip, const std::string& line) {
  const std::string where = std::string(gpiod_chip_name(chip)) + " [" + gpiod_chip_label(chip) + "]";
  if (IsOffset(line)) {
    const unsigned long offset = std::stoul(line);
    if (offset >= gpiod_chip_num_lines(chip))
      return NotFoundError(where + " has " + std::to_string(gpiod_chip_num_lines(chip)) + " lines, no offset " + line);
    gpiod_line* l = gpiod_chip_get_line(chip, static_cast<unsigned>(offset));
    if (l == nullptr) return UnavailableError(where + ": line " + line + ": " + std::strerror(errno));
    return l;
  }
  gpiod_line* l = gpiod_chip_find_line(chip, line.c_str());
  if (l == nullptr) return NotFoundError("no line named '" + line + "' on " + where);
  return l;
}

// Seconds and rates as a person writes them ("0.5", not "0.500000").
std::string GpiodNumber(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

int GpioBiasFlags(GpioBias bias) {
  switch (bias) {
    case GpioBias::kAsIs: return 0;
    case GpioBias::kPullUp: return GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_UP;
    case GpioBias::kPullDown: return GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_DOWN;
    case GpioBias::kDisabled: return GPIOD_LINE_REQUEST_FLAG_BIAS_DISABLE;
  }
  return 0;
}

Status RequestGpioLine(gpiod_line* line, int type, int flags, const std::string& what) {
  const gpiod_line_request_config config{kGpiodConsumer, type, flags};
  if (gpiod_line_request(line, &config, 0) == 0) return Status::Ok();
  const int e = errno;
  const char* holder = gpiod_line_consumer(line);
  if (e == EBUSY) {
    return FailedPreconditionError(what + " is held by " + (holder != nullptr ? "'" + std::string(holder) + "'" : "another program"));
  }
  return UnavailableError(what + ": cannot be requested (" + std::strerror(e) + ")");
}

}  // namespace

Status GpiodTriggerOptions::Validate() const {
  if (line.empty()) return InvalidArgumentError("line must name the input (an offset or a line name)");
  if (!output_line.empty() && output_line == line) {
    return InvalidArgumentError("output_line and line are both '" + line + "': one line cannot be input and output");
  }
  if (!output_line.empty() && rate_hz > 0.0 && pulse_width >= 1.0 / rate_hz) {
    return InvalidArgumentError("pulse_width " + GpiodNumber(pulse_width) + " s does not fit in a period at " +
                                GpiodNumber(rate_hz) + " Hz");
  }
  return Status::Ok();
}

GpiodTrigger::GpiodTrigger(GpiodTriggerOptions options)
    : options_(std::move(options)),
      wake_fd_(eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)),
      rate_hz_(options_.rate_hz),
      events_(new gpiod_line_event[kGpiodEdgeBatch]) {
  sequencer_.SetRate(options_.rate_hz);
}

GpiodTrigger::~GpiodTrigger() {
  Stop();
  if (wake_fd_ >= 0) close(wake_fd_);
}

std::string GpiodTrigger::name() const {
  return "gpiod:" + (options_.chip.empty() ? std::string() : options_.chip + "/") + options_.line;
}

GpiodTriggerCounts GpiodTrigger::counts() const {
  return {edges_.load(), missed_.load(), corrupt_.load(), pulses_.load(), skipped_pulses_.load(),
          timeouts_.load(), reconnections_.load(), open_attempts_.load()};
}

Status GpiodTrigger::Start(SensorSink* sink) {
  if (thread_.joinable()) return FailedPreconditionError(name() + ": already started");
  CAIRN_RETURN_IF_ERROR(options_.Validate().WithContext(name()));
  if (wake_fd_ < 0) return InternalError(name() + ": no eventfd to stop the thread with");
  sink_ = sink;
  thread_ = std::jthread([this](std::stop_token stop) { Run(stop); });
  return Status::Ok();
}

void GpiodTrigger::Stop() {
  if (thread_.joinable()) {
    thread_.request_stop();
    const uint64_t one = 1;
    (void)!write(wake_fd_, &one, sizeof one);
    thread_.join();
  }
  Close();  // the thread owned the chip until now
}

Status GpiodTrigger::SetRate(double hz) {
  if (!std::isfinite(hz) || hz < 0.0 || hz > 1000.0) {
    return InvalidArgumentError(name() + ": rate " + GpiodNumber(hz) + " Hz is outside [0, 1000]");
  }
  if (!options_.output_line.empty() && hz > 0.0 && options_.pulse_width >= 1.0 / hz) {
    return InvalidArgumentError(name() + ": at " + GpiodNumber(hz) + " Hz a period is shorter than pulse_width");
  }
  rate_hz_.store(hz);
  const uint64_t one = 1;
  (void)!write(wake_fd_, &one, sizeof one);
  return Status::Ok();
}

void GpiodTrigger::Fault(DeviceFaultKind kind, const std::string& detail) {
  if (sink_ != nullptr) sink_->OnDeviceFault(DeviceFault{clock_.Now(), name(), kind, detail});
}

Status GpiodTrigger::Open() {
  open_attempts_.fetch_add(1, std::memory_order_relaxed);
  if (options_.chip.empty()) {
    input_ = gpiod_line_find(options_.line.c_str());
    if (input_ == nullptr) {
      return UnavailableError("no GPIO line named '" + options_.line + "' on any chip (" + GpioChipList() + ")");
    }
    chip_ = gpiod_line_get_chip(input_);
  } else {
    chip_ = gpiod_chip_open_lookup(options_.chip.c_str());
    if (chip_ == nullptr) {
      const int e = errno;
      return UnavailableError("GPIO chip '" + options_.chip + "' not found (" + std::strerror(e) + "; " +
                              GpioChipList() + ")");
    }
    auto line = FindGpioLine(chip_, options_.line);
    if (!line.ok()) return line.status();
    input_ = *line;
  }
  chip_node_ = std::string("/dev/") + gpiod_chip_name(chip_);
  struct stat st {};
  chip_device_ = stat(chip_node_.c_str(), &st) == 0 ? st.st_rdev : 0;
  CAIRN_RETURN_IF_ERROR(RequestGpioLine(
      input_,
      options_.edge == GpioEdge::kRising ? GPIOD_LINE_REQUEST_EVENT_RISING_EDGE : GPIOD_LINE_REQUEST_EVENT_FALLING_EDGE,
      GpioBiasFlags(options_.bias), "input line " + options_.line + " of " + chip_node_));
  event_fd_ = gpiod_line_event_get_fd(input_);
  if (event_fd_ < 0 || fcntl(event_fd_, F_SETFL, fcntl(event_fd_, F_GETFL) | O_NONBLOCK) != 0) {
    return UnavailableError(chip_node_ + ": no event descriptor for line " + options_.line);
  }
  if (!options_.output_line.empty()) {
    auto line = FindGpioLine(chip_, options_.output_line);
    if (!line.ok()) return line.status();
    output_ = *line;
    CAIRN_RETURN_IF_ERROR(RequestGpioLine(output_, GPIOD_LINE_REQUEST_DIRECTION_OUTPUT, 0,
                                          "output line " + options_.output_line + " of " + chip_node_));
    timer_fd_ = timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
    if (timer_fd_ < 0) return InternalError(std::string("timerfd: ") + std::strerror(errno));
  }
  armed_rate_hz_ = -1.0;
  pulse_high_ = false;
  realtime_noted_ = false;
  return Status::Ok();
}

void GpiodTrigger::Close() {
  if (output_ != nullptr && gpiod_line_is_requested(output_)) (void)gpiod_line_set_value(output_, 0);  // best effort
  if (timer_fd_ >= 0) close(timer_fd_);
  if (chip_ != nullptr) gpiod_chip_close(chip_);  // releases the lines and their descriptors
  timer_fd_ = event_fd_ = -1;
  chip_ = nullptr;
  input_ = output_ = nullptr;
}

void GpiodTrigger::DrainWake() {
  uint64_t count = 0;
  (void)!read(wake_fd_, &count, sizeof count);
}

void GpiodTrigger::Sleep(Duration wait) {
  pollfd p{wake_fd_, POLLIN, 0};
  const int64_t ms = std::clamp<int64_t>((wait.nanoseconds() + 999'999) / 1'000'000, 1, 1000);
  if (poll(&p, 1, static_cast<int>(ms)) > 0) DrainWake();
}

void GpiodTrigger::Run(std::stop_token stop) {
  last_open_ = clock_.Now() - Duration::Seconds(options_.reopen_interval);
  bool ever_open = false;
  while (!stop.stop_requested()) {
    if (chip_ != nullptr) {
      Serve();
      continue;
    }
    const Timestamp now = clock_.Now();
    const Duration wait = Duration::Seconds(options_.reopen_interval) - (now - last_open_);
    if (wait > Duration()) {
      Sleep(wait);
      continue;
    }
    last_open_ = now;
    if (Status s = Open(); !s.ok()) {
      Close();
      if (!reported_) {
        Fault(s.code() == StatusCode::kUnavailable ? DeviceFaultKind::kDisconnected : DeviceFaultKind::kOther,
              s.message() + " (retrying every " + GpiodNumber(options_.reopen_interval) + " s)");
      }
      reported_ = true;
      continue;
    }
    if (ever_open) reconnections_.fetch_add(1, std::memory_order_relaxed);
    ever_open = true;
    reported_ = false;
    timed_out_ = false;
    last_edge_ = last_watch_ = now;
    sequencer_.Restart();
    ApplyRate(now);
  }
}

void GpiodTrigger::Serve() {
  pollfd p[3] = {{wake_fd_, POLLIN, 0}, {event_fd_, POLLIN, 0}, {timer_fd_, POLLIN, 0}};
  const nfds_t n = timer_fd_ >= 0 ? 3 : 2;
  if (poll(p, n, kGpiodWatchMs) < 0) return;  // EINTR
  const Timestamp now = clock_.Now();
  if ((p[0].revents & POLLIN) != 0) {
    DrainWake();
    ApplyRate(now);
  }
  // Each step may find the chip gone and close it.
  if (chip_ != nullptr && (p[1].revents & POLLIN) != 0) {
    ReadEdges();
  } else if (chip_ != nullptr && (p[1].revents & (POLLERR | POLLHUP | POLLNVAL)) != 0) {
    Lost("the line's event descriptor hung up", now);
  }
  if (chip_ != nullptr && n == 3 && (p[2].revents & POLLIN) != 0) Pulse(now);
  if (chip_ != nullptr && now - last_watch_ >= Duration::Milliseconds(kGpiodWatchMs)) Watch(now);
}

void GpiodTrigger::ApplyRate(Timestamp now) {
  const double hz = rate_hz_.load();
  sequencer_.SetRate(hz);
  if (output_ == nullptr || hz == armed_rate_hz_) return;
  armed_rate_hz_ = hz;
  pulse_high_ = false;
  if (gpiod_line_set_value(output_, 0) != 0) {
    Lost(std::string("cannot drive the output line (") + std::strerror(errno) + ")", now);
    return;
  }
  next_rise_ = now + Duration::Microseconds(100);
  ArmTimer(hz > 0.0 ? next_rise_ : Timestamp());  // a zero time disarms
}

void GpiodTrigger::ArmTimer(Timestamp at) {
  itimerspec spec{};
  spec.it_value.tv_sec = static_cast<time_t>(at.nanoseconds() / 1'000'000'000);
  spec.it_value.tv_nsec = static_cast<long>(at.nanoseconds() % 1'000'000'000);
  timerfd_settime(timer_fd_, TFD_TIMER_ABSTIME, &spec, nullptr);
}

void GpiodTrigger::Pulse(Timestamp now) {
  uint64_t expirations = 0;
  if (read(timer_fd_, &expirations, sizeof expirations) <= 0 || armed_rate_hz_ <= 0.0) return;
  const Duration period = Duration::Seconds(1.0 / armed_rate_hz_);
  if (gpiod_line_set_value(output_, pulse_high_ ? 0 : 1) != 0) {
    Lost(std::string("cannot drive the output line (") + std::strerror(errno) + ")", now);
    return;
  }
  pulse_high_ = !pulse_high_;
  if (pulse_high_) {
    pulses_.fetch_add(1, std::memory_order_relaxed);
    ArmTimer(now + Duration::Seconds(options_.pulse_width));
    return;
  }
  next_rise_ += period;
  if (next_rise_ <= now) {  // woke too late: skip to the next period still ahead
    const int64_t behind = (now - next_rise_).nanoseconds() / period.nanoseconds() + 1;
    next_rise_ += period * behind;
    skipped_pulses_.fetch_add(static_cast<uint64_t>(behind), std::memory_order_relaxed);
  }
  ArmTimer(next_rise_);
}

void GpiodTrigger::ReadEdges() {
  const int n = gpiod_line_event_read_fd_multiple(event_fd_, events_.get(), kGpiodEdgeBatch);
  const Timestamp now = clock_.Now();
  if (n < 0) {
    if (errno == EAGAIN || errno == EINTR) return;
    Lost(std::string("reading edges failed (") + std::strerror(errno) + ")", now);
    return;
  }
  timespec realtime{};
  clock_gettime(CLOCK_REALTIME, &realtime);
  const int64_t realtime_ns = realtime.tv_sec * int64_t{1'000'000'000} + realtime.tv_nsec;
  uint64_t missed = 0, corrupt = 0;
  for (int i = 0; i < n; ++i) {
    const timespec& ts = events_[static_cast<size_t>(i)].ts;
    const TriggerEdge edge = sequencer_.Add(ts.tv_sec * int64_t{1'000'000'000} + ts.tv_nsec, now, realtime_ns);
    if (edge.clock == TriggerEdgeClock::kRealtime && !realtime_noted_) {
      realtime_noted_ = true;
      Fault(DeviceFaultKind::kOther, "the kernel stamps edges with CLOCK_REALTIME (Linux before 5.7): converted "
                                     "to the monotonic clock, exact only while the wall clock is not stepped");
    }
    if (edge.clock == TriggerEdgeClock::kArrival || !edge.valid) ++corrupt;
    if (!edge.valid) continue;
    missed += edge.missed;
    edges_.fetch_add(1, std::memory_order_relaxed);
    sink_->OnTrigger(edge.event);
  }
  missed_.fetch_add(missed, std::memory_order_relaxed);
  corrupt_.fetch_add(corrupt, std::memory_order_relaxed);
  if (n > 0) {
    last_edge_ = now;
    timed_out_ = false;
  }
  if (const uint64_t k = missed_throttle_.Add(missed, now); k > 0) {
    Fault(DeviceFaultKind::kOverrun, std::to_string(k) + " edges lost by the time gaps at " +
                                         GpiodNumber(rate_hz_.load()) + " Hz since the last report");
  }
  if (const uint64_t k = corrupt_throttle_.Add(corrupt, now); k > 0) {
    Fault(DeviceFaultKind::kCorruptSample,
          std::to_string(k) + " edges with a stamp on neither clock or not after the previous edge");
  }
}

void GpiodTrigger::Watch(Timestamp now) {
  last_watch_ = now;
  struct stat st {};
  if (stat(chip_node_.c_str(), &st) != 0 || st.st_rdev != chip_device_) {
    Lost(chip_node_ + " is gone", now);
    return;
  }
  if (!timed_out_ && now - last_edge_ > Duration::Seconds(options_.timeout)) {
    timed_out_ = true;
    timeouts_.fetch_add(1, std::memory_order_relaxed);
    Fault(DeviceFaultKind::kTimeout, "no edge on line " + options_.line + " for " + GpiodNumber(options_.timeout) + " s");
  }
  // Losses of the last second are reported even when no edge follows them.
  if (const uint64_t k = missed_throttle_.Add(0, now); k > 0) {
    Fault(DeviceFaultKind::kOverrun, std::to_string(k) + " edges lost by the time gaps since the last report");
  }
}

void GpiodTrigger::Lost(const std::string& why, Timestamp now) {
  Fault(DeviceFaultKind::kDisconnected,
        name() + ": " + why + "; looking for the chip every " + GpiodNumber(options_.reopen_interval) + " s");
  Close();
  reported_ = true;
  last_open_ = now;
}

}  // namespace cairn
