#pragma once
// Turns one robot's local reference filter output into SLAM-graph factors in either topology of
// thesis Fig. 4.2, so both can be built from the same data and compared:
//  - kFilter (Fig. 4.2b): frame switches w between submap origins s_i -> s_i+1, and each robot
//    pose the graph needs as a filter estimate v from the current submap origin (no independence
//    assumption inside a submap).
//  - kSequential (Fig. 4.2a): robot poses chained by odometry u_i = x_i+1 (-) x_i (eq. 4.8) with
//    Sigma_u = max(Sigma_x_i+1 - Sigma_x_i, 1e-10 I) (eq. 4.9, max taken on the eigenvalues of the
//    difference); submap origins are the robot poses at the frame switches. Sigma_x is the filter
//    covariance accumulated along the frame switches (first order, frames' rotations ignored).

#include <vector>

#include "estimation/graph/slam_graph.h"

namespace cairn {

class TopologyBuilder {
 public:
  enum class Topology { kFilter, kSequential };
  TopologyBuilder(Topology topology, char robot);

  // Factors for the first submap (the prior when `own`, with the given information).
  std::vector<SlamFactor> Start(bool own, const Matrix6d& prior_information);
  // The filter switched its reference frame: `T_old_new` is the new origin in the old one.
  std::vector<SlamFactor> FrameSwitch(const Pose3& T_old_new, const Matrix6d& covariance);
  // A robot pose the graph needs (detection, landmark): the filter's estimate in its current
  // submap with covariance. Writes the new pose variable's key.
  std::vector<SlamFactor> PoseEstimate(const Pose3& T_s_x, const Matrix6d& covariance, uint64_t* key);
  // The variable standing for submap `index` (a robot pose in the sequential topology).
  uint64_t SubmapKey(uint64_t index) const;
  uint64_t current_submap() const { return submap_; }

 private:
  std::vector<SlamFactor> ChainTo(const Pose3& T_odom_x, const Matrix6d& cov, uint64_t* key);

  Topology topology_;
  char robot_;
  uint64_t submap_ = 0;
  uint64_t next_pose_ = 0;
  std::vector<uint64_t> submap_keys_;  // sequential: the robot pose of each submap origin
  // Sequential: dead-reckoned origin of the current submap and its accumulated covariance, and
  // the last chained robot pose.
  Pose3 T_odom_s_;
  Matrix6d cov_s_ = Matrix6d::Zero();
  uint64_t last_key_ = 0;
  Pose3 last_pose_;
  Matrix6d last_cov_ = Matrix6d::Zero();
};

}  // namespace cairn
