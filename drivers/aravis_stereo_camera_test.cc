// The Aravis stereo driver against two of Aravis' fake GigE Vision cameras on loopback addresses
// (drivers/testing/fake_gv_stereo_camera.h): pairing and pixels, time, zero copy and buffer reuse,
// conversions, every fault, with frames resuming after each, and a camera whose first frames come
// late. Each test has its own two addresses, since ctest runs them in parallel processes.
//
// The tests run on loaded machines (two at a time, under ThreadSanitizer, beside other tests): the
// fake cameras' threads then wake late, frames are lost, time out or find no partner. None of that
// fails a test, and the counts are in the failure messages; what must hold under any load is
// checked: every published pair's two images were served for the same frame (Together), their
// pixels are the served ones, times increase, buffers are reused, the injected faults are
// reported and frames resume after them. Frame rates and images are small where the test needs
// no more, and waits are long (they end as soon as their condition holds).

#include "drivers/aravis_stereo_camera.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "common/monotonic_clock.h"
#include "drivers/testing/fake_gv_stereo_camera.h"

namespace cairn {
namespace {

using std::chrono::milliseconds;

constexpr int kWidth = 64;
constexpr int kHeight = 48;
constexpr milliseconds kLongWait(20000);

// The frame slot of a fake camera's frame: both cameras take frames on multiples of the period
// (late by their thread's scheduling).
int64_t Slot(int64_t timestamp_ns, double rate_hz) {
  return std::llround(static_cast<double>(timestamp_ns) * 1e-9 * rate_hz);
}

// A pattern that names its camera and the time it was served (0.1 ms units, 32 bits) in its first
// pixels, and that every pixel is checked against.
uint8_t PatternPixel(int side, int64_t stamp, int x, int y) {
  if (y == 0 && x < 4) return static_cast<uint8_t>((stamp >> (8 * x)) & 0xFF);
  if (y == 0 && x == 4) return side == 0 ? 17 : 231;
  return static_cast<uint8_t>((x + 3 * y + 5 * stamp + 101 * side) & 0xFF);
}

testing::FakeGvStereoCamera::ImageFunction Pattern() {
  return [](int side, uint64_t, int64_t timestamp_ns, int width, int height, uint8_t* gray) {
    const int64_t stamp = (timestamp_ns / 100000) & 0xFFFFFFFF;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) gray[y * width + x] = PatternPixel(side, stamp, x, y);
  };
}

// The serving time the image names, or -1 when any pixel differs from the pattern.
int64_t DecodePattern(const Image& image, int side) {
  if (image.empty() || image.format != PixelFormat::kGray8) return -1;
  int64_t stamp = 0;
  for (int x = 0; x < 4; ++x) stamp |= static_cast<int64_t>(image.row(0)[x]) << (8 * x);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (y == 0 && x < 4) continue;
      if (image.row(y)[x] != PatternPixel(side, stamp, x, y)) return -1;
    }
  }
  return stamp;
}

// Whether the two images of a pair were served for the same frame: within half a period of each
// other (the driver pairs within 0.3 periods, Options(); frames of neighbouring triggers are a
// period apart).
bool Together(int64_t left_stamp, int64_t right_stamp, double rate_hz) {
  return left_stamp >= 0 && right_stamp >= 0 &&
         std::abs(left_stamp - right_stamp) <= std::llround(0.5 / rate_hz * 1e4);
}

// What the sink saw of one frame; it keeps images only when told to hold some.
struct Seen {
  Timestamp time, arrival;
  Duration exposure;
  uint64_t counter = 0;
  const uint8_t* left = nullptr;
  const uint8_t* right = nullptr;
  bool left_in_stream = false, right_in_stream = false;
  int64_t left_slot = -1, right_slot = -1;
  int width = 0, height = 0;
  int left_value = -1, right_value = -1;  // the pixel value of a uniform image, else -1
};

int UniformValue(const Image& image) {
  if (image.empty()) return -1;
  const uint8_t v = image.row(0)[0];
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      if (image.row(y)[x] != v) return -1;
  return v;
}

class StereoSink final : public SensorSink {
 public:
  void OnImu(const ImuSample&) override {}
  void OnWheelOdometry(const WheelOdometrySample&) override {}
  void OnTrigger(const TriggerEvent&) override {}
  void OnGnss(const GnssFix&) override {}
  void OnStereo(const StereoFrame& f) override {
    Seen s;
    s.arrival = clock_.Now();
    s.time = f.time;
    s.exposure = f.exposure;
    s.counter = f.frame_counter;
    s.left = f.left.data.get();
    s.right = f.right.data.get();
    s.left_in_stream = camera != nullptr && camera->IsStreamBuffer(s.left);
    s.right_in_stream = camera != nullptr && camera->IsStreamBuffer(s.right);
    s.left_slot = DecodePattern(f.left, 0);
    s.right_slot = DecodePattern(f.right, 1);
    s.left_value = UniformValue(f.left);
    s.right_value = UniformValue(f.right);
    s.width = f.left.width;
    s.height = f.left.height;
    {
      std::lock_guard lock(mutex);
      seen.push_back(s);
      if (static_cast<int>(held.size()) < hold) held.push_back(f);
    }
    cv_.notify_all();
  }
  void OnDeviceFault(const DeviceFault& f) override {
    {
      std::lock_guard lock(mutex);
      faults.push_back(f);
    }
    cv_.notify_all();
  }
  bool WaitFor(const std::function<bool()>& done, milliseconds timeout = kLongWait) {
    std::unique_lock lock(mutex);
    return cv_.wait_for(lock, timeout, done);
  }
  size_t Count(DeviceFaultKind kind) const {  // under `mutex`
    return static_cast<size_t>(
        std::count_if(faults.begin(), faults.end(), [&](const DeviceFault& f) { return f.kind == kind; }));
  }
  std::string Faults() const {  // under `mutex`
    std::string all;
    for (const DeviceFault& f : faults)
      all += std::string(DeviceFaultKindName(f.kind)) + ": " + f.detail + "\n";
    return all;
  }
  // Under `mutex`: what a failure message reports of the run.
  std::string Report(const AravisStereoCounts& c) const {
    return "published " + std::to_string(seen.size()) + " pairs (" + std::to_string(c.frames) +
           " counted), lost " + std::to_string(c.lost) + ", unpaired " + std::to_string(c.unpaired) +
           ", incomplete " + std::to_string(c.incomplete) + ", timeouts " + std::to_string(c.timeouts) +
           ", reconnections " + std::to_string(c.reconnections) + ", pair relearns " +
           std::to_string(c.pair_relearns) + ", pair offset " + std::to_string(c.pair_offset) +
           " s\nfaults:\n" + Faults();
  }

  const AravisStereoCamera* camera = nullptr;
  std::mutex mutex;
  std::vector<Seen> seen;
  std::vector<DeviceFault> faults;
  int hold = 0;
  std::vector<StereoFrame> held;

 private:
  MonotonicClock clock_;
  std::condition_variable cv_;
};

class AravisStereoCameraTest : public ::testing::Test {
 protected:
  // Test `index` gets 127.0.0.(20 + 2 index) and the next address.
  void Serve(int index, testing::FakeGvStereoCamera::ImageFunction image) {
    const std::string base = "127.0.0.";
    auto fake = testing::FakeGvStereoCamera::Create(base + std::to_string(20 + 2 * index),
                                                    base + std::to_string(21 + 2 * index), std::move(image));
    if (!fake.ok()) GTEST_SKIP() << fake.status().ToString();
    fake_ = std::move(*fake);
  }
  AravisCameraOptions Options(double rate_hz) const {
    AravisCameraOptions o;
    o.left = fake_->address(0);
    o.right = fake_->address(1);
    o.width = kWidth;
    o.height = kHeight;
    o.frame_rate_hz = rate_hz;
    o.exposure = 0.002;  // the fake camera has no automatic exposure
    o.buffers = 6;
    o.frame_timeout = 0.5;
    o.reopen_interval = 0.2;
    // The fake cameras stamp a frame when their threads wake: under load the two stamps of one
    // trigger differ by milliseconds (a real pair is hardware-triggered, 2 ms is plenty).
    o.pair_tolerance = 0.3 / rate_hz;
    o.packet_socket = false;
    return o;
  }
  bool WaitForFrames(size_t n) {
    return sink_.WaitFor([&] { return sink_.seen.size() >= n; });
  }

  std::unique_ptr<testing::FakeGvStereoCamera> fake_;
  StereoSink sink_;
};

// Checks what must hold of every published frame: both images are the served ones, of one frame,
// with the configured size; times and counters increase.
void ExpectCorrectPairs(const std::vector<Seen>& seen, double rate_hz, const std::string& report,
                        size_t first = 0) {
  for (size_t i = first; i < seen.size(); ++i) {
    const Seen& s = seen[i];
    ASSERT_GE(s.left_slot, 0) << "frame " << i << ": the left image is not what the camera served\n"
                              << report;
    ASSERT_GE(s.right_slot, 0) << "frame " << i << ": the right image is not what the camera served\n"
                               << report;
    ASSERT_TRUE(Together(s.left_slot, s.right_slot, rate_hz))
        << "frame " << i << " pairs images served " << (s.right_slot - s.left_slot) * 0.1
        << " ms apart (right - left)\n"
        << report;
    EXPECT_EQ(s.width, kWidth);
    EXPECT_EQ(s.height, kHeight);
    if (i > first) {
      EXPECT_GT(s.time, seen[i - 1].time) << i;
      EXPECT_GT(s.counter, seen[i - 1].counter) << i;
    }
  }
}

TEST_F(AravisStereoCameraTest, PublishesPairsOfTheServedImagesOnTheHostClock) {
  constexpr double kRate = 25.0;
  Serve(0, Pattern());
  if (!fake_) return;
  AravisStereoCamera camera(Options(kRate), StereoCalibration{});
  ASSERT_TRUE(camera.Start(&sink_).ok());
  ASSERT_TRUE(WaitForFrames(25));
  camera.Stop();
  const AravisStereoCounts c = camera.counts();
  std::lock_guard lock(sink_.mutex);
  const std::string report = sink_.Report(c);
  ExpectCorrectPairs(sink_.seen, kRate, report);
  std::vector<double> periods;
  for (size_t i = 0; i < sink_.seen.size(); ++i) {
    const Seen& s = sink_.seen[i];
    EXPECT_EQ(s.exposure, Duration::Milliseconds(2));
    // Mid-exposure, mapped from the device clock: before the frame reached the sink (but for the
    // half exposure the fake camera does not spend), and not long before (the fake cameras' clock
    // is the realtime clock, decades from the monotonic one).
    EXPECT_LE(s.time, s.arrival + s.exposure / 2) << i;
    EXPECT_GT(s.time, s.arrival - Duration::Milliseconds(500)) << i << "\n" << report;
    if (i > 0) {
      const Seen& p = sink_.seen[i - 1];
      periods.push_back((s.time - p.time).seconds() / static_cast<double>(s.counter - p.counter));
    }
  }
  // The frame period by the published times: the fake cameras' device clocks, mapped.
  std::nth_element(periods.begin(), periods.begin() + periods.size() / 2, periods.end());
  EXPECT_NEAR(periods[periods.size() / 2], 1.0 / kRate, 0.003) << report;
  EXPECT_EQ(c.frames, sink_.seen.size());
  // Both fake cameras stamp with the realtime clock, a trigger's frames within a few ms.
  EXPECT_NEAR(c.pair_offset, 0.0, 0.2 / kRate) << report;
  EXPECT_LT(c.left_offset, -1e8);
  EXPECT_LT(c.right_offset, -1e8);
}

TEST_F(AravisStereoCameraTest, Mono8ImagesAreTheStreamBuffersReusedAcrossTheFrameIdWrap) {
  constexpr double kRate = 50.0;
  Serve(1, Pattern());
  if (!fake_) return;
  AravisCameraOptions o = Options(kRate);
  o.buffers = 4;
  AravisStereoCamera camera(o, StereoCalibration{});
  sink_.camera = &camera;
  ASSERT_TRUE(camera.Start(&sink_).ok());
  // The fake cameras' frame ids start at 65401 (when created) and wrap from 65535 to 1 (0 is not
  // a frame id): the published counters, unwrapped, must go on past 65535.
  const bool wrapped =
      sink_.WaitFor([&] { return !sink_.seen.empty() && sink_.seen.back().counter > 65545; });
  camera.Stop();
  const AravisStereoCounts c = camera.counts();
  std::lock_guard lock(sink_.mutex);
  const std::string report = sink_.Report(c);
  ASSERT_TRUE(wrapped) << report;
  ASSERT_LE(sink_.seen.front().counter, 65535u) << "the frame ids did not start before the wrap";
  ExpectCorrectPairs(sink_.seen, kRate, report);
  std::set<const uint8_t*> left, right;
  for (size_t i = 0; i < sink_.seen.size(); ++i) {
    const Seen& s = sink_.seen[i];
    EXPECT_TRUE(s.left_in_stream && s.right_in_stream) << "an image was copied out of its stream buffer";
    left.insert(s.left);
    right.insert(s.right);
    // Across the wrap the counter steps by the frames missed, not by 65535 or back.
    if (i > 0) {
      EXPECT_LT(s.counter - sink_.seen[i - 1].counter, 50u) << i << "\n" << report;
    }
  }
  EXPECT_LE(left.size(), 4u);
  EXPECT_LE(right.size(), 4u);
  for (const DeviceFault& f : sink_.faults)
    EXPECT_EQ(f.detail.find("65535 -> 1)"), std::string::npos)
        << "the wrap was counted as a loss: " << f.detail;
}

TEST_F(AravisStereoCameraTest, ImagesHeldByTheConsumerStallTheStreamUntilReleased) {
  constexpr double kRate = 25.0;
  Serve(2, Pattern());
  if (!fake_) return;
  AravisCameraOptions o = Options(kRate);
  o.buffers = 3;
  AravisStereoCamera camera(o, StereoCalibration{});
  sink_.hold = 3;  // every buffer of both cameras
  ASSERT_TRUE(camera.Start(&sink_).ok());
  ASSERT_TRUE(WaitForFrames(3));
  std::this_thread::sleep_for(milliseconds(600));  // 15 frames each
  {
    std::lock_guard lock(sink_.mutex);
    EXPECT_EQ(sink_.seen.size(), 3u) << "a frame came without a free buffer";
    sink_.held.clear();  // the buffers go back to their streams
    sink_.hold = 0;
  }
  ASSERT_TRUE(WaitForFrames(15)) << "frames did not resume";
  camera.Stop();
  const AravisStereoCounts c = camera.counts();
  std::lock_guard lock(sink_.mutex);
  const std::string report = sink_.Report(c);
  ExpectCorrectPairs(sink_.seen, kRate, report);
  EXPECT_GE(sink_.Count(DeviceFaultKind::kOverrun), 1u) << report;
  EXPECT_GE(c.lost, 10u) << report;  // 600 ms at 25 Hz, both cameras
}

TEST_F(AravisStereoCameraTest, Mono16AndBayerArePublishedAsGray) {
  constexpr double kRate = 25.0;
  // Uniform images whose value changes with the slot: the Bayer window mean keeps them exact.
  Serve(3, [](int side, uint64_t, int64_t timestamp_ns, int width, int height, uint8_t* gray) {
    const int64_t slot = Slot(timestamp_ns, kRate);
    std::fill(gray, gray + width * height, static_cast<uint8_t>((slot * 7 + side * 50) & 0xFF));
  });
  if (!fake_) return;
  for (const char* format : {"mono16", "bayer_rg8"}) {
    SCOPED_TRACE(format);
    AravisCameraOptions o = Options(kRate);
    o.pixel_format = format;
    AravisStereoCamera camera(o, StereoCalibration{});
    sink_.camera = &camera;
    ASSERT_TRUE(camera.Start(&sink_).ok());
    ASSERT_TRUE(WaitForFrames(10));
    camera.Stop();
    std::lock_guard lock(sink_.mutex);
    const std::string report = sink_.Report(camera.counts());
    for (const Seen& s : sink_.seen) {
      EXPECT_FALSE(s.left_in_stream);  // converted into a gray image of the pool
      ASSERT_GE(s.left_value, 0) << "not uniform";
      ASSERT_GE(s.right_value, 0) << "not uniform";
      // The same slot; a neighbour's only when the two stamps of one trigger straddle the middle of
      // a period (threads waking later than 0.2 periods apart would not pair).
      const int d = (s.right_value - s.left_value + 256) % 256;
      EXPECT_TRUE(d == 50 || d == 43 || d == 57) << d << "\n" << report;
      EXPECT_EQ(s.width, kWidth);
    }
    sink_.seen.clear();
  }
}

TEST_F(AravisStereoCameraTest, AVanishedCameraIsReportedAndFramesResumeWhenItReturns) {
  constexpr double kRate = 20.0;
  Serve(4, Pattern());
  if (!fake_) return;
  AravisStereoCamera camera(Options(kRate), StereoCalibration{});
  ASSERT_TRUE(camera.Start(&sink_).ok());
  ASSERT_TRUE(WaitForFrames(5));
  fake_->StopCamera(1);  // the right camera's cable pulled
  // A silent camera is a timeout, then the probe finds it gone (GVCP gives up after 2.5 s).
  ASSERT_TRUE(sink_.WaitFor([&] { return sink_.Count(DeviceFaultKind::kDisconnected) > 0; }));
  ASSERT_TRUE(fake_->StartCamera(1).ok());
  size_t before = 0;
  {
    std::lock_guard lock(sink_.mutex);
    before = sink_.seen.size();
    EXPECT_GE(sink_.Count(DeviceFaultKind::kTimeout), 1u) << sink_.Faults();
    const auto gone = std::find_if(sink_.faults.begin(), sink_.faults.end(), [](const DeviceFault& f) {
      return f.kind == DeviceFaultKind::kDisconnected;
    });
    EXPECT_NE(gone->detail.find(fake_->address(1)), std::string::npos) << gone->detail;
  }
  ASSERT_TRUE(WaitForFrames(before + 10)) << "frames did not resume";
  camera.Stop();
  const AravisStereoCounts c = camera.counts();
  std::lock_guard lock(sink_.mutex);
  const std::string report = sink_.Report(c);
  EXPECT_GE(c.reconnections, 1u) << report;
  ExpectCorrectPairs(sink_.seen, kRate, report);
}

TEST_F(AravisStereoCameraTest, ACameraAbsentAtStartIsRetriedUntilItAppears) {
  constexpr double kRate = 20.0;
  Serve(5, Pattern());
  if (!fake_) return;
  fake_->StopCamera(0);
  AravisStereoCamera camera(Options(kRate), StereoCalibration{});
  ASSERT_TRUE(camera.Start(&sink_).ok());
  ASSERT_TRUE(sink_.WaitFor([&] { return !sink_.faults.empty(); }));
  {
    std::lock_guard lock(sink_.mutex);
    EXPECT_EQ(sink_.faults.front().kind, DeviceFaultKind::kDisconnected) << sink_.Faults();
    EXPECT_NE(sink_.faults.front().detail.find(fake_->address(0)), std::string::npos)
        << sink_.faults.front().detail;
  }
  ASSERT_TRUE(fake_->StartCamera(0).ok());
  ASSERT_TRUE(WaitForFrames(5));
  camera.Stop();
  std::lock_guard lock(sink_.mutex);
  const std::string report = sink_.Report(camera.counts());
  EXPECT_EQ(sink_.Count(DeviceFaultKind::kDisconnected), 1u) << "reported once while retrying: " << report;
  ExpectCorrectPairs(sink_.seen, kRate, report);
}

TEST_F(AravisStereoCameraTest, TriggerAndExposureApplyToBothCameras) {
  constexpr double kRate = 20.0;
  Serve(6, Pattern());
  if (!fake_) return;
  AravisCameraOptions o = Options(kRate);
  o.trigger_source = "Line0";  // the fake camera's input line
  AravisStereoCamera camera(o, StereoCalibration{});
  ASSERT_TRUE(camera.Start(&sink_).ok());
  ASSERT_TRUE(WaitForFrames(3));
  ASSERT_TRUE(camera.SetExposure(Duration::Milliseconds(3)).ok());
  EXPECT_FALSE(camera.SetExposure(Duration()).ok()) << "the fake camera has no automatic exposure";
  EXPECT_FALSE(camera.SetExposure(Duration::Milliseconds(-1)).ok());
  // An external trigger that never fires: silence, a timeout per camera, but both still answer.
  size_t timeouts = 0;
  {
    std::lock_guard lock(sink_.mutex);
    timeouts = sink_.Count(DeviceFaultKind::kTimeout);
  }
  ASSERT_TRUE(camera.SetTriggerMode(TriggerMode::kExternal).ok());
  ASSERT_TRUE(sink_.WaitFor([&] { return sink_.Count(DeviceFaultKind::kTimeout) >= timeouts + 2; }));
  std::this_thread::sleep_for(milliseconds(600));  // a probe of each
  size_t before = 0;
  {
    std::lock_guard lock(sink_.mutex);
    EXPECT_EQ(sink_.Count(DeviceFaultKind::kDisconnected), 0u) << sink_.Faults();
    before = sink_.seen.size();
  }
  ASSERT_TRUE(camera.SetTriggerMode(TriggerMode::kFreeRunning).ok());
  ASSERT_TRUE(WaitForFrames(before + 5));
  camera.Stop();
  const AravisStereoCounts c = camera.counts();
  std::lock_guard lock(sink_.mutex);
  const std::string report = sink_.Report(c);
  EXPECT_EQ(sink_.seen.back().exposure, Duration::Milliseconds(3));
  ExpectCorrectPairs(sink_.seen, kRate, report);
  EXPECT_EQ(c.reconnections, 0u) << report;
}

TEST_F(AravisStereoCameraTest, IncompleteFramesAreCorruptSamplesAndTheStreamGoesOn) {
  constexpr double kRate = 25.0;
  Serve(7, Pattern());
  if (!fake_) return;
  AravisCameraOptions o = Options(kRate);
  o.packet_resend = false;
  o.frame_retention = 0.02;
  AravisStereoCamera camera(o, StereoCalibration{});
  ASSERT_TRUE(camera.Start(&sink_).ok());
  ASSERT_TRUE(WaitForFrames(3));
  size_t corrupt = 0;
  {
    std::lock_guard lock(sink_.mutex);
    corrupt = sink_.Count(DeviceFaultKind::kCorruptSample);
  }
  fake_->SetPacketLoss(0, 0.1);
  ASSERT_TRUE(sink_.WaitFor([&] { return sink_.Count(DeviceFaultKind::kCorruptSample) >= corrupt + 3; }));
  fake_->SetPacketLoss(0, 0.0);
  size_t before = 0;
  {
    std::lock_guard lock(sink_.mutex);
    before = sink_.seen.size();
  }
  ASSERT_TRUE(WaitForFrames(before + 10)) << "frames did not resume";
  camera.Stop();
  const AravisStereoCounts c = camera.counts();
  EXPECT_GE(c.incomplete, 3u);
  std::lock_guard lock(sink_.mutex);
  ExpectCorrectPairs(sink_.seen, kRate, sink_.Report(c));  // no incomplete image published
}

TEST_F(AravisStereoCameraTest, StopIsIdempotentAndAHeldFrameOutlivesTheDriver) {
  constexpr double kRate = 25.0;
  Serve(8, Pattern());
  if (!fake_) return;
  sink_.hold = 1;
  StereoFrame kept;
  {
    AravisStereoCamera camera(Options(kRate), StereoCalibration{});
    ASSERT_TRUE(camera.Start(&sink_).ok());
    EXPECT_FALSE(camera.Start(&sink_).ok());
    ASSERT_TRUE(WaitForFrames(2));
    camera.Stop();
    camera.Stop();
    std::lock_guard lock(sink_.mutex);
    kept = sink_.held.front();
    sink_.held.clear();
  }  // the driver, its cameras and streams are gone; the kept frame's buffers are not
  fake_.reset();
  const int64_t slot = DecodePattern(kept.left, 0);
  EXPECT_GE(slot, 0);
  EXPECT_TRUE(Together(slot, DecodePattern(kept.right, 1), kRate));
  kept = StereoFrame();  // frees the buffers (ASan checks)
}

TEST_F(AravisStereoCameraTest, ACameraWhoseFirstFramesComeLateMakesNoWrongPairs) {
  constexpr double kRate = 20.0;
  // The left camera sends its first four frames 160 ms (over three periods) after stamping them,
  // so its clock mapper starts with that much transport delay in its offset: pairing by mapped
  // times paired them with the right camera's frames of three triggers later.
  auto delayed = std::make_shared<std::atomic<int>>(0);
  Serve(9, [delayed, pattern = Pattern()](int side, uint64_t id, int64_t timestamp_ns, int width, int height,
                                          uint8_t* gray) {
    if (side == 0 && delayed->load() < 4) {
      delayed->fetch_add(1);
      std::this_thread::sleep_for(milliseconds(160));
    }
    pattern(side, id, timestamp_ns, width, height, gray);
  });
  if (!fake_) return;
  AravisStereoCamera camera(Options(kRate), StereoCalibration{});
  ASSERT_TRUE(camera.Start(&sink_).ok());
  ASSERT_TRUE(WaitForFrames(30));
  camera.Stop();
  const AravisStereoCounts c = camera.counts();
  std::lock_guard lock(sink_.mutex);
  const std::string report = sink_.Report(c);
  EXPECT_EQ(delayed->load(), 4);
  ExpectCorrectPairs(sink_.seen, kRate, report);
  EXPECT_NEAR(c.pair_offset, 0.0, 0.2 / kRate) << report;
}

TEST(AravisCameraOptionsTest, ValidateNamesTheKeyAtFault) {
  AravisCameraOptions o;
  o.left = "127.0.0.2";
  o.right = "127.0.0.3";
  EXPECT_TRUE(o.Validate().ok()) << o.Validate().ToString();
  o.pixel_format = "rgb10";
  Status s = o.Validate();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("pixel_format"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("rgb10"), std::string::npos) << s.message();
  AravisStereoCamera camera(o, StereoCalibration{});
  StereoSink sink;
  EXPECT_EQ(camera.Start(&sink).code(), StatusCode::kInvalidArgument);
  o.pixel_format = "bayer_gr8";
  o.pair_tolerance = 0.03;  // beyond half of a 20 Hz period
  s = o.Validate();
  EXPECT_NE(s.message().find("pair_tolerance"), std::string::npos) << s.message();
  o.pair_tolerance = 0.002;
  o.right = o.left;
  EXPECT_FALSE(o.Validate().ok());
}

}  // namespace
}  // namespace cairn
