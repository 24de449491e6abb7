#pragma once
// What the team exchange hands the graph thread: one item of a teammate's log, decoded into plain
// structs (the pipeline never sees the wire). Frames are the teammate's local frames (its submap
// origins); poses and covariances follow the conventions of the teammate's own filter.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "common/timestamp.h"
#include "estimation/graph/pose_graph.h"
#include "hal/gnss_fix.h"
#include "mapping/matching/four_dof_transform.h"
#include "mapping/submap.h"

namespace cairn {

// Graph indices of frames and poses carry the robot run (incarnation) they belong to in their top
// bits, so that a robot's runs, before and after a restart, never share a variable: run 0 is this
// robot's current run, run k + 1 any robot's incarnation k as the exchange hands it over.
inline constexpr int kRunShift = 40;
inline constexpr uint32_t kCurrentRun = 0;
constexpr uint64_t RunIndex(uint32_t incarnation, uint64_t local) {
  return (static_cast<uint64_t>(incarnation + 1) << kRunShift) | local;
}
constexpr uint32_t RunOfIndex(uint64_t index) { return static_cast<uint32_t>(index >> kRunShift); }
constexpr uint32_t IncarnationOfRun(uint32_t run) { return run - 1; }
constexpr uint64_t LocalIndex(uint64_t index) { return index & ((uint64_t{1} << kRunShift) - 1); }
// How outputs name a robot's run before its latest: ".run<incarnation>".
inline std::string EarlierRunSuffix(uint32_t run) { return ".run" + std::to_string(IncarnationOfRun(run)); }

struct TeamPose {
  Timestamp time;
  uint64_t frame = 0;
  Eigen::Isometry3d T_frame_body = Eigen::Isometry3d::Identity();
};

struct TeamGraphPose {
  uint64_t pose_index = 0;
  TeamPose pose;
  Matrix6d covariance = Matrix6d::Zero();  // [position; rotation], the filter's
};

// A submap match c between two origins (of one robot or two): B in A, with the matcher's
// (x, y, z, yaw) covariance in A's axes.
struct TeamMatch {
  std::string robot_a;
  char letter_a = 0;  // graph letters (from the team file)
  uint32_t incarnation_a = 0;  // the robots' runs (on the wire; decoded frames include them)
  uint64_t frame_a = 0;
  std::string robot_b;
  char letter_b = 0;
  uint32_t incarnation_b = 0;
  uint64_t frame_b = 0;
  FourDofTransform T_a_b;
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Identity();
  double tilt_sigma = 0.0;
};

// A robot detection d (a teammate's tag seen, thesis 6.2, eq. 4.7) or a landmark observation o
// (the lander's): the observed carrier's body frame in the observer's body frame at the image's
// exposure time, with its covariance [translation; rotation vector], a right perturbation of T
// (translation in the observed carrier's axes, as the graph's residual takes it).
struct TeamDetection {
  Timestamp time;
  std::string observer;  // robot names
  char observer_letter = 0;
  uint32_t observer_run = kCurrentRun;  // which of the observer's runs saw it (see RunIndex)
  std::string observed;  // a robot's name or a landmark's
  char observed_letter = 0;  // 0 for landmarks and robots not in the team
  bool landmark = false;
  int tag_id = -1;
  Eigen::Isometry3d T_observer_observed = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Identity();
  // IPPE's other minimum, when it found two (same covariance): the graph takes it instead where
  // only it agrees with both robots' gravity.
  bool has_alternative = false;
  Eigen::Isometry3d T_observer_observed_alternative = Eigen::Isometry3d::Identity();
  double distance = 0.0;    // m, camera to tag
  double view_angle = 0.0;  // rad, tag normal to the line of sight
};

// A GNSS fix of a robot's antenna (at `antenna` in its body frame), during its run `run`.
struct TeamGnssFix {
  char letter = 0;
  uint32_t run = kCurrentRun;
  GnssFix fix;
  Eigen::Vector3d antenna = Eigen::Vector3d::Zero();
};

// Who observed a landmark and who named it: submap `frame` of `observer`, and `creator`'s submap
// `creator_frame`, whose face or edge first observed it (both landmark kinds).
struct TeamLandmarkNames {
  std::string observer;               // robot names
  char observer_letter = 0;           // graph letters (from the team file)
  uint32_t observer_incarnation = 0;  // the runs (on the wire; decoded frames include them)
  uint64_t frame = 0;
  std::string creator;
  char creator_letter = 0;
  uint32_t creator_incarnation = 0;
  uint64_t creator_frame = 0;
};

// A plane landmark observation o: submap `frame` of `observer` saw the landmark named by its first
// observation (plane `plane` of `creator`'s submap `creator_frame`), measured in the submap's
// gravity-aligned frame as normal . p + offset = 0, with `covariance` that of (a, b, d) in
// SubmapPlane's tangent axes, and `centroid` (in the submap's frame) where the landmark is placed
// when this observation creates it.
struct TeamPlaneObservation : TeamLandmarkNames {
  uint32_t observer_plane = 0;  // index in the observer's submap
  uint32_t plane = 0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;  // m
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  // rad, rad, m
};

// A line landmark observation o, as TeamPlaneObservation for straight edges: edge `observer_line`
// of the submap, the line through `point` (the edge's middle, in the submap's gravity-aligned
// frame) along unit `direction`, with `covariance` that of line_factors.h's error (rad, rad, m,
// m); the landmark is named by edge `line` of `creator`'s submap `creator_frame`.
struct TeamLineObservation : TeamLandmarkNames {
  uint32_t observer_line = 0;
  uint32_t line = 0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Identity();
};

struct TeamInput {
  enum class Kind : uint8_t {
    kRunStart,
    kFrameSwitch,
    kPoses,
    kSubmap,
    kMatch,
    kAttempt,
    kDetection,
    kGnssFix,
    kPlaneObservations,
    kLineObservations
  };
  Kind kind = Kind::kRunStart;
  std::string robot;   // the item's origin
  char letter = 0;     // its graph letter (from the team file)
  // kFrameSwitch: the new origin in the old one; covariance with its translation in the old
  // frame's axes, as the filter states it.
  uint64_t old_frame = 0;
  uint64_t new_frame = 0;
  Eigen::Isometry3d T_old_new = Eigen::Isometry3d::Identity();
  Matrix6d switch_covariance = Matrix6d::Zero();
  Timestamp time;
  // kPoses
  std::vector<TeamPose> poses;
  std::vector<TeamGraphPose> graph_poses;
  // kSubmap (its frame index in new_frame)
  std::shared_ptr<const Submap> submap;
  // kMatch and kAttempt (then only the pair and `matched`)
  TeamMatch match;
  bool matched = false;
  std::string outcome;
  // kDetection
  TeamDetection detection;
  // kGnssFix
  TeamGnssFix gnss;
  // kPlaneObservations: one robot's decisions for one of its submaps
  std::vector<TeamPlaneObservation> planes;
  // kLineObservations: the same for straight edges
  std::vector<TeamLineObservation> lines;
};

}  // namespace cairn
