#pragma once
// A whole simulated mission: one world, several robots moving at the same time, each robot's
// streams written as an EuRoC/ASL folder plus a candump log of its wheel CAN frames (rovers).
//
//   DIR/<robot>/mav0/{cam0,cam1,imu0,state_groundtruth_estimate0}/...
//   DIR/<robot>/can0.log      (rovers)
//   DIR/<robot>/markers.csv   marker id, size and pose in the body frame
//   DIR/landmarks.csv         static marker poses in the world frame

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/status.h"
#include "drivers/can_wheel_options.h"
#include "sim/camera_renderer.h"
#include "sim/imu_synthesizer.h"
#include "sim/sim_robot.h"
#include "sim/terrain.h"
#include "sim/wheel_can_encoder.h"
#include "sim/world_options.h"

namespace cairn::sim {

struct MissionOptions {
  // Names starting with "rover" or "hexacopter" (e.g. rover, rover2, hexacopter).
  std::vector<std::string> robots = {"rover"};
  double duration = 10.0;         // s
  double image_scale = 1.0;       // < 1 shrinks every camera (tests)
  double can_rate_hz = 100.0;
  double exposure_time = 0.004;   // s, reported with every stereo frame
  // > 1: each image averages this many instants spread over the exposure (motion blur).
  int motion_blur_samples = 1;
  // 2: RenderStereo renders the right camera on a thread of its own. Each image is computed by one
  // thread either way, so the bytes do not depend on this.
  int render_threads = 1;
  // Every robot starts in front of one of the lander's tags and sets out from there (see
  // Deployment in sim_robot.h); needs a lander in the world.
  bool deploy_from_lander = false;
  Timestamp start = Timestamp::FromNanoseconds(int64_t{1700000000} * 1000000000);
  RenderOptions render;
  CanWheelOptions can;            // frame layout of the rovers' platform controllers
};

class MissionSimulator {
 public:
  // Generates the terrain and the robots; rejects unknown robot names.
  static Expected<std::unique_ptr<MissionSimulator>> Create(const WorldOptions& world,
                                                            const MissionOptions& mission);

  const Terrain& terrain() const { return terrain_; }
  const std::vector<SimRobot>& robots() const { return robots_; }
  const std::vector<SimMarker>& landmarks() const { return landmarks_; }
  const std::vector<SimBox>& static_boxes() const { return static_boxes_; }
  // Every robot's and the lander's geometry at mission time t (seconds from the start).
  RenderScene SceneAt(double t) const;
  Eigen::Vector3d sun_direction() const;

  Timestamp start() const { return mission_.start; }
  double duration() const { return mission_.duration; }
  double exposure_time() const { return mission_.exposure_time; }
  const CanWheelOptions& can_layout() const { return mission_.can; }
  // Robot `r`'s IMU readings with ground truth, and (rovers) its wheel CAN traffic.
  std::vector<ImuTruth> ImuStream(size_t r) const;
  WheelCanStream WheelStream(size_t r) const;

  // Renders both images of robot `r` at mission time t (thread-safe: the simulator is not changed).
  void RenderStereo(size_t r, double t, uint64_t frame, std::vector<uint8_t>* left,
                    std::vector<uint8_t>* right, std::vector<float>* left_depth = nullptr) const;

  // Writes everything under `dir`; `progress` (may be empty) gets the fraction done.
  Status Write(const std::string& dir, const std::function<void(double)>& progress) const;

 private:
  MissionSimulator(const WorldOptions& world, const MissionOptions& mission);
  Status WriteRobot(size_t r, const std::string& dir, const std::function<void(double)>& progress,
                    size_t frames_before, size_t frames_total) const;

  WorldOptions world_;
  MissionOptions mission_;
  Terrain terrain_;
  std::vector<SimRobot> robots_;
  std::vector<SimMarker> landmarks_;
  std::vector<SimBox> static_boxes_;
};

}  // namespace cairn::sim
