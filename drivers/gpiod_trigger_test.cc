// The GPIO trigger: how kernel stamps become TriggerEvents (clock, sequence, lost edges), its
// options, a chip that is not there (reported, retried, Stop() prompt), and, where the kernel has
// gpio-sim (configfs), real edges, pulses and a chip that vanishes and comes back.

#include "drivers/gpiod_trigger.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>

#include "tests/support/recording_sink.h"

namespace cairn {
namespace {

constexpr int64_t kSecond = 1'000'000'000;

bool HasFault(testing::RecordingSink& sink, DeviceFaultKind kind) {
  return std::any_of(sink.faults.begin(), sink.faults.end(), [&](const DeviceFault& f) { return f.kind == kind; });
}

bool WaitForFault(testing::RecordingSink& sink, DeviceFaultKind kind) {
  return sink.WaitFor([&] { return HasFault(sink, kind); });
}

double SecondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// Polls `done` (the driver's counters change without a message to the sink) for up to 5 s.
template <class F>
bool Eventually(F done) {
  const auto start = std::chrono::steady_clock::now();
  while (!done()) {
    if (SecondsSince(start) > 5.0) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

// ---- the stamps and the sequence ---------------------------------------------------------------

TEST(TriggerEdgeSequencerTest, MonotonicStampsAreKeptAndNumbered) {
  TriggerEdgeSequencer s;
  const Timestamp now = Timestamp::FromNanoseconds(500 * kSecond);
  const int64_t realtime = 1'700'000'000 * kSecond;
  for (int k = 0; k < 3; ++k) {
    const int64_t stamp = 499 * kSecond + k * 1'000'000;
    const TriggerEdge e = s.Add(stamp, now, realtime);
    EXPECT_TRUE(e.valid);
    EXPECT_EQ(e.clock, TriggerEdgeClock::kMonotonic);
    EXPECT_EQ(e.event.time.nanoseconds(), stamp);
    EXPECT_EQ(e.event.sequence, static_cast<uint64_t>(k));
    EXPECT_EQ(e.missed, 0u);
  }
}

TEST(TriggerEdgeSequencerTest, RealtimeStampsOfOldKernelsMoveToTheMonotonicClock) {
  TriggerEdgeSequencer s;
  const Timestamp now = Timestamp::FromNanoseconds(500 * kSecond);
  const int64_t realtime = 1'700'000'000 * kSecond;
  const TriggerEdge e = s.Add(realtime - 2'000'000, now, realtime);  // 2 ms before the reading
  EXPECT_EQ(e.clock, TriggerEdgeClock::kRealtime);
  EXPECT_EQ(e.event.time.nanoseconds(), 500 * kSecond - 2'000'000);
  // A stamp on neither clock: the arrival time, flagged.
  const TriggerEdge odd = s.Add(5 * kSecond, now + Duration::Milliseconds(1), realtime);
  EXPECT_EQ(odd.clock, TriggerEdgeClock::kArrival);
  EXPECT_EQ(odd.event.time, now + Duration::Milliseconds(1));
  // A stamp in the future of the reading is no monotonic stamp either.
  EXPECT_EQ(s.Add(501 * kSecond, now + Duration::Milliseconds(2), realtime).clock, TriggerEdgeClock::kArrival);
}

TEST(TriggerEdgeSequencerTest, GapsAtAKnownRateCountLostEdgesAndSkipTheirNumbers) {
  TriggerEdgeSequencer s;
  s.SetRate(10.0);
  const Timestamp now = Timestamp::FromNanoseconds(100 * kSecond);
  const int64_t realtime = 1'700'000'000 * kSecond;
  const int64_t t0 = 90 * kSecond;
  EXPECT_EQ(s.Add(t0, now, realtime).event.sequence, 0u);
  const TriggerEdge late = s.Add(t0 + 140'000'000, now, realtime);  // 1.4 periods: jitter
  EXPECT_EQ(late.missed, 0u);
  EXPECT_EQ(late.event.sequence, 1u);
  const TriggerEdge gap = s.Add(t0 + 440'000'000, now, realtime);  // 3 periods later: 2 lost
  EXPECT_EQ(gap.missed, 2u);
  EXPECT_EQ(gap.event.sequence, 4u);
  const TriggerEdge back = s.Add(t0 + 440'000'000, now, realtime);  // not after the previous
  EXPECT_FALSE(back.valid);
  EXPECT_EQ(s.next_sequence(), 5u);
  // After a reconnection the outage is no loss; without a rate nothing is inferred.
  s.Restart();
  EXPECT_EQ(s.Add(t0 + 5 * kSecond, now, realtime).missed, 0u);
  s.SetRate(0.0);
  const TriggerEdge unknown = s.Add(t0 + 7 * kSecond, now, realtime);
  EXPECT_EQ(unknown.missed, 0u);
  EXPECT_EQ(unknown.event.sequence, 6u);
}

// ---- options and a missing chip -----------------------------------------------------------------

GpiodTriggerOptions MissingChip() {
  GpiodTriggerOptions o;
  o.chip = "cairn-test-no-such-chip";
  o.line = "3";
  o.reopen_interval = 0.05;
  o.timeout = 0.2;
  return o;
}

TEST(GpiodTriggerTest, OptionsThatCannotWorkAreRefusedAtStart) {
  testing::RecordingSink sink;
  GpiodTriggerOptions same = MissingChip();
  same.output_line = "3";
  EXPECT_EQ(GpiodTrigger(same).Start(&sink).code(), StatusCode::kInvalidArgument);
  GpiodTriggerOptions wide = MissingChip();
  wide.output_line = "4";
  wide.rate_hz = 100.0;
  wide.pulse_width = 0.01;
  const Status s = GpiodTrigger(wide).Start(&sink);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("pulse_width 0.01 s"), std::string::npos) << s.message();
  GpiodTrigger trigger(wide);
  EXPECT_FALSE(trigger.SetRate(-1.0).ok());
  EXPECT_FALSE(trigger.SetRate(std::nan("")).ok());
  EXPECT_FALSE(trigger.SetRate(200.0).ok());  // a 5 ms period cannot hold a 10 ms pulse
  EXPECT_TRUE(trigger.SetRate(50.0).ok());
}

TEST(GpiodTriggerTest, AMissingChipIsReportedOnceAndLookedForAgain) {
  testing::RecordingSink sink;
  GpiodTrigger trigger(MissingChip());
  ASSERT_TRUE(trigger.Start(&sink).ok());  // the daemon runs on without its trigger
  ASSERT_TRUE(WaitForFault(sink, DeviceFaultKind::kDisconnected));
  ASSERT_TRUE(Eventually([&] { return trigger.counts().open_attempts >= 4; }));
  EXPECT_TRUE(trigger.SetRate(20.0).ok());  // kept for when the chip appears
  trigger.Stop();
  std::lock_guard lock(sink.mutex);
  ASSERT_EQ(sink.faults.size(), 1u);  // one outage, one report
  const DeviceFault& f = sink.faults[0];
  EXPECT_EQ(f.device, "gpiod:cairn-test-no-such-chip/3");
  EXPECT_NE(f.detail.find("GPIO chip 'cairn-test-no-such-chip' not found"), std::string::npos) << f.detail;
  EXPECT_NE(f.detail.find("retrying every 0.05 s"), std::string::npos) << f.detail;
  EXPECT_TRUE(sink.triggers.empty());
  EXPECT_EQ(trigger.counts().timeouts, 0u);  // silence counts only while the line is open
}

TEST(GpiodTriggerTest, ALineNameFoundOnNoChipIsReported) {
  testing::RecordingSink sink;
  GpiodTriggerOptions o = MissingChip();
  o.chip = "";
  o.line = "CAIRN_TEST_STROBE";
  GpiodTrigger trigger(o);
  ASSERT_TRUE(trigger.Start(&sink).ok());
  ASSERT_TRUE(WaitForFault(sink, DeviceFaultKind::kDisconnected));
  trigger.Stop();
  std::lock_guard lock(sink.mutex);
  EXPECT_EQ(sink.faults[0].device, "gpiod:CAIRN_TEST_STROBE");
  EXPECT_NE(sink.faults[0].detail.find("no GPIO line named 'CAIRN_TEST_STROBE' on any chip"), std::string::npos)
      << sink.faults[0].detail;
}

TEST(GpiodTriggerTest, StopReturnsPromptlyWhileWaitingToReopen) {
  testing::RecordingSink sink;
  GpiodTriggerOptions o = MissingChip();
  o.reopen_interval = 30.0;  // the thread sleeps in poll() between attempts
  GpiodTrigger trigger(o);
  ASSERT_TRUE(trigger.Start(&sink).ok());
  ASSERT_TRUE(WaitForFault(sink, DeviceFaultKind::kDisconnected));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const auto before = std::chrono::steady_clock::now();
  trigger.Stop();
  EXPECT_LT(SecondsSince(before), 0.2);
  EXPECT_EQ(trigger.counts().open_attempts, 1u);
  trigger.Stop();  // idempotent
}

// ---- gpio-sim ---------------------------------------------------------------------------------

constexpr const char* kConfigfsGpioSim = "/sys/kernel/config/gpio-sim";

bool WriteSysfs(const std::string& path, const std::string& value) {
  std::ofstream out(path);
  out << value;
  out.flush();
  return static_cast<bool>(out);
}

std::string ReadSysfs(const std::string& path) {
  std::ifstream in(path);
  std::string s;
  std::getline(in, s);
  return s;
}

// A simulated GPIO chip of four lines (configfs gpio-sim): line 0 is named "cairn-strobe" and its
// level is set from outside through its `pull` attribute, as a camera's strobe output would.
class GpioSimChip {
 public:
  static constexpr const char* kLabel = "cairn-test-trigger";

  ~GpioSimChip() {
    SetLive(false);
    std::error_code ec;  // rmdir, whatever was made
    std::filesystem::remove(bank_ + "/line0", ec);
    std::filesystem::remove(bank_, ec);
    std::filesystem::remove(dir_, ec);
  }
  // Empty when the chip could not be made.
  std::string Create() {
    dir_ = std::string(kConfigfsGpioSim) + "/cairn-trigger-test";
    bank_ = dir_ + "/gpio-bank0";
    std::error_code ec;
    std::filesystem::create_directory(dir_, ec);
    if (!ec) std::filesystem::create_directory(bank_, ec);
    if (!ec) std::filesystem::create_directory(bank_ + "/line0", ec);
    if (ec) return "configfs: " + ec.message();
    if (!WriteSysfs(bank_ + "/num_lines", "4") || !WriteSysfs(bank_ + "/label", kLabel) ||
        !WriteSysfs(bank_ + "/line0/name", "cairn-strobe") || !SetLive(true)) {
      return "gpio-sim refused the chip";
    }
    return "";
  }
  bool SetLive(bool live) {
    if (dir_.empty()) return false;
    const bool ok = WriteSysfs(dir_ + "/live", live ? "1" : "0");
    if (live) sysfs_ = "/sys/devices/platform/" + ReadSysfs(dir_ + "/dev_name") + "/" + ReadSysfs(bank_ + "/chip_name");
    return ok;
  }
  bool SetLevel(int offset, bool high) {
    return WriteSysfs(sysfs_ + "/sim_gpio" + std::to_string(offset) + "/pull", high ? "pull-up" : "pull-down");
  }
  std::string Value(int offset) const { return ReadSysfs(sysfs_ + "/sim_gpio" + std::to_string(offset) + "/value"); }

 private:
  std::string dir_, bank_, sysfs_;
};

// Skips the test, saying why, when the kernel has no gpio-sim to make a chip with.
#define CAIRN_REQUIRE_GPIO_SIM(chip)                                                              \
  do {                                                                                            \
    if (!std::filesystem::exists(kConfigfsGpioSim)) {                                             \
      GTEST_SKIP() << kConfigfsGpioSim << " is absent: no gpio-sim on this machine (it needs "     \
                   << "CONFIG_GPIO_SIM, configfs mounted and root; `modprobe gpio-sim`)";          \
    }                                                                                             \
    if (const std::string why = (chip).Create(); !why.empty()) {                                  \
      GTEST_SKIP() << "gpio-sim: " << why;                                                        \
    }                                                                                             \
  } while (0)

class GpiodTriggerSimTest : public ::testing::Test {
 protected:
  void SetUp() override { CAIRN_REQUIRE_GPIO_SIM(chip_); }
  static GpiodTriggerOptions Options() {
    GpiodTriggerOptions o;
    o.chip = GpioSimChip::kLabel;
    o.line = "0";
    o.reopen_interval = 0.05;
    o.timeout = 0.5;
    return o;
  }
  // `n` pulses on line 0 from `idle` to the other level and back, 5 ms each.
  void Pulses(int n, bool idle) {
    for (int k = 0; k < n; ++k) {
      ASSERT_TRUE(chip_.SetLevel(0, !idle));
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      ASSERT_TRUE(chip_.SetLevel(0, idle));
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  GpioSimChip chip_;
  testing::RecordingSink sink_;
};

TEST_F(GpiodTriggerSimTest, RisingEdgesArriveStampedOnTheMonotonicClock) {
  ASSERT_TRUE(chip_.SetLevel(0, false));
  GpiodTrigger trigger(Options());
  ASSERT_TRUE(trigger.Start(&sink_).ok());
  ASSERT_TRUE(Eventually([&] { return trigger.counts().open_attempts >= 1; }));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the line is requested
  MonotonicClock clock;
  const Timestamp before = clock.Now();
  Pulses(10, false);
  const Timestamp after = clock.Now();
  ASSERT_TRUE(sink_.WaitFor([&] { return sink_.triggers.size() >= 10; }));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  trigger.Stop();
  std::lock_guard lock(sink_.mutex);
  ASSERT_EQ(sink_.triggers.size(), 10u);  // rising edges only
  for (size_t k = 0; k < 10; ++k) {
    EXPECT_EQ(sink_.triggers[k].sequence, k);
    EXPECT_GE(sink_.triggers[k].time, before);
    EXPECT_LE(sink_.triggers[k].time, after);
    if (k > 0) {
      EXPECT_GE((sink_.triggers[k].time - sink_.triggers[k - 1].time).seconds(), 0.009);
    }
  }
  EXPECT_FALSE(HasFault(sink_, DeviceFaultKind::kCorruptSample));
}

TEST_F(GpiodTriggerSimTest, ALineFoundByNameOnFallingEdges) {
  ASSERT_TRUE(chip_.SetLevel(0, true));
  GpiodTriggerOptions o = Options();
  o.chip = "";
  o.line = "cairn-strobe";
  o.edge = GpioEdge::kFalling;
  GpiodTrigger trigger(o);
  ASSERT_TRUE(trigger.Start(&sink_).ok());
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  Pulses(3, true);
  ASSERT_TRUE(sink_.WaitFor([&] { return sink_.triggers.size() >= 3; }));
  trigger.Stop();
  std::lock_guard lock(sink_.mutex);
  EXPECT_EQ(sink_.triggers.size(), 3u);
}

TEST_F(GpiodTriggerSimTest, SilenceTimesOutAndAVanishedChipComesBack) {
  ASSERT_TRUE(chip_.SetLevel(0, false));
  GpiodTrigger trigger(Options());
  ASSERT_TRUE(trigger.Start(&sink_).ok());
  ASSERT_TRUE(WaitForFault(sink_, DeviceFaultKind::kTimeout));
  ASSERT_TRUE(chip_.SetLive(false));
  ASSERT_TRUE(WaitForFault(sink_, DeviceFaultKind::kDisconnected));
  ASSERT_TRUE(chip_.SetLive(true));
  ASSERT_TRUE(Eventually([&] { return trigger.counts().reconnections >= 1; }));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  Pulses(1, false);
  ASSERT_TRUE(sink_.WaitFor([&] { return !sink_.triggers.empty(); }));
  trigger.Stop();
}

TEST_F(GpiodTriggerSimTest, PulsesOnTheOutputLineAtTheRate) {
  GpiodTriggerOptions o = Options();
  o.output_line = "1";
  o.rate_hz = 50.0;
  o.pulse_width = 0.004;
  GpiodTrigger trigger(o);
  ASSERT_TRUE(trigger.Start(&sink_).ok());
  ASSERT_TRUE(Eventually([&] { return trigger.counts().pulses >= 1; }));
  // Sample the output: it must be seen high and low.
  bool high = false, low = false;
  const auto start = std::chrono::steady_clock::now();
  while (SecondsSince(start) < 0.5) {
    const std::string v = chip_.Value(1);
    high = high || v == "1";
    low = low || v == "0";
  }
  const uint64_t pulses = trigger.counts().pulses;
  ASSERT_TRUE(trigger.SetRate(0.0).ok());  // stops the pulses
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const uint64_t stopped = trigger.counts().pulses;
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(trigger.counts().pulses, stopped);
  trigger.Stop();
  EXPECT_TRUE(high);
  EXPECT_TRUE(low);
  EXPECT_GE(pulses, 20u);  // 0.5 s at 50 Hz, and the first one before
  EXPECT_LE(pulses, 32u);
  EXPECT_EQ(chip_.Value(1), "0");  // left low
}

}  // namespace
}  // namespace cairn
