#include "sim/mission_simulator.h"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <future>
#include <numbers>

#include "sim/candump_format.h"
#include "sim/euroc_writer.h"
#include "sim/imu_synthesizer.h"
#include "sim/sim_random.h"
#include "sim/tag36h11_code.h"
#include "sim/wheel_can_encoder.h"

namespace cairn::sim {
namespace {

std::string MarkerRow(const SimMarker& m) {
  const Eigen::Vector3d p = m.T_body_marker.translation();
  const Eigen::Quaterniond q(m.T_body_marker.linear());
  char buf[256];
  std::snprintf(buf, sizeof(buf), "%d,%.9g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g\n", m.id, m.size,
                p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z());
  return buf;
}

Status WriteMarkers(const std::string& path, const std::vector<SimMarker>& markers) {
  // Ids are AprilTag 36h11 ids; size is the edge of the black border square.
  std::string text = "#id,size [m],p_x [m],p_y [m],p_z [m],q_w,q_x,q_y,q_z\n";
  for (const SimMarker& m : markers) text += MarkerRow(m);
  FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return IoError(path + ": cannot create");
  const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  return std::fclose(f) == 0 && ok ? Status::Ok() : IoError(path + ": write failed");
}

}  // namespace

MissionSimulator::MissionSimulator(const WorldOptions& world, const MissionOptions& mission)
    : world_(world), mission_(mission), terrain_(Terrain::Generate(world)) {}

Expected<std::unique_ptr<MissionSimulator>> MissionSimulator::Create(const WorldOptions& world,
                                                                     const MissionOptions& mission) {
  if (mission.robots.empty()) return InvalidArgumentError("--robots: name at least one robot");
  // Robot i carries tags 10 i .. 10 i + 2; the lander's tags are 200 .. 203.
  if (mission.robots.size() > 20) return InvalidArgumentError("--robots: at most 20 robots per mission");
  if (mission.motion_blur_samples < 1 || mission.motion_blur_samples > 64) {
    return InvalidArgumentError("--motion-blur: samples per exposure must be in [1, 64]");
  }
  if (mission.render_threads < 1 || mission.render_threads > 2) {
    return InvalidArgumentError("render threads per stereo pair must be 1 or 2");
  }
  if (!(mission.duration > 0.0) || mission.duration > 3600.0) {
    return InvalidArgumentError("--duration: must be in (0, 3600] s");
  }
  for (size_t i = 0; i < mission.robots.size(); ++i) {
    const std::string& n = mission.robots[i];
    if (n.rfind("rover", 0) != 0 && n.rfind("hexacopter", 0) != 0) {
      return InvalidArgumentError("--robots: '" + n + "' is neither rover* nor hexacopter*");
    }
    for (size_t j = 0; j < i; ++j) {
      if (mission.robots[j] == n) return InvalidArgumentError("--robots: '" + n + "' named twice");
    }
  }
  std::unique_ptr<MissionSimulator> sim(new MissionSimulator(world, mission));
  const uint64_t seed = static_cast<uint64_t>(world.seed);
  const double tag = world.tag_size;
  Deployment deployment;
  if (mission.deploy_from_lander) {
    if (world.lander.size() != 2) return InvalidArgumentError("deploying from the lander needs a lander in the world");
    if (mission.robots.size() > 4) return InvalidArgumentError("the lander has four tags: at most 4 robots deploy from it");
    deployment.enabled = true;
    deployment.lander = Eigen::Vector2d(world.lander[0], world.lander[1]);
    deployment.lander_ground = sim->terrain_.Height(world.lander[0], world.lander[1]);
    const Eigen::Vector3d sun = sim->sun_direction();
    deployment.sun = sun.head<2>().norm() > 1e-9 ? Eigen::Vector2d(sun.head<2>().normalized()) : Eigen::Vector2d::UnitX();
  }
  for (size_t i = 0; i < mission.robots.size(); ++i) {
    const std::string& n = mission.robots[i];
    const int index = static_cast<int>(i);
    const bool rover = n.rfind("rover", 0) == 0;
    sim->robots_.push_back(rover ? MakeRover(sim->terrain_, n, index, seed, mission.duration,
                                             mission.image_scale, tag, &deployment)
                                 : MakeHexacopter(sim->terrain_, n, index, seed, mission.duration,
                                                  mission.image_scale, tag, &deployment));
    if (rover && world.roof_tag_size > 0.0) AddRoofTag(index, world.roof_tag_size, &sim->robots_.back());
  }
  if (world.lander.size() == 2) {
    // A lander: a 1.6 m box on the ground with a tag on each side.
    const double x = world.lander[0], y = world.lander[1], z = sim->terrain_.Height(x, y);
    sim->static_boxes_.push_back({Eigen::Isometry3d(Eigen::Translation3d(x, y, z + 0.5)), {0.8, 0.8, 0.7}, 0.55f});
    for (int k = 0; k < 4; ++k) {
      SimMarker m;
      m.id = 200 + k;
      m.size = 2.0 * tag;
      m.bits = *Tag36h11MarkerBits(m.id);
      const double az = std::numbers::pi / 2 * k;
      m.T_body_marker.linear() = (Eigen::AngleAxisd(az, Eigen::Vector3d::UnitZ()) *
                                  Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(-std::numbers::pi / 2, Eigen::Vector3d::UnitZ()))
                                     .toRotationMatrix();
      m.T_body_marker.translation() = Eigen::Vector3d(x, y, z + 0.7) + 0.81 * Eigen::Vector3d(std::cos(az), std::sin(az), 0);
      sim->landmarks_.push_back(m);
    }
  }
  return sim;
}

Eigen::Vector3d MissionSimulator::sun_direction() const {
  const double az = world_.sun_azimuth * std::numbers::pi / 180, el = world_.sun_elevation * std::numbers::pi / 180;
  return Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
}

RenderScene MissionSimulator::SceneAt(double t) const {
  RenderScene s;
  s.terrain = &terrain_;
  s.sun_direction = sun_direction();
  s.boxes = static_boxes_;
  s.markers = landmarks_;
  for (const SimRobot& r : robots_) s.AddRobot(r, r.trajectory.Evaluate(t).T_world_body);
  return s;
}

void MissionSimulator::RenderStereo(size_t r, double t, uint64_t frame, std::vector<uint8_t>* left,
                                    std::vector<uint8_t>* right, std::vector<float>* left_depth) const {
  const SimRobot& robot = robots_[r];
  const uint64_t seed = static_cast<uint64_t>(world_.seed);
  const int samples = std::max(1, mission_.motion_blur_samples);
  const CameraCalibration* cams[2] = {&robot.stereo.left, &robot.stereo.right};
  std::vector<uint8_t>* images[2] = {left, right};
  // One camera's image: its noise-free signal averaged over the exposure, then the sensor noise.
  auto render_camera = [&](int c) {
    std::vector<float> sum, signal;
    for (int i = 0; i < samples; ++i) {
      // Instants spread evenly over the exposure, centred on the frame time (mid-exposure).
      const double ti = samples == 1 ? t : t + mission_.exposure_time * ((i + 0.5) / samples - 0.5);
      const RenderScene scene = SceneAt(ti);
      const Eigen::Isometry3d T_world_body = robot.trajectory.Evaluate(ti).T_world_body;
      // The first instant renders straight into the sum; later ones are added to it.
      CameraRenderer::RenderSignal(scene, cams[c]->intrinsics, T_world_body * cams[c]->T_body_cam, mission_.render,
                                   i == 0 ? &sum : &signal, c == 0 && i == samples / 2 ? left_depth : nullptr);
      if (i > 0) {
        for (size_t p = 0; p < signal.size(); ++p) sum[p] += signal[p];
      }
    }
    if (samples > 1) {
      for (float& v : sum) v /= static_cast<float>(samples);
    }
    CameraRenderer::ApplyNoise(sum, cams[c]->intrinsics.width, mission_.render,
                               SimRandom::Mix(seed ^ SimRandom::Mix(r * 1000003 + frame * 2 + static_cast<uint64_t>(c))),
                               images[c]);
  };
  if (mission_.render_threads > 1) {
    std::future<void> right_camera = std::async(std::launch::async, render_camera, 1);
    render_camera(0);
    right_camera.get();
  } else {
    render_camera(0);
    render_camera(1);
  }
}

Status MissionSimulator::Write(const std::string& dir, const std::function<void(double)>& progress) const {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return IoError(dir + ": cannot create: " + ec.message());
  CAIRN_RETURN_IF_ERROR(WriteMarkers(dir + "/landmarks.csv", landmarks_));
  std::vector<size_t> frames;
  size_t total = 0;
  for (const SimRobot& r : robots_) {
    frames.push_back(static_cast<size_t>(std::floor(mission_.duration * r.camera_rate_hz + 1e-9)) + 1);
    total += frames.back();
  }
  size_t before = 0;
  for (size_t r = 0; r < robots_.size(); ++r) {
    CAIRN_RETURN_IF_ERROR(WriteRobot(r, dir + "/" + robots_[r].name, progress, before, total));
    before += frames[r];
  }
  if (progress) progress(1.0);
  return Status::Ok();
}

std::vector<ImuTruth> MissionSimulator::ImuStream(size_t r) const {
  ImuSynthesizer imu(robots_[r].imu, SimRandom::Mix(static_cast<uint64_t>(world_.seed) ^ (0x1A0 + r)));
  return imu.Generate(robots_[r].trajectory, mission_.start, mission_.duration);
}

WheelCanStream MissionSimulator::WheelStream(size_t r) const {
  const SimRobot& robot = robots_[r];
  if (robot.wheels.empty()) return {};
  WheelCanEncoder encoder(mission_.can, robot.wheels.front().z(),
                          SimRandom::Mix(static_cast<uint64_t>(world_.seed) ^ (0xCA0 + r)));
  return encoder.Generate(robot.trajectory, mission_.start, mission_.duration, mission_.can_rate_hz);
}

Status MissionSimulator::WriteRobot(size_t r, const std::string& dir,
                                    const std::function<void(double)>& progress, size_t frames_before,
                                    size_t frames_total) const {
  const SimRobot& robot = robots_[r];
  auto writer = EurocWriter::Create(dir, robot.stereo, robot.camera_rate_hz, robot.imu);
  if (!writer.ok()) return writer.status();
  CAIRN_RETURN_IF_ERROR(WriteMarkers(dir + "/markers.csv", robot.markers));

  const std::vector<ImuTruth> samples = ImuStream(r);
  for (const ImuTruth& s : samples) CAIRN_RETURN_IF_ERROR((*writer)->AddImu(s));

  // Cameras are triggered on IMU sample instants (hardware synchronization).
  const int64_t period_ns = std::llround(1e9 / robot.camera_rate_hz);
  const size_t frames = static_cast<size_t>(std::floor(mission_.duration * robot.camera_rate_hz + 1e-9)) + 1;
  std::vector<uint8_t> left, right;
  for (size_t f = 0; f < frames; ++f) {
    const int64_t offset = static_cast<int64_t>(f) * period_ns;
    RenderStereo(r, static_cast<double>(offset) * 1e-9, f, &left, &right);
    CAIRN_RETURN_IF_ERROR((*writer)->AddStereo(mission_.start + Duration::Nanoseconds(offset), left, right,
                                               robot.stereo.left.intrinsics.width,
                                               robot.stereo.left.intrinsics.height));
    if (progress) progress(static_cast<double>(frames_before + f + 1) / static_cast<double>(frames_total));
  }
  CAIRN_RETURN_IF_ERROR((*writer)->Close());

  if (robot.kind == SimRobotKind::kRover) {
    const WheelCanStream stream = WheelStream(r);
    const std::string path = dir + "/can0.log";
    FILE* f = std::fopen(path.c_str(), "w");
    if (f == nullptr) return IoError(path + ": cannot create");
    for (const TimedCanFrame& fr : stream.frames) {
      std::fprintf(f, "%s\n", FormatCandumpLine(fr.time, mission_.can.interface, fr.frame).c_str());
    }
    if (std::ferror(f) || std::fclose(f) != 0) return IoError(path + ": write failed");
  }
  return Status::Ok();
}

}  // namespace cairn::sim
