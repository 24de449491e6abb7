#pragma once
// One simulated robot: its sensors' true calibration, its C2 trajectory through the world and the
// geometry other robots' cameras see (body boxes and AprilTag-style markers).

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "hal/calibration.h"
#include "sim/bspline_trajectory.h"
#include "sim/terrain.h"

namespace cairn::sim {

enum class SimRobotKind { kRover, kHexacopter };

// A square fiducial: 10 x 10 modules (white quiet ring, black border ring, 6 x 6 data bits),
// `size` is the edge of the black border square. z of the marker frame points out of the face.
struct SimMarker {
  int id = 0;  // tag36h11 id
  double size = 0.16;
  uint64_t bits = 0;  // 36 data bits, row-major from the marker's top-left
  Eigen::Isometry3d T_body_marker = Eigen::Isometry3d::Identity();
};

struct SimBox {
  Eigen::Isometry3d T_body_box = Eigen::Isometry3d::Identity();
  Eigen::Vector3d half_extent = Eigen::Vector3d::Constant(0.1);
  float albedo = 0.3f;
};

struct SimRobot {
  std::string name;
  SimRobotKind kind = SimRobotKind::kRover;
  StereoCalibration stereo;     // T_body_cam: body frame = IMU frame
  ImuCalibration imu;
  double camera_rate_hz = 10.0;
  BSplineTrajectory trajectory;
  std::vector<SimMarker> markers;
  std::vector<SimBox> boxes;
  // Wheel contact points in the body frame (rover only).
  std::vector<Eigen::Vector3d> wheels;
};

// Where robots start when the mission deploys them from the lander: each in front of one of the
// lander's four tags (its own face, nearest the way to its path), seeing it while it initializes,
// then it turns and goes onto its path where the path passes nearest the lander.
struct Deployment {
  bool enabled = false;
  Eigen::Vector2d lander = Eigen::Vector2d::Zero();
  double lander_ground = 0.0;  // terrain height at the lander
  // Towards the sun, horizontal: robots prefer sunlit faces (a tag in the shadow has little contrast).
  Eigen::Vector2d sun = Eigen::Vector2d::UnitX();
  unsigned taken_faces = 0;    // bit k: face k (outward normal at k * 90 deg) is a rover's
};

// LRU-like rover (1024 x 508, f = 1080 px, b = 0.09 m; MTi-10 IMU) driving a seeded loop.
// `image_scale` shrinks the cameras (tests); `index` separates robots of one mission.
SimRobot MakeRover(const Terrain& terrain, const std::string& name, int index, uint64_t seed,
                   double duration, double image_scale, double tag_size, Deployment* deployment = nullptr);
// A tag lying flat on a rover's rear deck, facing up (id 10 * index + 3): what a multicopter above
// sees of it. The deck is 0.9 m x 0.7 m, so `size` (the tag's black square) is at most 0.4 m.
void AddRoofTag(int index, double size, SimRobot* rover);
// Ardea-like hexacopter: stereo pair (666 x 506, b = 0.12 m) pitched 60 deg down, 400 Hz IMU.
SimRobot MakeHexacopter(const Terrain& terrain, const std::string& name, int index, uint64_t seed,
                        double duration, double image_scale, double tag_size, Deployment* deployment = nullptr);

}  // namespace cairn::sim
