#pragma once
// A stereo pair of GigE Vision cameras read through Aravis (aravis_camera_options.h). The driver's
// thread opens and configures both cameras (aravis_camera.h), then pairs their frames and publishes
// them as StereoFrames: Mono8 without a copy (the image holds the stream buffer until its last
// consumer lets go, aravis_buffer_pool.h), Mono16 and Bayer converted to gray into preallocated
// images.
//
// Pairing (aravis_frame_pairer.h) uses the cameras' raw device timestamps only: for true partners
// their difference, left - right, is a constant (0 for cameras on one PTP clock triggered
// together, their phase when free running, anything for independent tick counters) plus slow
// drift. The driver learns it after every (re)connection from candidate pairs, matched within
// half a frame period against the difference of the two cameras' least delayed frames, and
// publishes nothing until enough candidates agree; then two frames pair when their device time
// difference is within `pair_tolerance` of the learned one, which follows the drift. Neither the
// host clock mappings nor the transport delays enter: a camera whose first frames came late, or a
// mapper still settling, cannot make frames of different triggers a pair. A frame whose partner
// can no longer come, or does not come within two frame periods, is dropped and counted.
//
// Time: each camera's frame timestamp (its own tick counter) is mapped to the host's monotonic
// clock (device_clock_mapper.h) against the frame's arrival, measured when the driver takes the
// buffer (Aravis' "system timestamp" is the realtime clock and is not used). A pair's time is the
// mean of its two frames' mapped times plus half the exposure when the exposure is fixed: the
// timestamp is taken to mark the start of exposure, as on most GigE Vision cameras. While a
// mapper settles (the first seconds of a connection) its offset still carries some transport
// delay, and so does the pair's time, by half that camera's excess; pair times only increase.
//
// Faults, each reported to the sink and counted, never fatal: buffers that failed or miss packets
// (kCorruptSample), frames the frame ids say were lost, or that found every gray image held by
// consumers (kOverrun), no frame from a camera for `frame_timeout` (kTimeout; the camera is then
// probed every `frame_timeout`), a camera that cannot be opened, does not answer the probe or
// reports that control was lost (kDisconnected: both cameras are closed and reopened every
// `reopen_interval`, frames resume), a camera that refuses its configuration (kOther, retried).

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "common/monotonic_clock.h"
#include "drivers/aravis_camera.h"
#include "drivers/aravis_camera_options.h"
#include "drivers/aravis_frame_pairer.h"
#include "drivers/device_clock_mapper.h"
#include "hal/stereo_camera_interface.h"

namespace cairn {

struct AravisStereoCounts {
  uint64_t frames = 0;      // pairs published
  uint64_t incomplete = 0;  // buffers that failed or miss packets
  uint64_t lost = 0;        // frames missing by the frame ids, both cameras
  uint64_t unpaired = 0;    // frames dropped without a partner (also while the pair offset is learned)
  uint64_t no_image = 0;    // converted frames dropped: consumers held every gray image
  uint64_t timeouts = 0;
  uint64_t reconnections = 0;
  uint64_t pair_relearns = 0;  // the pair offset learned again without a reconnection
  // The learned left - right device time difference of partners (s); 0 while it is learned.
  double pair_offset = 0.0;
  // The fitted device-to-host clock offsets (s) and their drifts (ppm) of the current connection.
  double left_offset = 0.0, left_drift_ppm = 0.0;
  double right_offset = 0.0, right_drift_ppm = 0.0;
};

class AravisStereoCamera final : public StereoCameraInterface {
 public:
  AravisStereoCamera(AravisCameraOptions options, StereoCalibration calibration);
  ~AravisStereoCamera() override;

  std::string name() const override { return options_.left + "+" + options_.right; }
  Status Start(SensorSink* sink) override;
  void Stop() override;
  bool finished() const override { return false; }
  StereoCalibration calibration() const override { return calibration_; }
  // Both apply to both cameras, through the driver's thread (blocking until it has); while the
  // cameras are not open they are kept for the next opening and Ok is returned.
  Status SetExposure(Duration exposure) override;
  Status SetTriggerMode(TriggerMode mode) override;

  // A snapshot for reports.
  AravisStereoCounts counts() const;
  // True when `pixels` lies in a stream buffer of the open cameras: an image published without a
  // copy.
  bool IsStreamBuffer(const uint8_t* pixels) const;

 private:
  enum Side { kLeft = 0, kRight = 1 };
  struct Camera {
    std::unique_ptr<AravisCamera> device;
    DeviceClockMapper clock;
    bool have_id = false;
    uint64_t last_id = 0;
    uint64_t counter = 0;  // frame id unwrapped
    Timestamp last_frame, last_probe;
    bool timed_out = false;
  };
  struct Request {
    bool exposure = false;  // else the trigger mode
  };

  // Keeps a setting (under the request mutex) and, while running, has the driver's thread apply
  // it to both cameras, waiting for the result.
  Status Apply(Request request, const std::function<void()>& keep);
  void Run(std::stop_token stop);
  Status Connect();
  void Disconnect(int lost_side, const std::string& why);
  void Take(Side side, ArvBuffer* buffer, Timestamp arrival);
  void Pair(Timestamp now);
  void Watch(Timestamp now);
  void Serve();
  void Fault(DeviceFaultKind kind, const std::string& detail);
  void Wake();

  AravisCameraOptions options_;
  StereoCalibration calibration_;
  SensorSink* sink_ = nullptr;
  MonotonicClock clock_;
  Camera cameras_[2];
  bool connected_ = false;
  AravisFramePairer pairer_;
  AravisFramePairer::Frame pair_[2];  // the pair Pair() publishes

  std::mutex wake_mutex_;
  std::condition_variable wake_cv_;
  bool woken_ = false;

  // Settings and requests from other threads. The desired exposure and trigger mode are what every
  // (re)opening configures.
  std::mutex setter_mutex_;  // one request at a time
  mutable std::mutex request_mutex_;
  std::condition_variable request_cv_;
  Duration exposure_;
  TriggerMode trigger_ = TriggerMode::kFreeRunning;
  bool running_ = false;
  std::optional<Request> request_;
  std::optional<Status> result_;

  mutable std::mutex pools_mutex_;
  std::shared_ptr<AravisBufferPool> pools_[2];

  std::atomic<uint64_t> frames_{0}, incomplete_{0}, lost_{0}, unpaired_{0}, no_image_{0}, timeouts_{0},
      reconnections_{0}, pair_relearns_{0};
  std::atomic<double> offsets_[2] = {0.0, 0.0}, drifts_[2] = {0.0, 0.0}, pair_offset_{0.0};
  std::jthread thread_;
};

}  // namespace cairn
