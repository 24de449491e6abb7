#include "daemon/pipeline/graph_stage.h"

#include <cmath>

#include <gtest/gtest.h>

#include "daemon/telemetry/graph_scene_encoder.h"
#include "estimation/graph/g2o_io.h"
#include "foxglove/SceneUpdate.pb.h"

namespace cairn {
namespace {

Eigen::Isometry3d Pose(double x, double y, double yaw, double z = 0.0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
               Eigen::AngleAxisd(0.05 * std::sin(3 * x), Eigen::Vector3d::UnitX()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

// The robot drives an arc; the filter switches its frame every `per_frame` estimates, the new
// frame being the robot's pose then with roll and pitch removed (as the filter's switch does).
struct Drive {
  std::vector<GraphInput> inputs;
  std::vector<Eigen::Isometry3d> T_world_body;  // per estimate
  std::map<uint64_t, Eigen::Isometry3d> T_world_frame;
};

Drive MakeDrive(int estimates, int per_frame) {
  Drive d;
  uint64_t frame = 0;
  d.T_world_frame[0] = Eigen::Isometry3d::Identity();
  Matrix6d estimate_cov = Matrix6d::Zero();
  for (int i = 0; i < estimates; ++i) {
    const double s = 0.1 * i;
    const Eigen::Isometry3d T = Pose(3.0 * std::sin(s / 3.0), 3.0 * (1.0 - std::cos(s / 3.0)), s / 3.0, 0.01 * i);
    if (i > 0 && i % per_frame == 0) {
      Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
      origin.translation() = T.translation();
      origin.linear() = Eigen::AngleAxisd(s / 3.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      GraphInput in;
      in.kind = GraphInput::Kind::kFrameSwitch;
      in.frame_switch.old_frame_id = frame;
      in.frame_switch.new_frame_id = frame + 1;
      in.frame_switch.transform.T_old_new = d.T_world_frame[frame].inverse() * origin;
      Matrix6d c = Matrix6d::Zero();  // roll and pitch rows zero: singular, as the filter's
      c.diagonal() << 1e-4, 1e-4, 4e-4, 0.0, 0.0, 1e-5;
      in.frame_switch.transform.covariance = c;
      d.inputs.push_back(in);
      d.T_world_frame[++frame] = origin;
      estimate_cov.setZero();  // the new frame starts where the robot is
    }
    estimate_cov.diagonal().array() += 1e-6;
    GraphInput in;
    in.kind = GraphInput::Kind::kEstimate;
    in.estimate.valid = true;
    in.estimate.time = Timestamp::FromNanoseconds(int64_t{100000000} * i);
    in.estimate.frame_id = frame;
    in.estimate.T_frame_body = d.T_world_frame[frame].inverse() * T;
    in.estimate.pose_covariance = estimate_cov;
    d.inputs.push_back(in);
    d.T_world_body.push_back(T);
  }
  return d;
}

GraphStageOptions Options() {
  GraphStageOptions o;
  o.enabled = true;
  o.pose_every = 5;
  return o;
}

TEST(GraphStageTest, ChainOfFrameSwitchesPlacesEveryEstimate) {
  const Drive d = MakeDrive(120, 25);
  GraphStage g(Options(), /*deterministic=*/true);
  for (const GraphInput& in : d.inputs) g.OnInput(in);
  g.Finish();
  const GraphStageReport r = g.report();
  EXPECT_EQ(r.estimates, 120u);
  EXPECT_EQ(r.frame_switches, 4u);
  EXPECT_EQ(r.submap_origins, 5u);
  EXPECT_EQ(r.robot_poses, 24u);
  EXPECT_EQ(r.factors, 1u + 4u + 24u);
  EXPECT_EQ(r.rejected_factors, 0u);
  EXPECT_EQ(r.unplaced, 0u);
  EXPECT_EQ(r.unconnected_variables, 0u);
  EXPECT_LT(r.chi2, 1e-12);  // consistent measurements: nothing to trade off

  const auto origins = g.FrameOrigins();
  ASSERT_EQ(origins.size(), 5u);
  for (const auto& [id, T] : origins) {
    EXPECT_LT((T.matrix() - d.T_world_frame.at(id).matrix()).norm(), 1e-9) << "frame " << id;
  }
  const Trajectory t = g.GlobalTrajectory();
  EXPECT_EQ(t.frame, "global");
  ASSERT_EQ(t.poses.size(), 120u);
  for (size_t i = 0; i < t.poses.size(); ++i) {
    EXPECT_LT((t.poses[i].T_frame_body.matrix() - d.T_world_body[i].matrix()).norm(), 1e-9) << i;
  }
}

// A match's covariance is stated in A's frame. Between origins turned 90 deg apart, a match that
// is sure along A's x and unsure along A's y must move the solution along A's x only.
TEST(GraphStageTest, AMatchIsWeightedInTheAxesOfItsFirstSubmap) {
  GraphStage g(Options(), /*deterministic=*/true);
  GraphInput e;
  e.kind = GraphInput::Kind::kEstimate;
  e.estimate.valid = true;
  e.estimate.time = Timestamp::FromSeconds(1.0);
  e.estimate.frame_id = 0;
  e.estimate.pose_covariance = Matrix6d::Identity() * 1e-6;
  g.OnInput(e);
  Eigen::Isometry3d T_0_1 = Eigen::Isometry3d::Identity();
  T_0_1.translation() = Eigen::Vector3d(2.0, 1.0, 0.0);
  T_0_1.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  GraphInput w;
  w.kind = GraphInput::Kind::kFrameSwitch;
  w.frame_switch.time = Timestamp::FromSeconds(2.0);
  w.frame_switch.old_frame_id = 0;
  w.frame_switch.new_frame_id = 1;
  w.frame_switch.transform.T_old_new = T_0_1;
  Matrix6d c = Matrix6d::Zero();
  c.diagonal() << 0.01, 0.01, 0.01, 0.0, 0.0, 1e-4;
  w.frame_switch.transform.covariance = c;
  g.OnInput(w);
  e.estimate.time = Timestamp::FromSeconds(3.0);
  e.estimate.frame_id = 1;
  g.OnInput(e);
  // The match says 0.1 m further along A's x (sure) and 0.1 m along A's y (unsure).
  const FourDofTransform match(2.1, 1.1, 0.0, M_PI / 2);
  const Eigen::Matrix4d covariance = Eigen::Vector4d(1e-6, 1.0, 1e-4, 1e-6).asDiagonal();
  ASSERT_TRUE(g.AddMatch(0, 1, match, covariance, 0.01).ok());
  g.Finish();
  const auto origins = g.FrameOrigins();
  const Eigen::Vector3d t = (origins.at(0).inverse() * origins.at(1)).translation();
  EXPECT_NEAR(t.x(), 2.1, 0.005);  // the match's sure axis
  EXPECT_NEAR(t.y(), 1.0, 0.005);  // the odometry's, the match being unsure there
}

// The filter states a switch's position error in the old frame: sure along the old x, unsure
// along the old y. The new origin, turned 90 deg, must carry that uncertainty along the old
// (here world) axes.
TEST(GraphStageTest, ASwitchIsWeightedInTheAxesOfTheOldFrame) {
  GraphStage g(Options(), /*deterministic=*/true);
  GraphInput e;
  e.kind = GraphInput::Kind::kEstimate;
  e.estimate.valid = true;
  e.estimate.time = Timestamp::FromSeconds(1.0);
  e.estimate.frame_id = 0;
  e.estimate.pose_covariance = Matrix6d::Identity() * 1e-6;
  g.OnInput(e);
  GraphInput w;
  w.kind = GraphInput::Kind::kFrameSwitch;
  w.frame_switch.time = Timestamp::FromSeconds(2.0);
  w.frame_switch.old_frame_id = 0;
  w.frame_switch.new_frame_id = 1;
  w.frame_switch.transform.T_old_new = Eigen::Isometry3d(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  w.frame_switch.transform.T_old_new.translation() = Eigen::Vector3d(3.0, 0.0, 0.0);
  Matrix6d c = Matrix6d::Zero();
  c.diagonal() << 1e-4, 1e-2, 1e-4, 0.0, 0.0, 1e-6;
  w.frame_switch.transform.covariance = c;
  g.OnInput(w);
  const std::vector<OriginEstimate> origins = g.OriginEstimates(/*covariances=*/true);
  ASSERT_EQ(origins.size(), 2u);
  const OriginEstimate& o = origins[1].frame_id == 1 ? origins[1] : origins[0];
  ASSERT_TRUE(o.has_covariance);
  EXPECT_NEAR(o.covariance(0, 0), 1e-4, 2e-5);  // world x = old x: sure
  EXPECT_NEAR(o.covariance(1, 1), 1e-2, 2e-4);  // world y = old y: unsure
}

TEST(GraphStageTest, ExportedGraphReadsBackAsG2o) {
  const Drive d = MakeDrive(60, 20);
  GraphStage g(Options(), true);
  for (const GraphInput& in : d.inputs) g.OnInput(in);
  g.Finish();
  const PoseGraph exported = g.ExportPoseGraph();
  PoseGraph back;
  ASSERT_TRUE(ParseG2o(FormatG2o(exported), "graph.g2o", back).ok());
  EXPECT_EQ(back.num_vertices(), 3u + 12u);
  EXPECT_EQ(back.edges().size(), 2u + 12u);  // the prior is not a g2o edge
  const uint64_t s1 = VariableKey(VariableKind::kSubmap, 'a', 1);
  ASSERT_TRUE(back.HasVertex(s1));
  EXPECT_LT((back.poses()[back.Find(s1)].t - d.T_world_frame.at(1).translation()).norm(), 1e-6);
}

TEST(GraphStageTest, LateEstimatesUseTheirOwnFrameAndLostInputsAreCountedNotGuessed) {
  Drive d = MakeDrive(60, 20);
  // An estimate of frame 0 that the estimation thread emitted after the first switch.
  auto first_switch = std::find_if(d.inputs.begin(), d.inputs.end(),
                                   [](const GraphInput& in) { return in.kind == GraphInput::Kind::kFrameSwitch; });
  ASSERT_NE(first_switch, d.inputs.end());
  std::iter_swap(first_switch, first_switch - 1);
  // A switch out of a frame the graph never saw, and an estimate in it.
  GraphInput lost;
  lost.kind = GraphInput::Kind::kFrameSwitch;
  lost.frame_switch.old_frame_id = 7;
  lost.frame_switch.new_frame_id = 8;
  d.inputs.push_back(lost);
  GraphInput orphan = d.inputs.front();
  orphan.estimate.frame_id = 8;
  d.inputs.push_back(orphan);

  GraphStage g(Options(), true);
  for (const GraphInput& in : d.inputs) g.OnInput(in);
  g.Finish();
  const GraphStageReport r = g.report();
  EXPECT_EQ(r.unplaced, 2u);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_NE(r.errors[0].find("7 -> 8"), std::string::npos) << r.errors[0];
  const Trajectory t = g.GlobalTrajectory();
  ASSERT_EQ(t.poses.size(), 60u);
  for (size_t i = 0; i < t.poses.size(); ++i) {
    EXPECT_LT((t.poses[i].T_frame_body.matrix() - d.T_world_body[i].matrix()).norm(), 1e-9) << i;
  }
}

TEST(GraphStageTest, BadCovarianceIsRejectedAndTheGraphGoesOn) {
  Drive d = MakeDrive(30, 100);
  d.inputs[5].estimate.pose_covariance(2, 2) = std::nan("");  // the 6th estimate: a robot pose (pose_every 5)
  GraphStage g(Options(), true);
  for (const GraphInput& in : d.inputs) g.OnInput(in);
  g.Finish();
  const GraphStageReport r = g.report();
  EXPECT_EQ(r.rejected_factors, 1u);
  EXPECT_EQ(r.robot_poses, 5u);
  EXPECT_EQ(g.GlobalTrajectory().poses.size(), 30u);
}

TEST(GraphSceneEncoderTest, OriginsAreTwoSigmaEllipsoidsAndFactorsAreLines) {
  GraphScene scene;
  GraphScene::Node s0{VariableKey(VariableKind::kSubmap, 'a', 0), Eigen::Isometry3d::Identity(), Eigen::Matrix3d::Zero()};
  GraphScene::Node s1{VariableKey(VariableKind::kSubmap, 'a', 1), Pose(2.0, 0.0, 0.0), Eigen::Matrix3d::Zero()};
  s1.position_covariance.diagonal() << 0.04, 0.01, 0.0;  // sigmas 0.2, 0.1, 0 m
  GraphScene::Node x0{VariableKey(VariableKind::kRobotPose, 'a', 0), Pose(1.0, 0.5, 0.3), Eigen::Matrix3d::Zero()};
  scene.origins = {s0, s1};
  scene.poses = {x0};
  scene.edges = {{s0.key, s1.key, FactorKind::kFrameSwitch}, {s0.key, x0.key, FactorKind::kFilterEstimate}};
  GraphSceneEncoder encoder;
  foxglove::SceneUpdate u;
  ASSERT_TRUE(u.ParseFromString(encoder.Encode(Timestamp::FromNanoseconds(1500000000), 'a', scene)));
  ASSERT_EQ(u.entities_size(), 1);
  const foxglove::SceneEntity& e = u.entities(0);
  EXPECT_EQ(e.id(), "graph/a");
  EXPECT_EQ(e.frame_id(), "map");
  EXPECT_EQ(e.timestamp().seconds(), 1);
  EXPECT_EQ(e.timestamp().nanos(), 500000000);
  ASSERT_EQ(e.spheres_size(), 3);
  // s1: diameters of 4 sigma along the eigenvectors (any order), the unknown axis at the minimum.
  std::vector<double> d = {e.spheres(1).size().x(), e.spheres(1).size().y(), e.spheres(1).size().z()};
  std::sort(d.begin(), d.end());
  EXPECT_NEAR(d[0], 0.05, 1e-12);
  EXPECT_NEAR(d[1], 0.4, 1e-12);
  EXPECT_NEAR(d[2], 0.8, 1e-12);
  EXPECT_NEAR(e.spheres(1).pose().position().x(), 2.0, 1e-12);
  ASSERT_EQ(e.lines_size(), 2);
  EXPECT_EQ(e.lines(0).type(), foxglove::LinePrimitive::LINE_LIST);
  EXPECT_EQ(e.lines(0).points_size(), 2);  // the frame switch
  EXPECT_EQ(e.lines(1).points_size(), 2);  // the pose factor
  EXPECT_NEAR(e.lines(1).points(1).y(), 0.5, 1e-12);
  ASSERT_EQ(e.texts_size(), 2);
  EXPECT_EQ(e.texts(1).text(), "s1");
}

TEST(GraphStageTest, SceneShowsEveryVariableAndBinaryFactor) {
  const Drive d = MakeDrive(60, 20);
  GraphStage g(Options(), true);
  for (const GraphInput& in : d.inputs) g.OnInput(in);
  const GraphScene scene = g.Scene(/*covariances=*/true);
  EXPECT_EQ(scene.origins.size(), 3u);
  EXPECT_EQ(scene.poses.size(), 12u);
  EXPECT_EQ(scene.edges.size(), 2u + 12u);
  // The first origin holds the prior: known to its floor; later ones less well.
  EXPECT_LT(scene.origins[0].position_covariance.trace(), scene.origins[2].position_covariance.trace());
  EXPECT_GT(scene.origins[2].position_covariance.trace(), 0.0);
}

}  // namespace
}  // namespace cairn
