#include "tools/frame_switch_consistency.h"

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "daemon/pipeline/team_input.h"
#include "estimation/graph/slam_graph_types.h"

namespace cairn::tools {

std::vector<FrameSwitchError> FrameSwitchErrors(const PoseGraph& graph, const TrueOrigin& truth) {
  std::vector<FrameSwitchError> out;
  for (const PoseGraphEdge& e : graph.edges()) {
    if (KindOfKey(e.from) != VariableKind::kSubmap || KindOfKey(e.to) != VariableKind::kSubmap) continue;
    const char robot = RobotOfVariable(e.from);
    const uint64_t from = IndexOfVariable(e.from), to = IndexOfVariable(e.to);
    if (RobotOfVariable(e.to) != robot || to != from + 1) continue;
    const std::optional<FourDofTransform> a = truth(robot, LocalIndex(from)),
                                          b = truth(robot, LocalIndex(to));
    if (!a.has_value() || !b.has_value()) continue;
    const Eigen::LDLT<Matrix6d> info(e.information);
    if (info.info() != Eigen::Success || !(info.vectorD().array() > 0.0).all()) continue;
    const Matrix6d covariance = info.solve(Matrix6d::Identity());
    static constexpr int kAxes[4] = {0, 1, 2, 5};
    Eigen::Matrix4d c;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) c(i, j) = covariance(kAxes[i], kAxes[j]);

    const Eigen::Isometry3d T_true = a->ToIsometry().inverse() * b->ToIsometry();
    const Eigen::Matrix3d R = e.T_from_to.q.toRotationMatrix();
    Eigen::Vector4d err;
    // The factor's residual: translation in the next origin's frame (g2o's convention).
    err.head<3>() = R.transpose() * (T_true.translation() - e.T_from_to.t);
    err[3] = WrapAngle(std::atan2(R(1, 0), R(0, 0)) - (b->yaw() - a->yaw()));
    const Eigen::LDLT<Eigen::Matrix4d> marginal(c);
    if (marginal.info() != Eigen::Success) continue;

    FrameSwitchError f;
    f.robot = robot;
    f.from = LocalIndex(from);
    f.distance = T_true.translation().head<2>().norm();
    f.error_xy = err.head<2>().norm();
    f.error_yaw = std::abs(err[3]);
    if (T_true.translation().norm() > 0.0) f.scale = e.T_from_to.t.norm() / T_true.translation().norm();
    f.sigma_x = std::sqrt(c(0, 0));
    f.sigma_yaw = std::sqrt(c(3, 3));
    f.nees = err.dot(marginal.solve(err));
    out.push_back(f);
  }
  return out;
}

}  // namespace cairn::tools
