#include "sim/simulator_source.h"

#include <cmath>

#include "common/heap_bytes.h"
#include "drivers/can_wheel_decoder.h"
#include "sim/imu_synthesizer.h"
#include "sim/wheel_can_encoder.h"

namespace cairn::sim {
namespace {

// Hands a rendered buffer to the HAL image without copying it.
Image ToImage(std::vector<uint8_t>&& pixels, int width, int height) {
  auto holder = std::make_shared<std::vector<uint8_t>>(std::move(pixels));
  Image img;
  img.data = std::shared_ptr<const uint8_t[]>(holder, holder->data());
  img.width = width;
  img.height = height;
  img.stride = width;
  img.format = PixelFormat::kGray8;
  return img;
}

}  // namespace

SimulatorSource::SimulatorSource(std::shared_ptr<const MissionSimulator> simulator, size_t robot,
                                 ReplayOptions pacing, const GnssSimulatorOptions& gnss, uint64_t seed)
    : simulator_(std::move(simulator)), robot_(robot), gnss_(gnss), seed_(seed), clock_(pacing) {}

SimulatorSource::~SimulatorSource() { Stop(); }

Status SimulatorSource::Start(SensorSink* sink) {
  if (thread_.joinable()) return FailedPreconditionError(name() + ": already started");
  if (robot_ >= simulator_->robots().size()) return InvalidArgumentError("simulator: no robot " + std::to_string(robot_));
  sink_ = sink;
  imu_ = simulator_->ImuStream(robot_);
  if (simulator_->robots()[robot_].kind == SimRobotKind::kRover) can_ = simulator_->WheelStream(robot_);
  if (gnss_.enabled) {
    gnss_fixes_ =
        GnssSimulator(gnss_, seed_, robot_)
            .Generate(simulator_->robots()[robot_].trajectory, simulator_->start(), simulator_->duration());
  }
  clock_.Start(simulator_->start());
  thread_ = std::jthread([this](std::stop_token stop) { Run(stop); });
  return Status::Ok();
}

void SimulatorSource::Stop() {
  if (!thread_.joinable()) return;
  thread_.request_stop();
  clock_.Interrupt();
  thread_.join();
}

size_t SimulatorSource::memory_bytes() const {
  return HeapBytes(imu_, can_.frames, can_.reported, gnss_fixes_);
}

void SimulatorSource::Run(std::stop_token stop) {
  const SimRobot& robot = simulator_->robots()[robot_];
  const Timestamp start = simulator_->start();
  const double duration = simulator_->duration();
  const std::vector<ImuTruth>& imu = imu_;
  const WheelCanStream& can = can_;
  const std::vector<GnssTruth>& gnss = gnss_fixes_;
  CanWheelDecoder decoder(simulator_->can_layout());
  const int64_t period_ns = std::llround(1e9 / robot.camera_rate_hz);
  const size_t frames = static_cast<size_t>(std::floor(duration * robot.camera_rate_hz + 1e-9)) + 1;
  size_t i = 0, c = 0, f = 0, g = 0;
  bool stopped = false;
  while (i < imu.size() || c < can.frames.size() || f < frames || g < gnss.size()) {
    const Timestamp ti = i < imu.size() ? imu[i].sample.time : Timestamp::Max();
    const Timestamp tc = c < can.frames.size() ? can.frames[c].time : Timestamp::Max();
    const Timestamp tf = f < frames ? start + Duration::Nanoseconds(static_cast<int64_t>(f) * period_ns) : Timestamp::Max();
    const Timestamp tg = g < gnss.size() ? gnss[g].published : Timestamp::Max();
    if (tg < ti && tg < tc && tg < tf) {
      if ((stopped = !clock_.WaitUntilDue(stop, tg))) break;
      sink_->OnGnss(gnss[g++].fix);
    } else if (ti <= tc && ti <= tf) {
      if ((stopped = !clock_.WaitUntilDue(stop, ti))) break;
      sink_->OnImu(imu[i++].sample);
    } else if (tc <= tf) {
      if ((stopped = !clock_.WaitUntilDue(stop, tc))) break;
      WheelOdometrySample s;
      if (decoder.Feed(can.frames[c].frame, tc, &s) == CanWheelDecoder::Result::kSampleReady) {
        sink_->OnWheelOdometry(s);
      }
      ++c;
    } else {
      std::vector<uint8_t> left, right;
      simulator_->RenderStereo(robot_, static_cast<double>((tf - start).nanoseconds()) * 1e-9, f, &left, &right);
      if ((stopped = !clock_.WaitUntilDue(stop, tf))) break;
      const PinholeRadTan& k = robot.stereo.left.intrinsics;
      StereoFrame frame;
      frame.time = tf;
      frame.exposure = Duration::Seconds(simulator_->exposure_time());
      frame.frame_counter = f;
      frame.left = ToImage(std::move(left), k.width, k.height);
      frame.right = ToImage(std::move(right), k.width, k.height);
      sink_->OnStereo(frame);
      ++f;
    }
  }
  if (!stopped) finished_.store(true, std::memory_order_release);
}

}  // namespace cairn::sim
