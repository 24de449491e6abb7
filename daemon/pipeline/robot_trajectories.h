#pragma once
// The filter estimates of every robot the graph knows, by run, as the graph stage keeps them: to
// place sightings and GNSS fixes at their times and to write each robot's global trajectory; and
// the covariances of the robots' graph poses, which give a placed pose its factor's covariance.
// They grow with the mission, like the map. Not thread safe: the graph thread owns it.

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "common/timestamp.h"
#include "estimation/graph/pose_graph.h"

namespace cairn {

// A filter estimate: the body in its local frame at a time.
struct PlacedEstimate {
  Timestamp time;
  uint64_t frame_id = 0;
  Eigen::Isometry3d T_frame_body = Eigen::Isometry3d::Identity();
};

class RobotTrajectories {
 public:
  // `own`: this robot's graph letter, whose current run (kCurrentRun) is always one of its runs.
  explicit RobotTrajectories(char own) : own_(own) {}

  // Estimates and graph-pose covariances come in time order per robot and run. This robot's
  // current run is its own; a teammate's item never adds to it.
  void AddOwnEstimate(const PlacedEstimate& e) { own_estimates_.push_back(e); }
  void AddTeamEstimate(char robot, uint32_t run, const PlacedEstimate& e) {
    estimates_[{robot, run}].push_back(e);
  }
  void AddPoseCovariance(char robot, uint32_t run, Timestamp time, uint64_t frame_id,
                         const Matrix6d& covariance) {
    pose_covariances_[{robot, run}].push_back(PoseCovariance{time, frame_id, covariance});
  }

  // Null when the graph has none of that run.
  const std::vector<PlacedEstimate>* Estimates(char robot, uint32_t run) const;
  // This robot's current run (never null).
  const std::vector<PlacedEstimate>& Own() const { return own_estimates_; }
  // The runs of `robot` with estimates, oldest first (this robot's current run last).
  std::vector<uint32_t> Runs(char robot) const;
  uint32_t LatestRun(char robot) const;
  // The run of `robot` that was under way at `time`: of those started by then, the latest.
  uint32_t RunAt(char robot, Timestamp time) const;

  enum class Lookup { kReady, kWait, kNever };
  // `robot`'s pose at `time` in its frame (interpolated between estimates of one frame) and the
  // covariance of its nearest graph pose of that frame: kWait until estimates and graph poses
  // cover the time, kNever with `why` when they never will (a gap, a frame switch, none before).
  Lookup PoseAt(char robot, uint32_t run, Timestamp time, PlacedEstimate* pose, Matrix6d* covariance,
                std::string* why) const;

  // Heap bytes held.
  size_t bytes() const;

 private:
  using RunKey = std::pair<char, uint32_t>;
  struct PoseCovariance {
    Timestamp time;
    uint64_t frame_id = 0;
    Matrix6d covariance = Matrix6d::Zero();
  };
  char own_;
  std::vector<PlacedEstimate> own_estimates_;
  std::map<RunKey, std::vector<PlacedEstimate>> estimates_;  // every run but this robot's current one
  std::map<RunKey, std::vector<PoseCovariance>> pose_covariances_;
};

}  // namespace cairn
