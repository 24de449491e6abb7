#include "drivers/testing/emulated_mti.h"

#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>

#include "drivers/xbus_framer.h"

namespace cairn::testing {
namespace {

void PutFloat(std::vector<uint8_t>* out, float v) {
  uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  for (int s = 24; s >= 0; s -= 8) out->push_back(static_cast<uint8_t>(bits >> s));
}

void PutPacket(std::vector<uint8_t>* out, uint16_t xdi, std::span<const uint8_t> data) {
  out->push_back(static_cast<uint8_t>(xdi >> 8));
  out->push_back(static_cast<uint8_t>(xdi & 0xFF));
  out->push_back(static_cast<uint8_t>(data.size()));
  out->insert(out->end(), data.begin(), data.end());
}

}  // namespace

Expected<std::unique_ptr<EmulatedMti>> EmulatedMti::Create(const std::string& link) {
  std::unique_ptr<EmulatedMti> d(new EmulatedMti());
  d->master_ = posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (d->master_ < 0 || grantpt(d->master_) != 0 || unlockpt(d->master_) != 0)
    return UnavailableError(std::string("pseudo-terminal: ") + std::strerror(errno));
  termios t{};
  tcgetattr(d->master_, &t);
  cfmakeraw(&t);
  tcsetattr(d->master_, TCSANOW, &t);
  const char* slave = ptsname(d->master_);
  if (slave == nullptr) return UnavailableError("ptsname failed");
  std::error_code ec;
  std::filesystem::remove(link, ec);
  std::filesystem::create_symlink(slave, link, ec);
  if (ec) return UnavailableError(link + ": " + ec.message());
  d->thread_ = std::jthread([p = d.get()](std::stop_token stop) { p->Run(stop); });
  return d;
}

EmulatedMti::~EmulatedMti() {
  if (thread_.joinable()) {
    thread_.request_stop();
    thread_.join();
  }
  if (master_ >= 0) close(master_);
}

void EmulatedMti::SendRaw(std::span<const uint8_t> bytes) {
  std::lock_guard lock(mutex_);
  raw_.insert(raw_.end(), bytes.begin(), bytes.end());
}
void EmulatedMti::SkipPackets(int count) { skip_ += count; }
void EmulatedMti::SetSilent(bool silent) { silent_ = silent; }
void EmulatedMti::RefuseConfiguration(bool refuse) { refuse_ = refuse; }
void EmulatedMti::StartMeasuring() { measuring_ = true; }
void EmulatedMti::SendOrientationOnly(bool only) { orientation_only_ = only; }

void EmulatedMti::Vanish() {
  if (thread_.joinable()) {
    thread_.request_stop();
    thread_.join();
  }
  if (master_ >= 0) close(master_);
  master_ = -1;
}

std::vector<uint8_t> EmulatedMti::output_configuration() const {
  std::lock_guard lock(mutex_);
  return output_configuration_;
}

void EmulatedMti::Write(std::span<const uint8_t> bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = write(master_, bytes.data() + done, bytes.size() - done);
    if (n > 0) {
      done += static_cast<size_t>(n);
    } else if (n < 0 && (errno == EAGAIN || errno == EINTR)) {
      pollfd p{master_, POLLOUT, 0};
      poll(&p, 1, 10);
    } else {
      return;
    }
  }
}

void EmulatedMti::Run(std::stop_token stop) {
  XbusFramer framer;
  std::vector<uint8_t> in(256);
  uint16_t counter = 0;
  uint32_t ticks = 12'345;
  uint64_t n = 0;
  auto next = std::chrono::steady_clock::now();
  while (!stop.stop_requested()) {
    pollfd p{master_, POLLIN, 0};
    if (poll(&p, 1, 1) > 0 && (p.revents & POLLIN) != 0) {
      const ssize_t got = read(master_, in.data(), in.size());
      if (got > 0) {
        framer.Feed(std::span<const uint8_t>(in.data(), static_cast<size_t>(got)), [&](const XbusMessage& m) {
          std::vector<uint8_t> reply;
          if (m.mid == 0x30) {
            measuring_ = false;
            reply = XbusFramer::Encode(0x31, {});
          } else if (m.mid == 0xC0) {
            if (refuse_) {
              const uint8_t code = 0x21;
              reply = XbusFramer::Encode(0x42, std::span<const uint8_t>(&code, 1));
            } else {
              {
                std::lock_guard lock(mutex_);
                output_configuration_.assign(m.payload.begin(), m.payload.end());
              }
              for (size_t i = 0; i + 3 < m.payload.size(); i += 4) {
                const uint16_t xdi = static_cast<uint16_t>(m.payload[i] << 8 | m.payload[i + 1]);
                const uint16_t hz = static_cast<uint16_t>(m.payload[i + 2] << 8 | m.payload[i + 3]);
                if ((xdi & 0xFFF0) == 0x4020 && hz > 0 && hz != 0xFFFF) rate_hz_ = hz;
              }
              reply = XbusFramer::Encode(0xC1, {});
            }
          } else if (m.mid == 0x10) {
            measuring_ = true;
            ++configurations_;
            next = std::chrono::steady_clock::now();
            reply = XbusFramer::Encode(0x11, {});
          }
          if (!reply.empty()) Write(reply);
        });
      }
    }
    std::vector<uint8_t> raw;
    {
      std::lock_guard lock(mutex_);
      raw.swap(raw_);
    }
    if (!raw.empty()) Write(raw);
    if (!measuring_ || silent_ || std::chrono::steady_clock::now() < next) continue;
    const double rate = rate_hz_;
    next += std::chrono::nanoseconds(static_cast<int64_t>(1e9 / rate));
    const int skip = skip_.exchange(0);
    counter = static_cast<uint16_t>(counter + skip);
    ticks += static_cast<uint32_t>(skip * 10000.0 / rate);
    n += static_cast<uint64_t>(skip);
    std::vector<uint8_t> payload, data;
    data = {static_cast<uint8_t>(counter >> 8), static_cast<uint8_t>(counter & 0xFF)};
    PutPacket(&payload, 0x1020, data);
    data = {static_cast<uint8_t>(ticks >> 24), static_cast<uint8_t>(ticks >> 16), static_cast<uint8_t>(ticks >> 8),
            static_cast<uint8_t>(ticks)};
    PutPacket(&payload, 0x1060, data);
    data.clear();
    if (orientation_only_) {
      for (const float v : {1.0f, 0.0f, 0.0f, 0.0f}) PutFloat(&data, v);
      PutPacket(&payload, 0x2010, data);
    } else {
      for (const float v : {0.01f * static_cast<float>(n), -0.02f, 9.81f}) PutFloat(&data, v);
      PutPacket(&payload, 0x4020, data);
      data.clear();
      for (const float v : {0.1f, -0.2f, 0.001f * static_cast<float>(n)}) PutFloat(&data, v);
      PutPacket(&payload, 0x8020, data);
    }
    data = {0, 0, 0, 3};
    PutPacket(&payload, 0xE020, data);
    Write(XbusFramer::Encode(0x36, payload));
    ++samples_;
    ++counter;
    ticks += static_cast<uint32_t>(10000.0 / rate);
    ++n;
  }
}

}  // namespace cairn::testing
