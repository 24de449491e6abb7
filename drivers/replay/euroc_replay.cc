#include "drivers/replay/euroc_replay.h"

#include <opencv2/core.hpp>

#include "io/image_codec.h"

namespace cairn {
namespace {

// Wraps a decoded image without copying: the buffer keeps the cv::Mat alive.
Image ToImage(const cv::Mat& mat) {
  auto holder = std::make_shared<cv::Mat>(mat);
  Image img;
  img.data = std::shared_ptr<const uint8_t[]>(holder, holder->data);
  img.width = mat.cols;
  img.height = mat.rows;
  img.stride = static_cast<int>(mat.step[0]);
  img.format = mat.channels() == 3 ? PixelFormat::kBgr8 : PixelFormat::kGray8;
  return img;
}

}  // namespace

EurocReplay::EurocReplay(EurocDataset dataset, ReplayOptions options)
    : dataset_(std::move(dataset)), options_(std::move(options)), clock_(options_) {}

EurocReplay::~EurocReplay() { Stop(); }

Status EurocReplay::Start(SensorSink* sink) {
  if (thread_.joinable()) return FailedPreconditionError("replay already started");
  sink_ = sink;
  thread_ = std::jthread([this](std::stop_token stop) { Run(stop); });
  return Status::Ok();
}

void EurocReplay::Stop() {
  if (!thread_.joinable()) return;
  thread_.request_stop();
  clock_.Interrupt();
  thread_.join();
}

bool EurocReplay::PublishStereo(const EurocStereoEntry& entry, uint64_t counter) {
  const auto fault = [&](const std::string& detail) {
    sink_->OnDeviceFault(DeviceFault{entry.time, "replay/stereo", DeviceFaultKind::kCorruptSample, detail});
    return false;
  };
  const auto left_read = ImageCodec::Read(entry.left_path, ImageReadMode::kUnchanged);
  if (!left_read.ok()) return fault(left_read.status().message());
  const auto right_read = ImageCodec::Read(entry.right_path, ImageReadMode::kUnchanged);
  if (!right_read.ok()) return fault(right_read.status().message());
  const cv::Mat& left = *left_read;
  const cv::Mat& right = *right_read;
  if (left.size() != right.size() || left.type() != right.type() ||
      (left.channels() != 1 && left.channels() != 3) || left.depth() != CV_8U) {
    return fault(entry.left_path + ": left and right images differ in size or type, or are not 8-bit");
  }
  StereoFrame frame;
  frame.time = entry.time;
  frame.frame_counter = counter;
  frame.left = ToImage(left);
  frame.right = ToImage(right);
  sink_->OnStereo(frame);
  return true;
}

void EurocReplay::Run(std::stop_token stop) {
  const auto& imu = dataset_.imu();
  const auto& stereo = dataset_.stereo();
  size_t i = 0, s = 0;
  Timestamp start = Timestamp::Max();
  if (!imu.empty()) start = imu.front().time;
  if (!stereo.empty()) start = std::min(start, stereo.front().time);
  clock_.Start(start);
  while (i < imu.size() || s < stereo.size()) {
    const bool take_imu = s >= stereo.size() || (i < imu.size() && imu[i].time <= stereo[s].time);
    const Timestamp t = take_imu ? imu[i].time : stereo[s].time;
    if (!clock_.WaitUntilDue(stop, t)) return;  // stopped: not finished
    if (take_imu) {
      sink_->OnImu(imu[i++]);
      published_imu_.fetch_add(1, std::memory_order_relaxed);
    } else {
      PublishStereo(stereo[s], s);
      ++s;
      published_stereo_.fetch_add(1, std::memory_order_relaxed);
    }
  }
  finished_.store(true, std::memory_order_release);
}

}  // namespace cairn
