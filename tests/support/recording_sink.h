#pragma once
// A SensorSink that keeps everything it is given, for tests of drivers and sources.

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <vector>

#include "hal/sensor_sink.h"

namespace cairn::testing {

class RecordingSink final : public SensorSink {
 public:
  void OnImu(const ImuSample& s) override { Add([&] { imu.push_back(s); }); }
  void OnStereo(const StereoFrame& f) override { Add([&] { stereo.push_back(f); }); }
  void OnWheelOdometry(const WheelOdometrySample& s) override { Add([&] { wheel.push_back(s); }); }
  void OnTrigger(const TriggerEvent& e) override { Add([&] { triggers.push_back(e); }); }
  void OnGnss(const GnssFix& g) override {
    Add([&] { gnss.push_back(g); });
  }
  void OnDeviceFault(const DeviceFault& f) override { Add([&] { faults.push_back(f); }); }

  // Waits (up to `timeout`) until `done()` holds, evaluated under the lock.
  bool WaitFor(const std::function<bool()>& done,
               std::chrono::milliseconds timeout = std::chrono::milliseconds(5000)) {
    std::unique_lock lock(mutex);
    return cv.wait_for(lock, timeout, done);
  }

  std::mutex mutex;
  std::vector<ImuSample> imu;
  std::vector<StereoFrame> stereo;
  std::vector<WheelOdometrySample> wheel;
  std::vector<TriggerEvent> triggers;
  std::vector<GnssFix> gnss;
  std::vector<DeviceFault> faults;

 private:
  void Add(const std::function<void()>& f) {
    {
      std::lock_guard lock(mutex);
      f();
    }
    cv.notify_all();
  }
  std::condition_variable cv;
};

}  // namespace cairn::testing
