#include "drivers/aravis_stereo_camera.h"

#include <arv.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>

#include "drivers/gray_conversion.h"

namespace cairn {
namespace {

constexpr auto kWait = std::chrono::milliseconds(10);  // longest sleep of the driver's loop
constexpr uint64_t kLargestId16 = 65535;               // GigE Vision 1.x frame ids: 1..65535, 0 skipped
constexpr uint64_t kLargestGap = 30000;                // beyond it a camera restarted its ids

const char* BufferStatusName(ArvBufferStatus s) {
  switch (s) {
    case ARV_BUFFER_STATUS_SUCCESS:
      return "success";
    case ARV_BUFFER_STATUS_CLEARED:
      return "cleared";
    case ARV_BUFFER_STATUS_TIMEOUT:
      return "timed out";
    case ARV_BUFFER_STATUS_MISSING_PACKETS:
      return "missing packets";
    case ARV_BUFFER_STATUS_WRONG_PACKET_ID:
      return "wrong packet id";
    case ARV_BUFFER_STATUS_SIZE_MISMATCH:
      return "larger than its buffer";
    case ARV_BUFFER_STATUS_FILLING:
      return "still filling";
    case ARV_BUFFER_STATUS_ABORTED:
      return "aborted";
    default:
      return "failed";
  }
}

// Frames missing between two consecutive frame ids; 0 when `id` follows `last` or the ids restarted.
uint64_t MissingFrames(uint64_t last, uint64_t id) {
  uint64_t missing = 0;
  if (id > last) {
    missing = id - last - 1;
  } else if (last <= kLargestId16) {
    missing = (kLargestId16 - last) + (id - 1);  // wrapped past 65535 to 1
  } else {
    return 0;
  }
  return missing > kLargestGap ? 0 : missing;
}

}  // namespace

AravisStereoCamera::AravisStereoCamera(AravisCameraOptions options, StereoCalibration calibration)
    : options_(std::move(options)),
      calibration_(std::move(calibration)),
      pairer_(AravisFramePairerOptions{
          Duration::Seconds(1.0 / options_.frame_rate_hz), Duration::Seconds(options_.pair_tolerance),
          Duration::Seconds(options_.pair_tolerance + 2.0 / options_.frame_rate_hz),
          // Each waiting frame holds a stream buffer or a gray image: never more than `buffers`.
          static_cast<int>(options_.buffers) + 1}),
      exposure_(Duration::Seconds(options_.exposure)),
      trigger_(options_.trigger == AravisTrigger::kExternal ? TriggerMode::kExternal
                                                            : TriggerMode::kFreeRunning) {}

AravisStereoCamera::~AravisStereoCamera() { Stop(); }

AravisStereoCounts AravisStereoCamera::counts() const {
  AravisStereoCounts c;
  c.frames = frames_.load();
  c.incomplete = incomplete_.load();
  c.lost = lost_.load();
  c.unpaired = unpaired_.load();
  c.no_image = no_image_.load();
  c.timeouts = timeouts_.load();
  c.reconnections = reconnections_.load();
  c.pair_relearns = pair_relearns_.load();
  c.pair_offset = pair_offset_.load();
  c.left_offset = offsets_[kLeft].load();
  c.left_drift_ppm = drifts_[kLeft].load();
  c.right_offset = offsets_[kRight].load();
  c.right_drift_ppm = drifts_[kRight].load();
  return c;
}

bool AravisStereoCamera::IsStreamBuffer(const uint8_t* pixels) const {
  std::lock_guard lock(pools_mutex_);
  return std::any_of(std::begin(pools_), std::end(pools_),
                     [&](const auto& p) { return p && p->Owns(pixels); });
}

Status AravisStereoCamera::Start(SensorSink* sink) {
  if (thread_.joinable()) return FailedPreconditionError(name() + ": already started");
  CAIRN_RETURN_IF_ERROR(options_.Validate());
  sink_ = sink;
  {
    std::lock_guard lock(request_mutex_);
    running_ = true;
  }
  thread_ = std::jthread([this](std::stop_token stop) { Run(stop); });
  return Status::Ok();
}

void AravisStereoCamera::Stop() {
  if (thread_.joinable()) {
    thread_.request_stop();
    Wake();
    thread_.join();  // the thread closed the cameras
  }
}

Status AravisStereoCamera::SetExposure(Duration exposure) {
  if (exposure < Duration()) return InvalidArgumentError("exposure must not be negative");
  return Apply(Request{true}, [&] { exposure_ = exposure; });
}

Status AravisStereoCamera::SetTriggerMode(TriggerMode mode) {
  return Apply(Request{false}, [&] { trigger_ = mode; });
}

Status AravisStereoCamera::Apply(Request request, const std::function<void()>& keep) {
  std::lock_guard serial(setter_mutex_);
  std::unique_lock lock(request_mutex_);
  keep();
  if (!running_) return Status::Ok();
  request_ = request;
  result_.reset();
  lock.unlock();
  Wake();
  lock.lock();
  request_cv_.wait(lock, [&] { return result_.has_value(); });
  return *result_;
}

void AravisStereoCamera::Wake() {
  {
    std::lock_guard lock(wake_mutex_);
    woken_ = true;
  }
  wake_cv_.notify_one();
}

void AravisStereoCamera::Fault(DeviceFaultKind kind, const std::string& detail) {
  if (sink_ != nullptr) sink_->OnDeviceFault(DeviceFault{clock_.Now(), name(), kind, detail});
}

void AravisStereoCamera::Serve() {
  std::unique_lock lock(request_mutex_);
  if (!request_) return;
  const Request r = *request_;
  const Duration exposure = exposure_;
  const TriggerMode trigger = trigger_;
  request_.reset();
  lock.unlock();
  Status result = Status::Ok();
  if (connected_) {
    for (Camera& c : cameras_) {
      Status s = r.exposure ? c.device->SetExposure(exposure) : c.device->SetTrigger(trigger);
      if (!s.ok() && result.ok()) result = s;
    }
  }
  lock.lock();
  result_ = result;
  request_cv_.notify_all();
}

Status AravisStereoCamera::Connect() {
  Duration exposure;
  TriggerMode trigger;
  {
    std::lock_guard lock(request_mutex_);
    exposure = exposure_;
    trigger = trigger_;
  }
  const std::string* ids[2] = {&options_.left, &options_.right};
  for (int side : {kLeft, kRight}) {
    auto device = AravisCamera::Open(*ids[side], options_, exposure, trigger, [this] { Wake(); });
    if (!device.ok()) {
      for (Camera& c : cameras_) {
        if (c.device) c.device->Close(true);
        c.device.reset();
      }
      return device.status();
    }
    cameras_[side].device = std::move(*device);
  }
  const Timestamp now = clock_.Now();
  for (Camera& c : cameras_) {
    c.clock = DeviceClockMapper();  // a reopened camera may have restarted its clock
    c.have_id = false;
    c.last_frame = c.last_probe = now;
    c.timed_out = false;
  }
  pairer_.Reset();  // and the offset between the two clocks with it
  // Started back to back, so that free-running cameras begin with frames close in time.
  for (Camera& c : cameras_) {
    if (Status s = c.device->Start(); !s.ok()) {
      for (Camera& d : cameras_) d.device.reset();
      return s;
    }
  }
  std::lock_guard lock(pools_mutex_);
  for (int side : {kLeft, kRight}) pools_[side] = cameras_[side].device->shared_pool();
  return Status::Ok();
}

void AravisStereoCamera::Disconnect(int lost_side, const std::string& why) {
  if (!why.empty()) Fault(DeviceFaultKind::kDisconnected, why + "; reopening");
  {
    std::lock_guard lock(pools_mutex_);
    for (auto& p : pools_) p.reset();
  }
  pairer_.Reset();  // the waiting frames' buffers go back to their pools (freed once closed)
  for (int side : {kLeft, kRight}) {
    Camera& c = cameras_[side];
    if (c.device) c.device->Close(side != lost_side);
    c.device.reset();
  }
  connected_ = false;
}

void AravisStereoCamera::Take(Side side, ArvBuffer* buffer, Timestamp arrival) {
  Camera& c = cameras_[side];
  AravisBufferPool& pool = c.device->pool();
  const std::string& id = c.device->id();
  c.last_frame = arrival;
  c.timed_out = false;
  const uint64_t frame_id = arv_buffer_get_frame_id(buffer);
  if (frame_id != 0) {
    if (c.have_id) {
      const uint64_t missing = MissingFrames(c.last_id, frame_id);
      if (missing > 0) {
        lost_.fetch_add(missing, std::memory_order_relaxed);
        Fault(DeviceFaultKind::kOverrun, id + ": " + std::to_string(missing) + " frames lost (frame id " +
                                             std::to_string(c.last_id) + " -> " + std::to_string(frame_id) +
                                             ")");
      }
      c.counter += missing + 1;
    } else {
      c.counter = frame_id;
    }
    c.have_id = true;
    c.last_id = frame_id;
  }
  // Read before a converted frame's buffer goes back to the stream (to be filled again).
  const auto device_time = static_cast<int64_t>(arv_buffer_get_timestamp(buffer));
  const ArvBufferStatus status = arv_buffer_get_status(buffer);
  if (status != ARV_BUFFER_STATUS_SUCCESS ||
      arv_buffer_get_payload_type(buffer) != ARV_BUFFER_PAYLOAD_TYPE_IMAGE) {
    incomplete_.fetch_add(1, std::memory_order_relaxed);
    Fault(DeviceFaultKind::kCorruptSample,
          id + ": frame " + std::to_string(frame_id) + " " +
              (status != ARV_BUFFER_STATUS_SUCCESS ? BufferStatusName(status) : "is not an image"));
    pool.Requeue(buffer);
    return;
  }
  const int width = arv_buffer_get_image_width(buffer);
  const int height = arv_buffer_get_image_height(buffer);
  gint x_padding = 0, y_padding = 0;
  arv_buffer_get_image_padding(buffer, &x_padding, &y_padding);
  size_t size = 0;
  const auto* pixels = static_cast<const uint8_t*>(arv_buffer_get_image_data(buffer, &size));
  const ArvPixelFormat format = arv_buffer_get_image_pixel_format(buffer);
  const int bytes_per_pixel = format == ARV_PIXEL_FORMAT_MONO_16 ? 2 : 1;
  const size_t stride =
      static_cast<size_t>(width) * static_cast<size_t>(bytes_per_pixel) + static_cast<size_t>(x_padding);
  if (pixels == nullptr || width <= 0 || height <= 0 ||
      size < stride * static_cast<size_t>(height - 1) + static_cast<size_t>(width * bytes_per_pixel)) {
    incomplete_.fetch_add(1, std::memory_order_relaxed);
    Fault(DeviceFaultKind::kCorruptSample, id + ": frame " + std::to_string(frame_id) +
                                               " is smaller than its " + std::to_string(width) + "x" +
                                               std::to_string(height) + " image");
    pool.Requeue(buffer);
    return;
  }
  Image image;
  image.width = width;
  image.height = height;
  image.format = PixelFormat::kGray8;
  if (format == ARV_PIXEL_FORMAT_MONO_8) {
    image.stride = static_cast<int>(stride);
    image.data = pool.Share(buffer, pixels);
    if (image.data == nullptr) {
      pool.Requeue(buffer);
      return;
    }
  } else {
    const bool bayer = format == ARV_PIXEL_FORMAT_BAYER_RG_8 || format == ARV_PIXEL_FORMAT_BAYER_BG_8 ||
                       format == ARV_PIXEL_FORMAT_BAYER_GB_8 || format == ARV_PIXEL_FORMAT_BAYER_GR_8;
    if (!bayer && format != ARV_PIXEL_FORMAT_MONO_16) {
      incomplete_.fetch_add(1, std::memory_order_relaxed);
      Fault(DeviceFaultKind::kCorruptSample, id + ": frame " + std::to_string(frame_id) +
                                                 " has pixel format 0x" + std::to_string(format) +
                                                 ", not the configured " + options_.pixel_format);
      pool.Requeue(buffer);
      return;
    }
    AravisBufferPool::GrayImage gray = pool.AcquireGray();
    if (gray.pixels == nullptr) {
      no_image_.fetch_add(1, std::memory_order_relaxed);
      Fault(DeviceFaultKind::kOverrun,
            id + ": frame " + std::to_string(frame_id) + " dropped, consumers hold every gray image");
      pool.Requeue(buffer);
      return;
    }
    if (bayer) {
      Bayer8ToGray8(pixels, stride, width, height, gray.pixels);
    } else {
      Mono16ToGray8(pixels, stride, width, height, gray.pixels);
    }
    pool.Requeue(buffer);
    image.stride = width;
    image.data = std::move(gray.data);
  }
  const Timestamp time = c.clock.Map(device_time, arrival);
  offsets_[side].store(c.clock.offset_seconds(), std::memory_order_relaxed);
  drifts_[side].store(c.clock.drift_ppm(), std::memory_order_relaxed);
  AravisFramePairer::Frame frame;
  frame.image = std::move(image);
  frame.device_time = device_time;
  frame.time = time;
  frame.arrival = arrival;
  frame.counter = c.counter;
  pairer_.Add(side, std::move(frame));
}

void AravisStereoCamera::Pair(Timestamp now) {
  AravisFramePairer::Frame& left = pair_[kLeft];
  AravisFramePairer::Frame& right = pair_[kRight];
  while (pairer_.Next(now, left, right)) {
    const Duration exposure = cameras_[kLeft].device->exposure();
    StereoFrame frame;
    frame.time = right.time + (left.time - right.time) / 2 + exposure / 2;  // the mean, mid-exposure
    frame.exposure = exposure;
    frame.frame_counter = left.counter;
    frame.left = std::move(left.image);
    frame.right = std::move(right.image);
    left = AravisFramePairer::Frame();
    right = AravisFramePairer::Frame();
    frames_.fetch_add(1, std::memory_order_relaxed);
    sink_->OnStereo(frame);
  }
  unpaired_.store(pairer_.dropped(), std::memory_order_relaxed);
  pair_relearns_.store(pairer_.relearned(), std::memory_order_relaxed);
  pair_offset_.store(static_cast<double>(pairer_.offset_ns()) * 1e-9, std::memory_order_relaxed);
}

void AravisStereoCamera::Watch(Timestamp now) {
  const Duration timeout = Duration::Seconds(options_.frame_timeout);
  for (int side : {kLeft, kRight}) {
    Camera& c = cameras_[side];
    if (c.device->control_lost()) {
      Disconnect(side, c.device->id() + ": control of the camera was lost");
      return;
    }
    if (now - c.last_frame <= timeout) continue;
    if (!c.timed_out) {
      c.timed_out = true;
      timeouts_.fetch_add(1, std::memory_order_relaxed);
      Fault(DeviceFaultKind::kTimeout,
            c.device->id() + ": no frame for " + std::to_string(options_.frame_timeout) + " s");
    }
    // Silence is normal for a trigger that does not fire; a camera that does not answer is gone.
    if (now - c.last_probe >= timeout) {
      c.last_probe = now;
      if (Status s = c.device->Probe(); !s.ok()) {
        Disconnect(side, s.message());
        return;
      }
    }
  }
}

void AravisStereoCamera::Run(std::stop_token stop) {
  Timestamp last_open = clock_.Now() - Duration::Seconds(options_.reopen_interval);
  bool ever_open = false, reported_closed = false;
  while (!stop.stop_requested()) {
    {
      std::unique_lock lock(wake_mutex_);
      wake_cv_.wait_for(lock, kWait, [&] { return woken_; });
      woken_ = false;
    }
    Serve();
    Timestamp now = clock_.Now();
    if (!connected_) {
      if (now - last_open < Duration::Seconds(options_.reopen_interval)) continue;
      if (Status s = Connect(); !s.ok()) {
        last_open = clock_.Now();
        if (!reported_closed) {
          Fault(
              s.code() == StatusCode::kUnavailable ? DeviceFaultKind::kDisconnected : DeviceFaultKind::kOther,
              s.message() + " (retrying)");
        }
        reported_closed = true;
        continue;
      }
      connected_ = true;
      reported_closed = false;
      if (ever_open) reconnections_.fetch_add(1, std::memory_order_relaxed);
      ever_open = true;
      continue;
    }
    for (int side : {kLeft, kRight}) {
      while (ArvBuffer* b = cameras_[side].device->TryPop()) Take(static_cast<Side>(side), b, clock_.Now());
    }
    now = clock_.Now();
    Pair(now);
    Watch(now);
    if (!connected_) {
      last_open = clock_.Now();
      reported_closed = true;
    }
  }
  Disconnect(-1, "");
  std::lock_guard lock(request_mutex_);
  running_ = false;
  if (request_) {
    request_.reset();
    result_ = Status::Ok();  // kept for the next start
    request_cv_.notify_all();
  }
}

}  // namespace cairn
