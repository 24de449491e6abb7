#include "drivers/aravis_camera.h"

#include <arv.h>

#include <cmath>

namespace cairn {
namespace {

// GigE Vision bootstrap register: bit 1 (control) or 0 (exclusive) set while this host controls
// the camera.
constexpr guint64 kControlChannelPrivilege = 0x0A00;
constexpr guint32 kControlOrExclusive = 0x3;

// Turns an Aravis error into a Status naming `what`, and frees it. Ok when there was none.
Status Take(GError*& error, const std::string& what, StatusCode code = StatusCode::kFailedPrecondition) {
  if (error == nullptr) return Status::Ok();
  Status s(code, what + ": " + error->message);
  g_clear_error(&error);
  return s;
}

ArvPixelFormat ArvFormat(AravisPixelFormat f) {
  switch (f) {
    case AravisPixelFormat::kMono8:
      return ARV_PIXEL_FORMAT_MONO_8;
    case AravisPixelFormat::kMono16:
      return ARV_PIXEL_FORMAT_MONO_16;
    case AravisPixelFormat::kBayerRg8:
      return ARV_PIXEL_FORMAT_BAYER_RG_8;
    case AravisPixelFormat::kBayerBg8:
      return ARV_PIXEL_FORMAT_BAYER_BG_8;
    case AravisPixelFormat::kBayerGb8:
      return ARV_PIXEL_FORMAT_BAYER_GB_8;
    case AravisPixelFormat::kBayerGr8:
      return ARV_PIXEL_FORMAT_BAYER_GR_8;
  }
  return ARV_PIXEL_FORMAT_MONO_8;
}

}  // namespace

Expected<std::unique_ptr<AravisCamera>> AravisCamera::Open(const std::string& id,
                                                           const AravisCameraOptions& options,
                                                           Duration exposure, TriggerMode trigger,
                                                           std::function<void()> on_buffer) {
  auto format = ParseAravisPixelFormat(options.pixel_format);
  if (!format.ok()) return format.status();
  std::unique_ptr<AravisCamera> c(new AravisCamera());
  c->id_ = id;
  c->trigger_source_ = options.trigger_source;
  c->frame_rate_hz_ = options.frame_rate_hz;
  c->on_buffer_ = std::move(on_buffer);
  GError* error = nullptr;
  c->camera_ = arv_camera_new(id.c_str(), &error);
  if (c->camera_ == nullptr) {
    if (error == nullptr) return UnavailableError(id + ": not found");
    return Take(error, id, StatusCode::kUnavailable);
  }
  c->control_lost_handler_ = g_signal_connect(arv_camera_get_device(c->camera_), "control-lost",
                                              G_CALLBACK(&AravisCamera::OnControlLost), c.get());

  arv_camera_set_pixel_format(c->camera_, ArvFormat(*format), &error);
  CAIRN_RETURN_IF_ERROR(Take(error, id + ": pixel format " + options.pixel_format));
  CAIRN_RETURN_IF_ERROR(c->Configure(options, exposure, trigger));

  if (arv_camera_is_gv_device(c->camera_)) {
    arv_camera_gv_set_stream_options(c->camera_, options.packet_socket
                                                     ? ARV_GV_STREAM_OPTION_NONE
                                                     : ARV_GV_STREAM_OPTION_PACKET_SOCKET_DISABLED);
  }
  ArvStream* stream = arv_camera_create_stream(c->camera_, nullptr, nullptr, &error);
  if (stream == nullptr) {
    if (error == nullptr) return UnavailableError(id + ": no stream");
    return Take(error, id + ": creating the stream", StatusCode::kUnavailable);
  }
  if (ARV_IS_GV_STREAM(stream)) {
    g_object_set(
        stream, "packet-resend",
        options.packet_resend ? ARV_GV_STREAM_PACKET_RESEND_ALWAYS : ARV_GV_STREAM_PACKET_RESEND_NEVER,
        "packet-timeout", static_cast<guint>(std::lround(options.packet_timeout * 1e6)), "frame-retention",
        static_cast<guint>(std::lround(options.frame_retention * 1e6)), nullptr);
  }
  const gint payload = arv_camera_get_payload(c->camera_, &error);
  if (Status s = Take(error, id + ": payload size"); !s.ok()) {
    g_object_unref(stream);
    return s;
  }
  gint x = 0, y = 0, width = 0, height = 0;
  arv_camera_get_region(c->camera_, &x, &y, &width, &height, &error);
  if (Status s = Take(error, id + ": region"); !s.ok()) {
    g_object_unref(stream);
    return s;
  }
  const size_t gray_bytes =
      *format == AravisPixelFormat::kMono8 ? 0 : static_cast<size_t>(width) * static_cast<size_t>(height);
  c->pool_ = AravisBufferPool::Create(stream, static_cast<size_t>(payload), static_cast<int>(options.buffers),
                                      gray_bytes);
  g_signal_connect(stream, "new-buffer", G_CALLBACK(&AravisCamera::OnNewBuffer), c.get());
  arv_stream_set_emit_signals(stream, TRUE);
  g_object_unref(stream);  // the pool holds it
  return c;
}

AravisCamera::~AravisCamera() { Close(false); }

Status AravisCamera::Configure(const AravisCameraOptions& options, Duration exposure, TriggerMode trigger) {
  GError* error = nullptr;
  if (options.width > 0 || options.height > 0) {
    gint x = 0, y = 0, width = 0, height = 0;
    arv_camera_get_region(camera_, &x, &y, &width, &height, &error);
    CAIRN_RETURN_IF_ERROR(Take(error, id_ + ": region"));
    arv_camera_set_region(camera_, 0, 0, options.width > 0 ? static_cast<gint>(options.width) : width,
                          options.height > 0 ? static_cast<gint>(options.height) : height, &error);
    CAIRN_RETURN_IF_ERROR(Take(
        error, id_ + ": region " + std::to_string(options.width) + "x" + std::to_string(options.height)));
  }
  arv_camera_set_acquisition_mode(camera_, ARV_ACQUISITION_MODE_CONTINUOUS, &error);
  CAIRN_RETURN_IF_ERROR(Take(error, id_ + ": continuous acquisition"));
  CAIRN_RETURN_IF_ERROR(SetTrigger(trigger));
  return SetExposure(exposure);
}

Status AravisCamera::Start() {
  GError* error = nullptr;
  arv_camera_start_acquisition(camera_, &error);
  return Take(error, id_ + ": starting acquisition", StatusCode::kUnavailable);
}

ArvBuffer* AravisCamera::TryPop() { return pool_ != nullptr ? pool_->TryPop() : nullptr; }

Status AravisCamera::Probe() {
  if (camera_ == nullptr) return UnavailableError(id_ + ": closed");
  GError* error = nullptr;
  guint32 value = 0;
  if (ARV_IS_GV_DEVICE(arv_camera_get_device(camera_))) {
    arv_device_read_register(arv_camera_get_device(camera_), kControlChannelPrivilege, &value, &error);
    CAIRN_RETURN_IF_ERROR(Take(error, id_ + " does not answer", StatusCode::kUnavailable));
    if ((value & kControlOrExclusive) == 0) return UnavailableError(id_ + ": control of the camera was lost");
    return Status::Ok();
  }
  arv_camera_get_pixel_format(camera_, &error);  // any register read: the device still answers
  return Take(error, id_ + " does not answer", StatusCode::kUnavailable);
}

Status AravisCamera::SetExposure(Duration exposure) {
  if (exposure < Duration()) return InvalidArgumentError("exposure must not be negative");
  GError* error = nullptr;
  const bool has_auto = arv_camera_is_exposure_auto_available(camera_, &error);
  CAIRN_RETURN_IF_ERROR(Take(error, id_ + ": exposure"));
  if (exposure == Duration()) {
    if (!has_auto) return FailedPreconditionError(id_ + ": the camera has no automatic exposure");
    arv_camera_set_exposure_time_auto(camera_, ARV_AUTO_CONTINUOUS, &error);
    CAIRN_RETURN_IF_ERROR(Take(error, id_ + ": automatic exposure"));
    exposure_ = Duration();
    return Status::Ok();
  }
  if (has_auto) {
    arv_camera_set_exposure_time_auto(camera_, ARV_AUTO_OFF, &error);
    CAIRN_RETURN_IF_ERROR(Take(error, id_ + ": automatic exposure off"));
  }
  arv_camera_set_exposure_time(camera_, static_cast<double>(exposure.nanoseconds()) * 1e-3, &error);
  CAIRN_RETURN_IF_ERROR(Take(error, id_ + ": exposure " + std::to_string(exposure.seconds()) + " s"));
  // The camera rounds to what it can do: keep what it took.
  const double us = arv_camera_get_exposure_time(camera_, &error);
  CAIRN_RETURN_IF_ERROR(Take(error, id_ + ": reading the exposure back"));
  exposure_ = Duration::Nanoseconds(std::llround(us * 1e3));
  return Status::Ok();
}

Status AravisCamera::SetTrigger(TriggerMode mode) {
  GError* error = nullptr;
  // Many cameras refuse trigger and rate changes while acquiring; Start() resumes.
  if (pool_ != nullptr) {
    arv_camera_stop_acquisition(camera_, &error);
    CAIRN_RETURN_IF_ERROR(Take(error, id_ + ": stopping acquisition", StatusCode::kUnavailable));
  }
  if (mode == TriggerMode::kFreeRunning) {
    arv_camera_clear_triggers(camera_, &error);
    CAIRN_RETURN_IF_ERROR(Take(error, id_ + ": free running"));
    if (arv_camera_is_frame_rate_available(camera_, nullptr)) {
      arv_camera_set_frame_rate(camera_, frame_rate_hz_, &error);
      CAIRN_RETURN_IF_ERROR(Take(error, id_ + ": frame rate " + std::to_string(frame_rate_hz_) + " Hz"));
    }
  } else {
    arv_camera_set_trigger(camera_, trigger_source_.c_str(), &error);
    CAIRN_RETURN_IF_ERROR(Take(error, id_ + ": external trigger on " + trigger_source_));
  }
  if (pool_ != nullptr) return Start();
  return Status::Ok();
}

void AravisCamera::Close(bool reachable) {
  if (camera_ == nullptr) return;
  if (reachable && pool_ != nullptr) {
    GError* error = nullptr;
    arv_camera_stop_acquisition(camera_, &error);
    g_clear_error(&error);  // closing anyway
  }
  if (pool_ != nullptr) pool_->Close();
  pool_.reset();
  // The device's heartbeat thread emits "control-lost" holding a reference to the device (GLib
  // does, for the emission). Were that the last one, the device would be finalized on its own
  // heartbeat thread, which would join itself (GLib aborts: "Resource deadlock avoided"), and the
  // emission could still be running OnControlLost on this object. Once the handler is
  // disconnected no emission starts (none has a handler left); one under way is waited for, so
  // the last reference goes here.
  ArvDevice* device = ARV_DEVICE(g_object_ref(arv_camera_get_device(camera_)));
  g_signal_handler_disconnect(device, control_lost_handler_);
  g_object_unref(camera_);
  camera_ = nullptr;
  for (int i = 0; i < 2000 && g_atomic_int_get(&G_OBJECT(device)->ref_count) > 1; ++i) g_usleep(1000);
  g_object_unref(device);  // leaves control of the camera, joins its heartbeat thread
}

void AravisCamera::OnNewBuffer(void* /*stream*/, void* self) {
  static_cast<AravisCamera*>(self)->on_buffer_();
}

void AravisCamera::OnControlLost(void* /*device*/, void* self) {
  static_cast<AravisCamera*>(self)->control_lost_.store(true);
}

}  // namespace cairn
