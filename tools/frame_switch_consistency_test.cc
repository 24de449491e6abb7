#include "tools/frame_switch_consistency.h"

#include <cmath>
#include <map>

#include <gtest/gtest.h>

#include "daemon/pipeline/team_input.h"
#include "estimation/graph/slam_graph_types.h"

namespace cairn::tools {
namespace {

PoseGraphEdge Edge(uint64_t from, uint64_t to, const FourDofTransform& T,
                   const Eigen::Matrix<double, 6, 1>& sigma) {
  PoseGraphEdge e;
  e.from = from;
  e.to = to;
  e.T_from_to.t = T.translation();
  e.T_from_to.q = Eigen::Quaterniond(Eigen::AngleAxisd(T.yaw(), Eigen::Vector3d::UnitZ()));
  e.information = sigma.cwiseInverse().cwiseAbs2().asDiagonal();
  return e;
}

// A teammate's origins (run bits in the index, as a graph holds them): the error of each switch
// in the earlier origin's frame, whitened by the factor's sigmas; matches and non-consecutive
// origins are not switches.
TEST(FrameSwitchConsistencyTest, ErrorsAreWhitenedByTheFactorsCovariance) {
  const std::map<uint64_t, FourDofTransform> truth{{0, FourDofTransform(1.0, 2.0, 0.0, 0.5)},
                                                   {1, FourDofTransform(4.0, 6.0, 0.1, 0.7)},
                                                   {2, FourDofTransform(4.0, 9.0, 0.1, 0.7)}};
  const auto key = [](uint64_t i) { return VariableKey(VariableKind::kSubmap, 'c', RunIndex(0, i)); };
  const auto T = [&](uint64_t i, uint64_t j) {
    return FourDofTransform::FromIsometry(truth.at(i).ToIsometry().inverse() * truth.at(j).ToIsometry(), 1e-9)
        .value();
  };
  Eigen::Matrix<double, 6, 1> sigma;
  sigma << 0.01, 0.02, 0.03, 0.001, 0.001, 0.004;
  PoseGraph g;
  // 0 -> 1: 1 sigma off in x (the residual's, in origin 1's frame) and 2 in yaw: NEES 1 + 4.
  const FourDofTransform t01 = T(0, 1);
  const double yaw01 = t01.yaw() + 0.008;
  g.AddEdge(Edge(key(0), key(1),
                 FourDofTransform(t01.translation() - Eigen::AngleAxisd(yaw01, Eigen::Vector3d::UnitZ()) *
                                                          Eigen::Vector3d(0.01, 0.0, 0.0),
                                  yaw01),
                 sigma));
  g.AddEdge(Edge(key(1), key(2), T(1, 2), sigma));             // exact
  g.AddEdge(Edge(key(0), key(2), FourDofTransform(), sigma));  // a match, not a switch
  const std::vector<FrameSwitchError> errors =
      FrameSwitchErrors(g, [&](char robot, uint64_t i) -> std::optional<FourDofTransform> {
        if (robot != 'c' || !truth.contains(i)) return std::nullopt;
        return truth.at(i);
      });
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].robot, 'c');
  EXPECT_EQ(errors[0].from, 0u);
  EXPECT_NEAR(errors[0].nees, 5.0, 1e-6);
  EXPECT_NEAR(errors[0].error_xy, 0.01, 1e-9);
  EXPECT_NEAR(errors[0].error_yaw, 0.008, 1e-9);
  EXPECT_NEAR(errors[0].distance, 5.0, 1e-9);
  EXPECT_NEAR(errors[0].sigma_x, 0.01, 1e-12);
  EXPECT_NEAR(errors[0].sigma_yaw, 0.004, 1e-12);
  EXPECT_NEAR(errors[1].nees, 0.0, 1e-9);
  EXPECT_NEAR(errors[1].scale, 1.0, 1e-9);
  EXPECT_EQ(errors[1].from, 1u);
  // Without truth for an end, no error.
  EXPECT_TRUE(FrameSwitchErrors(g, [](char, uint64_t) { return std::nullopt; }).empty());
}

}  // namespace
}  // namespace cairn::tools
