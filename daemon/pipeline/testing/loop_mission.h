#pragma once
// A robot's loop through a rock field as the graph and the matcher see it: graph inputs with biased
// odometry, and the submap each origin saw. Shared by the matcher stage's tests.

#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include <Eigen/Geometry>

#include "daemon/pipeline/graph_stage.h"
#include "mapping/submap.h"
#include "mapping/testing/rock_field_scene.h"

namespace cairn::testing {

// A robot drives once around a circle in a rock field; its filter switches frames at `origins`
// places, and each switch's odometry carries a bias (the drift a loop closure has to remove).
// Each finished submap saw the field within kViewRadius of its origin.
// Non-consecutive origins are 4.3-5 m apart: the view must reach past half that for them to overlap.
constexpr double kViewRadius = 4.5;

struct LoopMission {
  std::vector<Eigen::Isometry3d> T_world_origin;  // truth
  std::vector<GraphInput> inputs;                  // per origin: one estimate, then the switch away
  std::vector<std::shared_ptr<const Submap>> submaps;
};

inline LoopMission MakeLoop(int origins) {
  LoopMission m;
  RockFieldOptions field;
  field.x_min = -6.0, field.x_max = 6.0, field.y_min = -6.0, field.y_max = 6.0;
  field.rocks = 45;
  field.boxes = 10;
  field.seed = 17;
  const std::vector<ScenePoint> scene = RockField(field);
  for (int k = 0; k < origins; ++k) {
    const double a = 2.0 * std::numbers::pi * k / origins;
    m.T_world_origin.push_back(
        YawPose(a + std::numbers::pi / 2, Eigen::Vector3d(2.5 * std::cos(a), 2.5 * std::sin(a), 0.3)));
  }
  Eigen::Isometry3d believed = m.T_world_origin[0];  // the chain of biased switches
  for (int k = 0; k < origins; ++k) {
    const Eigen::Isometry3d& T = m.T_world_origin[static_cast<size_t>(k)];
    GraphInput e;
    e.kind = GraphInput::Kind::kEstimate;
    e.estimate.valid = true;
    e.estimate.time = Timestamp::FromSeconds(10.0 * k + 1.0);
    e.estimate.frame_id = static_cast<uint64_t>(k);
    e.estimate.pose_covariance = Matrix6d::Identity() * 1e-6;
    m.inputs.push_back(e);
    std::vector<ScenePoint> seen;
    for (const ScenePoint& p : scene) {
      if ((p.p.head<2>() - T.translation().head<2>()).norm() < kViewRadius) seen.push_back(p);
    }
    SceneSubmapOptions so;
    so.seed = 100 + static_cast<unsigned>(k);
    so.viewpoints = {T * Eigen::Vector3d(0.0, 0.0, 1.2), T * Eigen::Vector3d(1.5, 0.0, 1.2),
                     T * Eigen::Vector3d(-1.5, 0.0, 1.2)};
    auto submap = SceneSubmap(seen, T, so);
    SubmapMetadata meta = submap->metadata();
    meta.robot = "rover";
    meta.id = static_cast<uint64_t>(k);
    m.submaps.push_back(std::make_shared<const Submap>(meta, submap->points(),
                                                       std::unique_ptr<octomap::OcTree>(new octomap::OcTree(submap->tree()))));
    if (k + 1 == origins) break;
    const Eigen::Isometry3d step = T.inverse() * m.T_world_origin[static_cast<size_t>(k + 1)];
    // Biased odometry: 3 % long and 0.03 rad too far left per switch.
    Eigen::Isometry3d measured = step;
    measured.translation() *= 1.03;
    measured.linear() = Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitZ()).toRotationMatrix() * step.linear();
    GraphInput w;
    w.kind = GraphInput::Kind::kFrameSwitch;
    w.frame_switch.time = Timestamp::FromSeconds(10.0 * k + 9.0);
    w.frame_switch.old_frame_id = static_cast<uint64_t>(k);
    w.frame_switch.new_frame_id = static_cast<uint64_t>(k + 1);
    w.frame_switch.transform.T_old_new = measured;
    Matrix6d c = Matrix6d::Zero();
    c.diagonal() << 0.01, 0.01, 0.0025, 0.0, 0.0, 0.001;  // 0.1 m, 0.05 m, 0.03 rad per switch
    w.frame_switch.transform.covariance = c;
    m.inputs.push_back(w);
    believed = believed * measured;
  }
  return m;
}

inline double OriginError(const GraphStage& graph, const LoopMission& m) {
  const auto origins = graph.FrameOrigins();
  double sum = 0.0;
  for (const auto& [id, T] : origins) {
    const Eigen::Isometry3d truth = m.T_world_origin[0].inverse() * m.T_world_origin[id];
    sum += (T.translation() - truth.translation()).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(origins.size()));
}

}  // namespace cairn::testing
