#include "daemon/pipeline/graph_stage.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "daemon/telemetry/graph_scene_encoder.h"
#include "estimation/graph/g2o_io.h"
#include "estimation/math/local_tangent_plane.h"
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
  GraphScene::Node s0{VariableKey(VariableKind::kSubmap, 'a', 0), Eigen::Isometry3d::Identity(), Eigen::Matrix3d::Zero(), "a/s0"};
  GraphScene::Node s1{VariableKey(VariableKind::kSubmap, 'a', 1), Pose(2.0, 0.0, 0.0), Eigen::Matrix3d::Zero(), "a/s1"};
  s1.position_covariance.diagonal() << 0.04, 0.01, 0.0;  // sigmas 0.2, 0.1, 0 m
  GraphScene::Node x0{VariableKey(VariableKind::kRobotPose, 'a', 0), Pose(1.0, 0.5, 0.3), Eigen::Matrix3d::Zero(), ""};
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
  EXPECT_EQ(e.texts(1).text(), "a/s1");
}

TEST(GraphSceneEncoderTest, EachPlacedRobotsTrajectoryIsALineInItsColour) {
  GraphScene scene;
  scene.tracks = {{'a', "a", {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 1, 0)}},
                  {'b', "b.run0", {Eigen::Vector3d(5, 0, 0), Eigen::Vector3d(6, 0, 0)}}};
  GraphSceneEncoder encoder;
  foxglove::SceneUpdate u;
  ASSERT_TRUE(u.ParseFromString(encoder.Encode(Timestamp::FromNanoseconds(1), 'a', scene)));
  ASSERT_EQ(u.entities_size(), 3);
  EXPECT_EQ(u.entities(1).id(), "trajectory/a");
  EXPECT_EQ(u.entities(2).id(), "trajectory/b.run0");
  ASSERT_EQ(u.entities(1).lines_size(), 1);
  EXPECT_EQ(u.entities(1).lines(0).type(), foxglove::LinePrimitive::LINE_STRIP);
  EXPECT_EQ(u.entities(1).lines(0).points_size(), 3);
  EXPECT_NEAR(u.entities(1).lines(0).points(2).y(), 1.0, 1e-12);
  const foxglove::Color& ca = u.entities(1).lines(0).color();
  const foxglove::Color& cb = u.entities(2).lines(0).color();
  EXPECT_FALSE(ca.r() == cb.r() && ca.g() == cb.g() && ca.b() == cb.b());
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
  EXPECT_EQ(scene.origins[2].label, "a/s2");
  ASSERT_EQ(scene.tracks.size(), 1u);
  EXPECT_EQ(scene.tracks[0].name, "a");
  EXPECT_EQ(scene.tracks[0].positions.size(), 60u);
}


// A teammate's drive as the exchange hands it over: its switches and its estimates (every 5th a
// graph pose with its covariance), in batches of `batch` estimates.
std::vector<TeamInput> TeamInputsOf(const Drive& d, char letter, size_t batch) {
  std::vector<TeamInput> out;
  TeamInput poses;
  poses.kind = TeamInput::Kind::kPoses;
  poses.letter = letter;
  poses.robot = std::string(1, letter);
  uint64_t index = 0;
  const auto flush = [&] {
    if (!poses.poses.empty()) out.push_back(poses);
    poses.poses.clear();
    poses.graph_poses.clear();
  };
  for (const GraphInput& in : d.inputs) {
    if (in.kind == GraphInput::Kind::kFrameSwitch) {
      flush();
      TeamInput w;
      w.kind = TeamInput::Kind::kFrameSwitch;
      w.letter = letter;
      w.robot = poses.robot;
      w.old_frame = in.frame_switch.old_frame_id;
      w.new_frame = in.frame_switch.new_frame_id;
      w.T_old_new = in.frame_switch.transform.T_old_new;
      w.switch_covariance = in.frame_switch.transform.covariance;
      out.push_back(w);
      continue;
    }
    const TeamPose p{in.estimate.time, in.estimate.frame_id, in.estimate.T_frame_body};
    if (poses.poses.size() % 5 == 0) poses.graph_poses.push_back(TeamGraphPose{index++, p, in.estimate.pose_covariance});
    poses.poses.push_back(p);
    if (poses.poses.size() >= batch) flush();
  }
  flush();
  return out;
}

Eigen::Isometry3d Offset() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(2.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(5.0, -3.0, 0.4);
  return T;
}

// Teammate b's global trajectory (100 estimates) lies within `tolerance` of the truth.
void ExpectTeammateWhereItWas(const GraphStage& g, const Drive& b, double tolerance) {
  const Trajectory tb = g.GlobalTrajectory('b');
  ASSERT_EQ(tb.poses.size(), 100u);
  for (size_t i = 0; i < tb.poses.size(); i += 9) {
    const Eigen::Isometry3d truth = Offset() * b.T_world_body[i];
    EXPECT_LT((tb.poses[i].T_frame_body.translation() - truth.translation()).norm(), tolerance) << i;
  }
}

TeamDetection Sighting(const Drive& a, const Drive& b, size_t i, double time_shift = 0.0) {
  TeamDetection d;
  d.time = Timestamp::FromNanoseconds(int64_t{100000000} * static_cast<int64_t>(i) + std::llround(time_shift * 1e9));
  d.observer = "a";
  d.observer_letter = 'a';
  d.observed = "b";
  d.observed_letter = 'b';
  d.tag_id = 10;
  d.T_observer_observed = a.T_world_body[i].inverse() * Offset() * b.T_world_body[i];
  d.covariance = Matrix6d::Identity() * 1e-4;
  return d;
}

TEST(GraphStageTest, ADetectionTiesATeammatesFloatingSubgraphToOurs) {
  const Drive a = MakeDrive(100, 25);
  const Drive b = MakeDrive(100, 20);  // its own start is its frame: Offset() away from ours
  GraphStage g(Options(), true);
  for (const GraphInput& in : a.inputs) g.OnInput(in);
  // The detection arrives before the teammate's estimates: it waits for them.
  g.AddDetection(Sighting(a, b, 60), true, "");
  EXPECT_EQ(g.report().detections_pending, 1u);
  for (const TeamInput& in : TeamInputsOf(b, 'b', 7)) g.OnTeamInput(in);
  EXPECT_EQ(g.report().detections_pending, 0u);
  EXPECT_EQ(g.report().detections, 1u);
  ASSERT_TRUE(g.Connected('b'));
  EXPECT_EQ(g.OutsideTies('a'), 1u);
  EXPECT_EQ(g.OutsideTies('b'), 1u);
  g.Finish();
  // One sighting fixes the whole rigid subgraph: every estimate lands where it truly was.
  ExpectTeammateWhereItWas(g, b, 0.05);
  ASSERT_EQ(g.detections().size(), 1u);
  EXPECT_EQ(g.detections()[0].status, "factor");
}

// Two matches tie a teammate at once, one of them 0.22 m and 1.4 deg off (a small overlap's). The
// graph takes neither until the team screen has waited for a third opinion; then the better
// determined one ties the teammate, the other is rejected and named, and the teammate lands right.
TEST(GraphStageTest, DisagreeingFirstMatchesWithATeammateWaitAndOnlyTheRightOneTiesIt) {
  const Drive a = MakeDrive(100, 25);
  const Drive b = MakeDrive(100, 20);
  GraphStageOptions options = Options();
  options.team_matches.hold_seconds = 3.0;
  GraphStage g(options, true);
  const size_t half = 52;  // a's frames 0 and 1, up to 5 s
  for (size_t i = 0; i < half; ++i) g.OnInput(a.inputs[i]);
  for (const TeamInput& in : TeamInputsOf(b, 'b', 7)) g.OnTeamInput(in);
  ASSERT_FALSE(g.Connected('b'));
  auto match = [&](uint64_t fa, uint64_t fb, const Eigen::Isometry3d& error, double scale) {
    const Eigen::Isometry3d T = a.T_world_frame.at(fa).inverse() * Offset() * b.T_world_frame.at(fb) * error;
    bool held = false;
    const Status s =
        g.AddMatch('a', fa, 'b', fb, FourDofTransform::ProjectIsometry(T),
                   scale * Eigen::Vector4d(4e-4, 4e-4, 4e-4, 1e-5).asDiagonal().toDenseMatrix(), 0.01, &held);
    EXPECT_TRUE(s.ok()) << s.ToString();
    EXPECT_TRUE(held);
  };
  Eigen::Isometry3d wrong = Eigen::Isometry3d::Identity();
  wrong.translation() = Eigen::Vector3d(0.22, 0.0, 0.0);
  wrong.linear() =
      Eigen::AngleAxisd(1.4 * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  match(0, 0, wrong, 1.5);
  match(1, 1, Eigen::Isometry3d::Identity(), 1.0);
  EXPECT_EQ(g.report().team_matches_held, 2u);
  EXPECT_EQ(g.report().team_matches, 0u);
  EXPECT_FALSE(g.Connected('b'));
  for (size_t i = half; i < a.inputs.size(); ++i) g.OnInput(a.inputs[i]);
  const GraphStageReport r = g.report();
  EXPECT_EQ(r.team_matches_held, 0u);
  EXPECT_EQ(r.team_matches, 1u);
  EXPECT_EQ(r.team_matches_rejected, 1u);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_NE(r.errors[0].find("a/0 - b/0 disagrees with the accepted match a/1 - b/1"), std::string::npos)
      << r.errors[0];
  ASSERT_TRUE(g.Connected('b'));
  g.Finish();
  ExpectTeammateWhereItWas(g, b, 0.05);
}

// A lone first match with a teammate enters at the end of the run at the latest.
TEST(GraphStageTest, ALoneTeamMatchEntersWhenTheRunEnds) {
  const Drive a = MakeDrive(40, 25);
  const Drive b = MakeDrive(100, 20);
  GraphStage g(Options(), true);  // the shipped 30 s hold: longer than the run
  for (const GraphInput& in : a.inputs) g.OnInput(in);
  for (const TeamInput& in : TeamInputsOf(b, 'b', 7)) g.OnTeamInput(in);
  const Eigen::Isometry3d T = a.T_world_frame.at(1).inverse() * Offset() * b.T_world_frame.at(2);
  ASSERT_TRUE(g.AddMatch('a', 1, 'b', 2, FourDofTransform::ProjectIsometry(T),
                         Eigen::Matrix4d::Identity() * 1e-4, 0.01)
                  .ok());
  EXPECT_FALSE(g.Connected('b'));
  g.Finish();
  EXPECT_TRUE(g.Connected('b'));
  EXPECT_EQ(g.report().team_matches, 1u);
}

// IPPE's flip tilts the seen tag: a sighting whose rotation turns b's up 60 deg away from a's is
// taken as its other minimum when that one agrees with gravity, and refused when neither does.
TEST(GraphStageTest, ASightingAgainstGravityTakesTheOtherMinimumOrIsRefused) {
  const Drive a = MakeDrive(100, 25);
  const Drive b = MakeDrive(100, 20);
  GraphStage g(Options(), true);
  for (const GraphInput& in : a.inputs) g.OnInput(in);
  for (const TeamInput& in : TeamInputsOf(b, 'b', 10)) g.OnTeamInput(in);
  const Eigen::Isometry3d flip(
      Eigen::AngleAxisd(60 * std::numbers::pi / 180, Eigen::Vector3d(1, 1, 0).normalized()));
  TeamDetection flipped = Sighting(a, b, 40);
  flipped.has_alternative = true;
  flipped.T_observer_observed_alternative = flipped.T_observer_observed;  // the truth
  flipped.T_observer_observed = flipped.T_observer_observed * flip;
  g.AddDetection(flipped, true, "");
  TeamDetection wrong = Sighting(a, b, 60);
  wrong.has_alternative = true;
  wrong.T_observer_observed = wrong.T_observer_observed * flip;
  wrong.T_observer_observed_alternative = wrong.T_observer_observed * flip;
  g.AddDetection(wrong, true, "");
  TeamDetection single = Sighting(a, b, 70);
  single.T_observer_observed = single.T_observer_observed * flip;
  g.AddDetection(single, true, "");
  g.AddDetection(Sighting(a, b, 80), true, "");  // a good one, with no alternative
  g.Finish();
  const auto& recs = g.detections();
  ASSERT_EQ(recs.size(), 4u);
  EXPECT_EQ(recs[0].status, "factor (IPPE's other minimum: the best tilts 60.0 deg off gravity)");
  EXPECT_TRUE(recs[0].detection.T_observer_observed.isApprox(Sighting(a, b, 40).T_observer_observed, 1e-12));
  EXPECT_EQ(recs[1].status.rfind("refused: tilts 60.0 deg off the robots' gravity", 0), 0u) << recs[1].status;
  EXPECT_NE(recs[1].status.find("as does the other minimum"), std::string::npos) << recs[1].status;
  EXPECT_EQ(recs[2].status.rfind("refused: tilts 60.0 deg", 0), 0u) << recs[2].status;
  EXPECT_EQ(recs[3].status, "factor");
  EXPECT_EQ(g.report().detections, 2u);
  EXPECT_EQ(g.report().detections_flipped, 1u);
  EXPECT_EQ(g.report().detections_against_gravity, 2u);
  // The factor taken is the true one: b lands where it was, and the graph is consistent.
  const Trajectory tb = g.GlobalTrajectory('b');
  ASSERT_FALSE(tb.poses.empty());
  EXPECT_LT((tb.poses[50].T_frame_body.translation() - (Offset() * b.T_world_body[50]).translation()).norm(),
            0.05);
  EXPECT_LT(g.report().chi2, 1.0);
}

TEST(GraphStageTest, DetectionsBetweenEstimatesAreInterpolatedAndUnplaceableOnesSayWhy) {
  const Drive a = MakeDrive(100, 25);
  const Drive b = MakeDrive(100, 20);
  GraphStage g(Options(), true);
  for (const GraphInput& in : a.inputs) g.OnInput(in);
  for (const TeamInput& in : TeamInputsOf(b, 'b', 10)) g.OnTeamInput(in);
  // Half way between two estimates (the truth at that instant interpolated the same way).
  TeamDetection mid = Sighting(a, b, 33, 0.05);
  const Eigen::Isometry3d Ta = a.T_world_body[33], Tb = Offset() * b.T_world_body[33];
  const Eigen::Isometry3d Ta2 = a.T_world_body[34], Tb2 = Offset() * b.T_world_body[34];
  const auto lerp = [](const Eigen::Isometry3d& x, const Eigen::Isometry3d& y) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = 0.5 * (x.translation() + y.translation());
    T.linear() = Eigen::Quaterniond(x.linear()).slerp(0.5, Eigen::Quaterniond(y.linear())).toRotationMatrix();
    return T;
  };
  mid.T_observer_observed = lerp(Ta, Ta2).inverse() * lerp(Tb, Tb2);
  g.AddDetection(mid, true, "");
  // Before the teammate's first estimate; of a robot not in the team; refused by the stage.
  TeamDetection early = Sighting(a, b, 0, -1.0);
  g.AddDetection(early, true, "");
  TeamDetection stranger = Sighting(a, b, 40);
  stranger.observed = "rover9";
  stranger.observed_letter = 0;
  g.AddDetection(stranger, true, "");
  g.AddDetection(Sighting(a, b, 41), false, "farther than 12.0 m");
  g.Finish();
  const auto& recs = g.detections();
  ASSERT_EQ(recs.size(), 4u);
  EXPECT_EQ(recs[0].status, "factor");
  EXPECT_NE(recs[1].status.find("unplaced: no estimate of a before"), std::string::npos) << recs[1].status;
  EXPECT_NE(recs[2].status.find("rover9"), std::string::npos) << recs[2].status;
  EXPECT_EQ(recs[3].status, "refused: farther than 12.0 m");
  EXPECT_EQ(g.report().detections, 1u);
  EXPECT_EQ(g.report().detections_unplaced, 2u);
  const Trajectory tb = g.GlobalTrajectory('b');
  ASSERT_FALSE(tb.poses.empty());
  EXPECT_LT((tb.poses[50].T_frame_body.translation() - (Offset() * b.T_world_body[50]).translation()).norm(), 0.05);
  // The chi2 stays that of a consistent graph (the interpolated sighting agrees with the truth).
  EXPECT_LT(g.report().chi2, 1.0);
}

TEST(GraphStageTest, TwoRobotsSeeingTheLanderAreTiedThroughIt) {
  const Drive a = MakeDrive(100, 25);
  const Drive b = MakeDrive(100, 20);
  GraphStage g(Options(), true);
  g.SetLandmarks({"lander"});
  Eigen::Isometry3d T_world_lander = Eigen::Isometry3d::Identity();
  T_world_lander.translation() = Eigen::Vector3d(2.0, 4.0, 0.1);
  T_world_lander.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (const GraphInput& in : a.inputs) g.OnInput(in);
  for (const TeamInput& in : TeamInputsOf(b, 'b', 10)) g.OnTeamInput(in);
  const auto sees = [&](char who, const Drive& d, const Eigen::Isometry3d& T_world_start, size_t i) {
    TeamDetection s;
    s.time = Timestamp::FromNanoseconds(int64_t{100000000} * static_cast<int64_t>(i));
    s.observer = std::string(1, who);
    s.observer_letter = who;
    s.observed = "lander";
    s.landmark = true;
    s.tag_id = 200;
    s.T_observer_observed = (T_world_start * d.T_world_body[i]).inverse() * T_world_lander;
    s.covariance = Matrix6d::Identity() * 1e-4;
    return s;
  };
  g.AddDetection(sees('a', a, Eigen::Isometry3d::Identity(), 20), true, "");
  EXPECT_FALSE(g.Connected('b'));
  // The live view leaves out what the graph cannot place: b's origins, poses and trajectory.
  const auto drawn = [](const GraphScene& scene, char robot) {
    size_t n = 0;
    for (const auto& o : scene.origins) n += RobotOfVariable(o.key) == robot;
    for (const auto& t : scene.tracks) n += t.robot == robot;
    return n;
  };
  EXPECT_EQ(drawn(g.Scene(false), 'b'), 0u);
  g.AddDetection(sees('b', b, Offset(), 70), true, "");
  EXPECT_TRUE(g.Connected('b'));
  EXPECT_EQ(drawn(g.Scene(false), 'b'), 5u + 1u);  // its origins and its trajectory
  EXPECT_EQ(g.report().landmark_observations, 2u);
  EXPECT_EQ(g.OutsideTies('a'), 1u);  // each its sighting of the lander
  EXPECT_EQ(g.OutsideTies('b'), 1u);
  g.Finish();
  const Trajectory tb = g.GlobalTrajectory('b');
  ASSERT_EQ(tb.poses.size(), 100u);
  EXPECT_LT((tb.poses[70].T_frame_body.translation() - (Offset() * b.T_world_body[70]).translation()).norm(), 0.05);
  // The landmark is not a robot.
  EXPECT_EQ(g.Robots(), (std::vector<char>{'a', 'b'}));
}


// A robot's inputs as the exchange hands over its run `incarnation`: frames and pose indices carry it.
std::vector<TeamInput> OfRun(std::vector<TeamInput> inputs, uint32_t incarnation) {
  for (TeamInput& in : inputs) {
    in.old_frame = RunIndex(incarnation, in.old_frame);
    in.new_frame = RunIndex(incarnation, in.new_frame);
    for (TeamPose& p : in.poses) p.frame = RunIndex(incarnation, p.frame);
    for (TeamGraphPose& g : in.graph_poses) {
      g.pose_index = RunIndex(incarnation, g.pose_index);
      g.pose.frame = RunIndex(incarnation, g.pose.frame);
    }
  }
  return inputs;
}

// What run `run` of `observer` saw of `observed` (a robot's letter, or the lander) at estimate `i`.
TeamDetection SeenAt(size_t i, char observer, uint32_t run, const std::string& observed, const Eigen::Isometry3d& T) {
  TeamDetection d;
  d.time = Timestamp::FromNanoseconds(int64_t{100000000} * static_cast<int64_t>(i));
  d.observer = std::string(1, observer);
  d.observer_letter = observer;
  d.observer_run = run;
  d.observed = observed;
  d.landmark = observed == "lander";
  d.observed_letter = d.landmark ? 0 : observed[0];
  d.tag_id = d.landmark ? 200 : 11;
  d.T_observer_observed = T;
  d.covariance = Matrix6d::Identity() * 1e-4;
  return d;
}

TEST(GraphStageTest, ARestartedRobotsRunsStayApartAndEachIsPlacedByItsOwnSightings) {
  const Drive a = MakeDrive(100, 25);
  const Drive b = MakeDrive(100, 20);
  // b was restarted somewhere else, its clock starting over: both runs span the same times.
  Eigen::Isometry3d restart = Offset();
  restart.translation() += Eigen::Vector3d(-2.0, 1.5, 0.0);
  restart.linear() = Eigen::AngleAxisd(-1.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  GraphStage g(Options(), true);
  for (const GraphInput& in : a.inputs) g.OnInput(in);
  for (const TeamInput& in : OfRun(TeamInputsOf(b, 'b', 10), 0)) g.OnTeamInput(in);
  for (const TeamInput& in : OfRun(TeamInputsOf(b, 'b', 10), 1)) g.OnTeamInput(in);
  const uint32_t first = RunOfIndex(RunIndex(0, 0)), second = RunOfIndex(RunIndex(1, 0));
  EXPECT_EQ(g.Runs('b'), (std::vector<uint32_t>{first, second}));
  // We see b at 6 s: the run under way then is the one begun last.
  TeamDetection seen = Sighting(a, b, 60);
  seen.T_observer_observed = a.T_world_body[60].inverse() * restart * b.T_world_body[60];
  g.AddDetection(seen, true, "");
  EXPECT_TRUE(g.Connected('b'));
  EXPECT_FALSE(g.Connected('b', first));
  // b's first run saw us at 3 s (an item of that run).
  g.AddDetection(SeenAt(30, 'b', first, "a", (Offset() * b.T_world_body[30]).inverse() * a.T_world_body[30]), true, "");
  EXPECT_TRUE(g.Connected('b', first));
  EXPECT_EQ(g.report().detections, 2u);
  g.Finish();
  const Trajectory before = g.GlobalTrajectory('b', first), after = g.GlobalTrajectory('b');
  ASSERT_EQ(before.poses.size(), 100u);
  ASSERT_EQ(after.poses.size(), 100u);
  for (size_t i = 0; i < 100; i += 9) {
    EXPECT_LT((before.poses[i].T_frame_body.translation() - (Offset() * b.T_world_body[i]).translation()).norm(), 0.05) << i;
    EXPECT_LT((after.poses[i].T_frame_body.translation() - (restart * b.T_world_body[i]).translation()).norm(), 0.05) << i;
  }
  EXPECT_LT(g.report().chi2, 1.0);
}

TEST(GraphStageTest, ThisRobotsEarlierRunJoinsItsGraphAsARunOfItsOwn) {
  const Drive a = MakeDrive(100, 25);
  GraphStage g(Options(), true);
  for (const GraphInput& in : a.inputs) g.OnInput(in);
  // The run before a restart, from this robot's store, started at Offset() in today's frame.
  for (const TeamInput& in : OfRun(TeamInputsOf(a, 'a', 10), 0)) g.OnTeamInput(in);
  const uint32_t earlier = RunOfIndex(RunIndex(0, 0));
  EXPECT_EQ(g.Runs('a'), (std::vector<uint32_t>{earlier, kCurrentRun}));
  EXPECT_FALSE(g.Connected('a', earlier));
  EXPECT_TRUE(g.GlobalTrajectory('a', earlier).poses.empty());  // not guessed
  ASSERT_EQ(g.GlobalTrajectory('a').poses.size(), 100u);      // today's run, as before
  g.SetLandmarks({"lander"});
  Eigen::Isometry3d T_world_lander = Eigen::Isometry3d::Identity();
  T_world_lander.translation() = Eigen::Vector3d(2.0, 4.0, 0.1);
  for (uint32_t run : {earlier, kCurrentRun}) {
    const Eigen::Isometry3d T_world_start = run == kCurrentRun ? Eigen::Isometry3d::Identity() : Offset();
    g.AddDetection(SeenAt(40, 'a', run, "lander", (T_world_start * a.T_world_body[40]).inverse() * T_world_lander), true, "");
  }
  EXPECT_TRUE(g.Connected('a', earlier));
  g.Finish();
  const Trajectory t = g.GlobalTrajectory('a', earlier);
  ASSERT_EQ(t.poses.size(), 100u);
  EXPECT_LT((t.poses[80].T_frame_body.translation() - (Offset() * a.T_world_body[80]).translation()).norm(), 0.05);
}

// A fix of the antenna at `antenna` on a body at T_world_body, the datum at T_world_enu.
GnssFix FixOf(const Eigen::Isometry3d& T_world_body, const Eigen::Vector3d& antenna,
              const Eigen::Isometry3d& T_world_enu, const LocalTangentPlane& plane, Timestamp time) {
  const GeodeticPoint p = plane.ToGeodetic(T_world_enu.inverse() * (T_world_body * antenna));
  GnssFix fix;
  fix.time = time;
  fix.latitude = p.latitude;
  fix.longitude = p.longitude;
  fix.height = p.height;
  fix.covariance = Eigen::Matrix3d::Identity() * 0.01;
  fix.quality = GnssQuality::kDifferential;
  return fix;
}

TEST(GraphStageTest, GnssFixesStartTheDatumAndAreCountedWhenRefusedOrUnplaced) {
  const Drive d = MakeDrive(120, 25);
  GraphStageOptions o = Options();
  o.gnss.enabled = true;
  o.gnss.datum_latitude = 46.5;
  o.gnss.datum_longitude = 7.9;
  o.gnss.antenna_z = 0.5;
  GraphStage g(o, /*deterministic=*/true);
  const LocalTangentPlane plane(
      GeodeticPoint{46.5 * std::numbers::pi / 180, 7.9 * std::numbers::pi / 180, 0.0});
  Eigen::Isometry3d T_world_enu = Eigen::Isometry3d::Identity();
  T_world_enu.linear() = Eigen::AngleAxisd(-0.8, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_world_enu.translation() = Eigen::Vector3d(40.0, -25.0, 3.0);
  auto fix_at = [&](int i) {
    return FixOf(d.T_world_body[static_cast<size_t>(i)], Eigen::Vector3d(0, 0, 0.5), T_world_enu, plane,
                 Timestamp::FromNanoseconds(int64_t{100000000} * i));
  };
  GnssFix early = fix_at(0);
  early.time = early.time - Duration::Seconds(1.0);  // before the filter's first estimate
  GnssFix lost = fix_at(3);
  lost.quality = GnssQuality::kNone;
  size_t estimates = 0, fixes = 0;
  for (const GraphInput& in : d.inputs) {
    g.OnInput(in);
    if (in.kind != GraphInput::Kind::kEstimate) continue;
    if (estimates == 1) {
      g.AddGnssFix(early);
      g.AddGnssFix(lost);
    }
    // At 1 Hz, arriving a little after their time, as a receiver's do.
    if (estimates >= 3 && (estimates - 3) % 10 == 0) {
      g.AddGnssFix(fix_at(static_cast<int>(estimates) - 3));
      ++fixes;
    }
    ++estimates;
  }
  g.Finish();
  const GraphStageReport r = g.report();
  EXPECT_EQ(r.gnss_fixes, fixes + 2);
  EXPECT_EQ(r.gnss_refused, 1u);
  EXPECT_EQ(r.gnss_unplaced, 1u);
  EXPECT_TRUE(r.gnss_datum);
  EXPECT_EQ(r.gnss_factors + r.gnss_pending, fixes);
  EXPECT_GE(r.gnss_factors, fixes - 1);  // the last may wait for a later estimate
  Eigen::Isometry3d datum;
  ASSERT_TRUE(g.Datum(&datum));
  EXPECT_LT(Eigen::AngleAxisd(datum.linear().transpose() * T_world_enu.linear()).angle(), 0.01);
  EXPECT_LT((datum.translation() - T_world_enu.translation()).norm(), 0.05);
  // The fixes agree with the filter: the trajectory stays where it was.
  const Trajectory t = g.GlobalTrajectory();
  ASSERT_EQ(t.poses.size(), d.T_world_body.size());
  for (size_t i = 0; i < t.poses.size(); i += 20) {
    EXPECT_LT((t.poses[i].T_frame_body.translation() - d.T_world_body[i].translation()).norm(), 0.02) << i;
  }
  // The datum is not a robot and not a pose of the g2o graph.
  EXPECT_EQ(g.Robots(), std::vector<char>{'a'});
  const PoseGraph exported = g.ExportPoseGraph();
  for (uint64_t id : exported.ids()) EXPECT_NE(KindOfKey(id), VariableKind::kDatum);
}

// A teammate's fixes wait while its subgraph floats and they cannot place it (two fixes 1 m apart
// leave its yaw open), and enter once a sighting ties it to ours; they are of its own antenna.
TEST(GraphStageTest, ATeammatesGnssFixesWaitUntilItsSubgraphIsTied) {
  const Drive a = MakeDrive(100, 25);
  const Drive b = MakeDrive(100, 20);
  GraphStageOptions o = Options();
  o.gnss.enabled = true;
  o.gnss.datum_latitude = -20.0;
  o.gnss.datum_longitude = -68.0;
  GraphStage g(o, /*deterministic=*/true);
  const LocalTangentPlane plane(
      GeodeticPoint{-20.0 * std::numbers::pi / 180, -68.0 * std::numbers::pi / 180, 0.0});
  Eigen::Isometry3d T_world_enu = Eigen::Isometry3d::Identity();
  T_world_enu.linear() = Eigen::AngleAxisd(1.9, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_world_enu.translation() = Eigen::Vector3d(-7.0, 12.0, 0.5);
  const Eigen::Vector3d antenna_b(0.0, 0.1, 0.3);
  for (const GraphInput& in : a.inputs) g.OnInput(in);
  for (int i = 5; i < 95; i += 10) {
    g.AddGnssFix(FixOf(a.T_world_body[static_cast<size_t>(i)], Eigen::Vector3d::Zero(), T_world_enu, plane,
                       Timestamp::FromNanoseconds(int64_t{100000000} * i)));
  }
  ASSERT_TRUE(g.report().gnss_datum);
  for (const TeamInput& in : TeamInputsOf(b, 'b', 7)) g.OnTeamInput(in);
  size_t b_fixes = 0;
  for (int i = 3; i < 20; i += 10, ++b_fixes) {
    TeamInput in;
    in.kind = TeamInput::Kind::kGnssFix;
    in.robot = "b";
    in.letter = 'b';
    in.gnss.antenna = antenna_b;
    in.gnss.fix = FixOf(Offset() * b.T_world_body[static_cast<size_t>(i)], antenna_b, T_world_enu, plane,
                        Timestamp::FromNanoseconds(int64_t{100000000} * i));
    g.OnTeamInput(in);
  }
  EXPECT_EQ(g.report().gnss_team_factors, 0u);
  EXPECT_EQ(g.report().gnss_pending, b_fixes);
  g.AddDetection(Sighting(a, b, 60), true, "");
  ASSERT_TRUE(g.Connected('b'));
  g.Finish();
  const GraphStageReport r = g.report();
  EXPECT_EQ(r.gnss_team_factors, b_fixes);
  EXPECT_EQ(r.gnss_pending, 0u);
  EXPECT_EQ(r.rejected_factors, 0u);
  // b's fixes agree with the sighting: its trajectory stays where it truly was.
  ExpectTeammateWhereItWas(g, b, 0.05);
}

// Robots that never meet: a teammate's subgraph, neither matched nor seen, is placed by its own
// fixes once they fix its yaw, and lands where it truly is.
TEST(GraphStageTest, ATeammateNeverMetIsPlacedByItsGnssFixes) {
  const Drive a = MakeDrive(100, 25);
  const Drive b = MakeDrive(100, 20);
  GraphStageOptions o = Options();
  o.gnss.enabled = true;
  o.gnss.datum_latitude = 64.1;
  o.gnss.datum_longitude = -21.9;
  GraphStage g(o, /*deterministic=*/true);
  const LocalTangentPlane plane(
      GeodeticPoint{64.1 * std::numbers::pi / 180, -21.9 * std::numbers::pi / 180, 0.0});
  Eigen::Isometry3d T_world_enu = Eigen::Isometry3d::Identity();
  T_world_enu.linear() = Eigen::AngleAxisd(-2.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_world_enu.translation() = Eigen::Vector3d(3.0, 4.0, -1.0);
  for (const GraphInput& in : a.inputs) g.OnInput(in);
  for (int i = 5; i < 95; i += 10) {
    g.AddGnssFix(FixOf(a.T_world_body[static_cast<size_t>(i)], Eigen::Vector3d::Zero(), T_world_enu, plane,
                       Timestamp::FromNanoseconds(int64_t{100000000} * i)));
  }
  for (const TeamInput& in : TeamInputsOf(b, 'b', 7)) g.OnTeamInput(in);
  EXPECT_FALSE(g.Connected('b'));
  for (int i = 3; i < 95; i += 10) {
    TeamInput in;
    in.kind = TeamInput::Kind::kGnssFix;
    in.robot = "b";
    in.letter = 'b';
    in.gnss.fix = FixOf(Offset() * b.T_world_body[static_cast<size_t>(i)], Eigen::Vector3d::Zero(),
                        T_world_enu, plane, Timestamp::FromNanoseconds(int64_t{100000000} * i));
    g.OnTeamInput(in);
  }
  ASSERT_TRUE(g.Connected('b'));
  g.Finish();
  const GraphStageReport r = g.report();
  EXPECT_EQ(r.gnss_placed_subgraphs, 1u);
  EXPECT_EQ(r.gnss_pending, 0u);
  EXPECT_EQ(r.detections, 0u);
  EXPECT_EQ(r.team_matches, 0u);
  ExpectTeammateWhereItWas(g, b, 0.1);
}

}  // namespace
}  // namespace cairn
