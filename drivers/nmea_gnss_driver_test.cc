// The NMEA GNSS driver against a receiver emulated on a pseudo-terminal: fixes and their values,
// and every fault the driver reports, with fixes resuming after each.

#include "drivers/nmea_gnss_driver.h"

#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>
#include <thread>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "common/monotonic_clock.h"
#include "tests/support/recording_sink.h"
#include "tests/support/scoped_temp_dir.h"

namespace cairn {
namespace {

using std::chrono::milliseconds;

std::string NmeaPtySentence(const std::string& body) {
  unsigned sum = 0;
  for (const char c : body) sum ^= static_cast<unsigned char>(c);
  char hex[3];
  std::snprintf(hex, sizeof hex, "%02X", sum);
  return "$" + body + "*" + hex + "\r\n";
}

// A receiver on a pseudo-terminal, reached through a symlink (as udev names a real one) so that it
// can vanish and come back under the same path. Every 50 ms an epoch: GGA (altitude 500 + 0.1 n m
// for epoch n) and, unless turned off, GST (ellipse 3 m x 2 m, semi-major axis east; 4.5 m up).
class NmeaPtyReceiver {
 public:
  static Expected<std::unique_ptr<NmeaPtyReceiver>> Create(const std::string& link) {
    std::unique_ptr<NmeaPtyReceiver> r(new NmeaPtyReceiver());
    // Non-blocking: a receiver nobody reads drops its output instead of stalling.
    r->master_ = posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC | O_NONBLOCK);
    if (r->master_ < 0 || grantpt(r->master_) != 0 || unlockpt(r->master_) != 0)
      return UnavailableError(std::string("pseudo-terminal: ") + std::strerror(errno));
    termios t{};
    tcgetattr(r->master_, &t);
    cfmakeraw(&t);
    tcsetattr(r->master_, TCSANOW, &t);
    const char* slave = ptsname(r->master_);
    if (slave == nullptr) return UnavailableError("ptsname failed");
    std::error_code ec;
    std::filesystem::remove(link, ec);
    std::filesystem::create_symlink(slave, link, ec);
    if (ec) return UnavailableError(link + ": " + ec.message());
    r->thread_ = std::jthread([p = r.get()](std::stop_token stop) { p->Run(stop); });
    return r;
  }
  ~NmeaPtyReceiver() { Vanish(); }

  void SendRaw(const std::string& bytes) {  // before the next epoch
    std::lock_guard lock(mutex_);
    raw_ += bytes;
  }
  void SetSilent(bool silent) { silent_ = silent; }
  void SetGst(bool gst) { gst_ = gst; }
  // Closes the pty: the port hangs up.
  void Vanish() {
    if (thread_.joinable()) {
      thread_.request_stop();
      thread_.join();
    }
    if (master_ >= 0) close(master_);
    master_ = -1;
  }

 private:
  NmeaPtyReceiver() = default;

  void Run(std::stop_token stop) {
    int64_t n = 0;
    while (!stop.stop_requested()) {
      std::this_thread::sleep_for(milliseconds(50));
      std::string out;
      {
        std::lock_guard lock(mutex_);
        out.swap(raw_);
      }
      if (!silent_) {
        const int64_t cs = ((12 * 60 + 35) * 60 + 19) * 100 + 5 * n;  // 12:35:19.00 on
        char time[16], gga[96];
        std::snprintf(time, sizeof time, "%02d%02d%02d.%02d", static_cast<int>(cs / 360000 % 24),
                      static_cast<int>(cs / 6000 % 60), static_cast<int>(cs / 100 % 60),
                      static_cast<int>(cs % 100));
        std::snprintf(gga, sizeof gga, "GPGGA,%s,4807.0380,N,01131.0000,E,1,08,0.9,%.1f,M,46.9,M,,", time,
                      500.0 + 0.1 * static_cast<double>(n));
        out += NmeaPtySentence(gga);
        if (gst_) out += NmeaPtySentence(std::string("GPGST,") + time + ",1.2,3.0,2.0,90.0,2.0,3.0,4.5");
        ++n;
      }
      Write(out, stop);
    }
  }

  void Write(const std::string& bytes, const std::stop_token& stop) {
    size_t done = 0;
    while (done < bytes.size() && !stop.stop_requested()) {
      const ssize_t n = write(master_, bytes.data() + done, bytes.size() - done);
      if (n > 0) {
        done += static_cast<size_t>(n);
      } else if (n < 0 && (errno == EAGAIN || errno == EINTR)) {
        pollfd p{master_, POLLOUT, 0};
        if (poll(&p, 1, 10) == 0) return;  // nobody reads: dropped, as on a real line
      } else {
        return;
      }
    }
  }

  int master_ = -1;
  std::atomic<bool> silent_{false}, gst_{true};
  std::mutex mutex_;
  std::string raw_;
  std::jthread thread_;
};

NmeaGnssOptions NmeaPtyOptions(const std::string& link) {
  NmeaGnssOptions o;
  o.device = link;
  o.reopen_interval = 0.1;
  return o;
}

size_t NmeaPtyCountFaults(testing::RecordingSink& sink, DeviceFaultKind kind) {
  std::lock_guard lock(sink.mutex);
  return static_cast<size_t>(std::count_if(sink.faults.begin(), sink.faults.end(),
                                           [&](const DeviceFault& f) { return f.kind == kind; }));
}

class NmeaGnssDriverTest : public ::testing::Test {
 protected:
  void SetUp() override {
    link_ = temp_.path() + "/gnss";
    auto receiver = NmeaPtyReceiver::Create(link_);
    ASSERT_TRUE(receiver.ok()) << receiver.status().ToString();
    receiver_ = std::move(*receiver);
  }
  bool WaitForFixes(size_t n) {
    return sink_.WaitFor([&] { return sink_.gnss.size() >= n; });
  }
  bool WaitForFault(DeviceFaultKind kind, size_t n = 1) {
    return sink_.WaitFor([&] {
      return static_cast<size_t>(std::count_if(sink_.faults.begin(), sink_.faults.end(),
                                               [&](const DeviceFault& f) { return f.kind == kind; })) >= n;
    });
  }
  size_t fixes() {
    std::lock_guard lock(sink_.mutex);
    return sink_.gnss.size();
  }
  const testing::ScopedTempDir temp_{"nmea"};
  std::string link_;
  std::unique_ptr<NmeaPtyReceiver> receiver_;
  testing::RecordingSink sink_;
  MonotonicClock clock_;
};

TEST_F(NmeaGnssDriverTest, PublishesTheReceiversFixes) {
  const Timestamp start = clock_.Now();
  NmeaGnssDriver driver(NmeaPtyOptions(link_));
  ASSERT_TRUE(driver.Start(&sink_).ok());
  ASSERT_TRUE(WaitForFixes(20));
  driver.Stop();
  const Timestamp stop = clock_.Now();
  std::lock_guard lock(sink_.mutex);
  EXPECT_TRUE(sink_.faults.empty()) << sink_.faults.front().detail;
  double last_epoch = -1.0;
  for (const GnssFix& f : sink_.gnss) {
    EXPECT_NEAR(f.latitude, (48.0 + 7.038 / 60.0) * kDegree, 1e-12);
    EXPECT_NEAR(f.longitude, (11.0 + 31.0 / 60.0) * kDegree, 1e-12);
    EXPECT_EQ(f.quality, GnssQuality::kAutonomous);
    EXPECT_EQ(f.satellites, 8);
    // The ellipse's semi-major axis east, from GST.
    EXPECT_NEAR(f.covariance(0, 0), 9.0, 1e-9);
    EXPECT_NEAR(f.covariance(1, 1), 4.0, 1e-9);
    EXPECT_NEAR(f.covariance(2, 2), 20.25, 1e-9);
    // Each epoch once and in order: height = 500 + 0.1 n + 46.9.
    const double epoch = (f.height - 546.9) / 0.1;
    EXPECT_NEAR(epoch, std::round(epoch), 1e-6);
    EXPECT_GT(epoch, last_epoch + 0.5);
    last_epoch = epoch;
    EXPECT_GE(f.time, start);
    EXPECT_LE(f.time, stop);
  }
  for (size_t i = 1; i < sink_.gnss.size(); ++i) EXPECT_GT(sink_.gnss[i].time, sink_.gnss[i - 1].time);
  const NmeaGnssCounts c = driver.counts();
  EXPECT_EQ(c.fixes, sink_.gnss.size());
  EXPECT_EQ(c.corrupt, 0u);
  EXPECT_EQ(c.hdop_fallbacks, 0u);
  EXPECT_EQ(c.reconnections, 0u);
}

TEST_F(NmeaGnssDriverTest, GarbageAndABadChecksumAreFaultsAndFixesGoOn) {
  NmeaGnssDriver driver(NmeaPtyOptions(link_));
  ASSERT_TRUE(driver.Start(&sink_).ok());
  ASSERT_TRUE(WaitForFixes(5));
  std::string damaged = NmeaPtySentence("GPGGA,000000.00,4807.0380,N,01131.0000,E,1,08,0.9,545.4,M,46.9,M,,");
  damaged[10] = '9';
  receiver_->SendRaw(std::string("\x00\x13noise", 7) + damaged);
  // The second refusal comes within a second of the first: reported a second later.
  ASSERT_TRUE(WaitForFault(DeviceFaultKind::kCorruptSample, 2));
  ASSERT_TRUE(WaitForFixes(fixes() + 10));
  driver.Stop();
  EXPECT_EQ(driver.counts().corrupt, 2u);
  std::lock_guard lock(sink_.mutex);
  ASSERT_EQ(sink_.faults.size(), 2u);
  EXPECT_EQ(sink_.faults[0].detail, "7 bytes outside any NMEA sentence");
  EXPECT_EQ(sink_.faults[1].detail, "GPGGA: checksum 64, computed 6D");
  EXPECT_EQ(sink_.faults[1].device, link_);
}

TEST_F(NmeaGnssDriverTest, WithoutGstTheFixesComeWithTheHdopModel) {
  receiver_->SetGst(false);
  NmeaGnssDriver driver(NmeaPtyOptions(link_));
  ASSERT_TRUE(driver.Start(&sink_).ok());
  ASSERT_TRUE(WaitForFixes(5));
  driver.Stop();
  EXPECT_EQ(driver.counts().hdop_fallbacks, driver.counts().fixes);
  std::lock_guard lock(sink_.mutex);
  EXPECT_NEAR(sink_.gnss[0].covariance(0, 0), 2.7 * 2.7, 1e-9);  // HDOP 0.9 * 3 m
  EXPECT_NEAR(sink_.gnss[0].covariance(2, 2), 4.05 * 4.05, 1e-9);
}

TEST_F(NmeaGnssDriverTest, SilenceIsATimeoutAndAVanishedPortIsReopened) {
  NmeaGnssOptions o = NmeaPtyOptions(link_);
  o.timeout = 0.3;
  NmeaGnssDriver driver(o);
  ASSERT_TRUE(driver.Start(&sink_).ok());
  ASSERT_TRUE(WaitForFixes(5));
  receiver_->SetSilent(true);
  ASSERT_TRUE(WaitForFault(DeviceFaultKind::kTimeout));
  receiver_->SetSilent(false);
  ASSERT_TRUE(WaitForFixes(fixes() + 5));

  // Unplugged: the port hangs up. Plugged in again: a new device node under the same link.
  receiver_->Vanish();
  ASSERT_TRUE(WaitForFault(DeviceFaultKind::kDisconnected));
  auto again = NmeaPtyReceiver::Create(link_);
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  receiver_ = std::move(*again);
  ASSERT_TRUE(WaitForFixes(fixes() + 10));
  driver.Stop();
  EXPECT_EQ(driver.counts().reconnections, 1u);
  EXPECT_GE(NmeaPtyCountFaults(sink_, DeviceFaultKind::kTimeout), 1u);
  EXPECT_EQ(NmeaPtyCountFaults(sink_, DeviceFaultKind::kCorruptSample), 0u);
}

TEST_F(NmeaGnssDriverTest, AMissingPortIsReportedAndABadBaudRefused) {
  NmeaGnssDriver absent(NmeaPtyOptions(link_ + "-absent"));
  ASSERT_TRUE(absent.Start(&sink_).ok());
  ASSERT_TRUE(WaitForFault(DeviceFaultKind::kDisconnected));
  const auto before = std::chrono::steady_clock::now();
  absent.Stop();  // while waiting to retry
  EXPECT_LT(std::chrono::steady_clock::now() - before, milliseconds(300));
  {
    std::lock_guard lock(sink_.mutex);
    EXPECT_NE(sink_.faults.front().detail.find("-absent"), std::string::npos) << sink_.faults.front().detail;
    EXPECT_EQ(sink_.faults.size(), 1u);  // reported once, not at every retry
  }
  NmeaGnssOptions bad = NmeaPtyOptions(link_);
  bad.baud = 123456;
  EXPECT_FALSE(bad.Validate().ok());
  EXPECT_FALSE(NmeaGnssDriver(bad).Start(&sink_).ok());
  EXPECT_TRUE(NmeaPtyOptions(link_).Validate().ok());
}

TEST_F(NmeaGnssDriverTest, StopIsPromptAndIdempotent) {
  NmeaGnssDriver driver(NmeaPtyOptions(link_));
  ASSERT_TRUE(driver.Start(&sink_).ok());
  EXPECT_FALSE(driver.Start(&sink_).ok());
  ASSERT_TRUE(WaitForFixes(3));
  const auto before = std::chrono::steady_clock::now();
  driver.Stop();
  EXPECT_LT(std::chrono::steady_clock::now() - before, milliseconds(300));
  driver.Stop();
  const size_t after = fixes();
  std::this_thread::sleep_for(milliseconds(150));
  EXPECT_EQ(fixes(), after);  // nothing published after Stop()
}

}  // namespace
}  // namespace cairn
