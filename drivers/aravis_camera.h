#pragma once
// One GigE Vision (or USB3 Vision) camera opened through Aravis for AravisStereoCamera: configured
// from AravisCameraOptions, with a stream whose buffers live in an AravisBufferPool. Used from the
// stereo driver's thread only; Aravis' own threads (stream, heartbeat) reach it through two
// callbacks: a buffer is ready, and control of the camera was lost (another host took it, or the
// camera restarted).
//
// Every Aravis error comes back as a Status; a GigE Vision camera that does not answer costs its
// register access 2.5 s (Aravis retries five times, 500 ms each), which is what opening an absent
// camera, probing a vanished one and releasing it take.

#include <atomic>
#include <functional>
#include <memory>
#include <string>

#include "common/status.h"
#include "common/timestamp.h"
#include "drivers/aravis_buffer_pool.h"
#include "drivers/aravis_camera_options.h"
#include "hal/stereo_camera_interface.h"

typedef struct _ArvCamera ArvCamera;

namespace cairn {

class AravisCamera {
 public:
  // Opens `id`, configures it (pixel format, region, rate, trigger, exposure) and creates its
  // stream with `options.buffers` buffers; acquisition starts with Start(). `on_buffer` runs on
  // Aravis' stream thread whenever a buffer is ready.
  static Expected<std::unique_ptr<AravisCamera>> Open(const std::string& id,
                                                      const AravisCameraOptions& options, Duration exposure,
                                                      TriggerMode trigger, std::function<void()> on_buffer);
  ~AravisCamera();
  AravisCamera(const AravisCamera&) = delete;
  AravisCamera& operator=(const AravisCamera&) = delete;

  Status Start();
  // The next finished buffer, or null. It must go back through pool().Share or pool().Requeue.
  ArvBuffer* TryPop();
  AravisBufferPool& pool() { return *pool_; }
  std::shared_ptr<AravisBufferPool> shared_pool() const { return pool_; }

  // Reads the control channel privilege: an error when the camera does not answer or no longer
  // sees this host as its controller.
  Status Probe();
  bool control_lost() const { return control_lost_.load(); }

  // Zero selects automatic exposure.
  Status SetExposure(Duration exposure);
  Status SetTrigger(TriggerMode mode);
  // The exposure of every frame when fixed; zero when automatic (unknown per frame).
  Duration exposure() const { return exposure_; }

  // Stops acquisition (skipped when `reachable` is false: the camera would not answer) and
  // releases the stream and the camera; buffers consumers still hold are freed later. Idempotent.
  void Close(bool reachable);

  const std::string& id() const { return id_; }

 private:
  AravisCamera() = default;
  Status Configure(const AravisCameraOptions& options, Duration exposure, TriggerMode trigger);
  static void OnNewBuffer(void* stream, void* self);
  static void OnControlLost(void* device, void* self);

  std::string id_;
  std::string trigger_source_;
  double frame_rate_hz_ = 0.0;
  ArvCamera* camera_ = nullptr;
  std::shared_ptr<AravisBufferPool> pool_;
  std::function<void()> on_buffer_;
  std::atomic<bool> control_lost_{false};
  unsigned long control_lost_handler_ = 0;  // NOLINT: glib's gulong
  Duration exposure_;
};

}  // namespace cairn
