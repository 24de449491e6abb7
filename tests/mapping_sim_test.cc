// Mapping against the simulator's ground truth: obstacle cells vs. the true terrain's steps,
// occupied voxels vs. the true surface, and a partitioned submap chain re-composed.

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <utility>

#include <gtest/gtest.h>

#include "mapping/local_mapper.h"
#include "mapping/map_composer.h"
#include "sim/obstacle_ground_truth.h"
#include "sim/surface_distance.h"
#include "sim/testing/sim_depth_scenes.h"

namespace cairn {
namespace {

using testing::ForwardCameraPose;

constexpr double kTilt = 25.0 * 3.14159265358979 / 180.0;

sim::Terrain World() {
  sim::WorldOptions w;
  w.size = 40.0;
  w.seed = 11;
  w.lander.clear();
  return sim::Terrain::Generate(w);
}

// What `cairn bench map` drives through: the default world without its lander (the landing site
// moves the big crater away and reshuffles the boulders the drive was laid out among).
sim::WorldOptions BenchMapWorld() {
  sim::WorldOptions w;
  w.lander.clear();
  return w;
}

DepthImage Render(const sim::Terrain& terrain, const StereoCamera& cam, const Eigen::Isometry3d& T_world_cam, unsigned seed) {
  return testing::RenderSimulatedDepth(terrain, cam, T_world_cam, seed, 0.2);
}

Eigen::Isometry3d CameraAt(const sim::Terrain& t, double x, double y, double yaw) {
  return ForwardCameraPose({x, y, t.Height(x, y) + 1.3}, yaw, kTilt);
}

struct SwitchRecorder : FrameSwitchRequesterInterface {
  int requests = 0;
  void RequestFrameSwitch(const FrameSwitchRequest&) override { ++requests; }
};

// Gravity-aligned frame at a pose's position and yaw (what the filter switches into).
Eigen::Isometry3d YawFrame(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d fwd = T.linear().col(0);
  Eigen::Isometry3d F = Eigen::Isometry3d::Identity();
  F.linear() = Eigen::AngleAxisd(std::atan2(fwd.y(), fwd.x()), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  F.translation() = T.translation();
  return F;
}

// A drive of 11 m with the distance criterion at 4 m: the partitioner asks for switches, the test
// plays the filter (switching into the body's position and yaw, with a drift of 0.5 % of the
// distance in the local poses), and the submap chain composed along the filter's frame-switch
// transforms (no loop closures) lies on the true surface within one voxel plus the drift.
TEST(MappingSimTest, PartitionedSubmapChainRecomposesToGroundTruth) {
  const sim::Terrain terrain = World();
  StereoCamera cam = testing::RoverCamera(0.5);
  // Body frame = x forward, z up at the camera mast; camera pitched down.
  cam.T_body_cam = ForwardCameraPose(Eigen::Vector3d::Zero(), 0.0, kTilt);
  MappingOptions o;
  o.partition.max_distance = 4.0;
  SwitchRecorder rec;
  LocalMapper mapper(o, cam, "rover1", &rec);
  const double drift = 0.005;
  uint64_t frame = 1;
  Eigen::Isometry3d T_world_frame_true = Eigen::Isometry3d::Identity();  // true pose of the local frame
  Eigen::Isometry3d T_world_frame_est = Eigen::Isometry3d::Identity();   // chained from the filter
  double dist_in_frame = 0.0;
  std::vector<std::pair<std::shared_ptr<const Submap>, Eigen::Isometry3d>> chain;
  Eigen::Vector3d last(0, 0, 0);
  bool first = true;
  for (int i = 0; i <= 44; ++i) {
    const double s = 0.25 * i;
    const double x = -5.0 + s, y = 1.5 * std::sin(0.25 * s), yaw = std::atan(1.5 * 0.25 * std::cos(0.25 * s));
    Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
    T_world_body.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T_world_body.translation() = Eigen::Vector3d(x, y, terrain.Height(x, y) + 1.3);
    if (first) {
      T_world_frame_true = T_world_frame_est = YawFrame(T_world_body);
      first = false;
    } else {
      dist_in_frame += (T_world_body.translation() - last).norm();
    }
    last = T_world_body.translation();
    // The filter's local pose: true relative pose plus drift along the local x axis.
    Eigen::Isometry3d T_local_body = T_world_frame_true.inverse() * T_world_body;
    T_local_body.translation().x() += drift * dist_in_frame;
    const int before = rec.requests;
    MappingPose pose;
    pose.time = Timestamp::FromSeconds(s);
    pose.frame_id = frame;
    pose.T_local_body = T_local_body;
    pose.position_covariance = Eigen::Matrix3d::Identity() * 1e-4;
    ASSERT_TRUE(mapper.Process(Render(terrain, cam, T_world_body * cam.T_body_cam, 100 + i), pose).ok());
    if (rec.requests > before) {
      // Switch into the body's estimated position and yaw in the old frame.
      const Eigen::Isometry3d T_old_new = YawFrame(T_local_body);
      auto done = mapper.OnFrameSwitch(frame + 1, T_old_new);
      ASSERT_NE(done, nullptr);
      chain.emplace_back(done, T_world_frame_est);
      T_world_frame_est = T_world_frame_est * T_old_new;
      T_world_frame_true = YawFrame(T_world_body);
      ++frame;
      dist_in_frame = 0.0;
    }
  }
  EXPECT_EQ(rec.requests, 2);
  ASSERT_EQ(chain.size(), 2u);
  MapComposer composer(o.composition, o.submap);
  for (const auto& [submap, T] : chain) ASSERT_TRUE(composer.SetSubmap(submap, T).ok());
  composer.SetOpenSubmap(&mapper.open_submap(), T_world_frame_est);
  composer.Update();
  const auto tree = composer.Octree();
  const sim::SurfaceDistance surface(terrain);
  int64_t occupied = 0, near = 0;
  // One voxel plus the largest drift (4 m x 0.5 % per frame, two frames chained so far).
  const double bound = o.submap.octree_resolution + 3 * 4.0 * drift;
  for (auto it = tree->begin_leafs(); it != tree->end_leafs(); ++it) {
    if (!tree->isNodeOccupied(*it)) continue;
    const octomap::point3d c = it.getCoordinate();
    ++occupied;
    near += surface.Distance(Eigen::Vector3d(c.x(), c.y(), c.z()), bound) <= bound;
  }
  std::printf("composed occupied voxels %ld, within %.3f m of the surface %.2f %%\n", static_cast<long>(occupied), bound,
              100.0 * static_cast<double>(near) / static_cast<double>(occupied));
  EXPECT_GT(occupied, 3000);
  EXPECT_GE(static_cast<double>(near), 0.95 * static_cast<double>(occupied));
}

// Single submap with exact poses: occupied voxels lie within one voxel of the true surface.
TEST(MappingSimTest, OccupiedVoxelsLieOnTheTrueSurface) {
  const sim::Terrain terrain = World();
  const StereoCamera cam = testing::RoverCamera(1.0);
  MappingOptions o;
  SwitchRecorder rec;
  LocalMapper mapper(o, cam, "rover1", &rec);
  for (int i = 0; i < 12; ++i) {
    const Eigen::Isometry3d T = CameraAt(terrain, 2.0 + 0.3 * i, -3.0 + 0.1 * i, 1.2);
    MappingPose pose;
    pose.frame_id = 1;
    pose.T_local_body = T;
    ASSERT_TRUE(mapper.Process(Render(terrain, cam, T, 7 + i), pose).ok());
  }
  const auto submap = mapper.OnFrameSwitch(2, Eigen::Isometry3d::Identity());
  ASSERT_NE(submap, nullptr);
  const sim::SurfaceDistance surface(terrain);
  const double voxel = submap->tree().getResolution();
  int64_t occupied = 0, near = 0;
  for (auto it = submap->tree().begin_leafs(); it != submap->tree().end_leafs(); ++it) {
    if (!submap->tree().isNodeOccupied(*it)) continue;
    const octomap::point3d c = it.getCoordinate();
    ++occupied;
    near += surface.Distance(Eigen::Vector3d(c.x(), c.y(), c.z()), voxel) <= voxel;
  }
  std::printf("occupied voxels %ld, within one voxel of the surface %.2f %%\n", static_cast<long>(occupied),
              100.0 * static_cast<double>(near) / static_cast<double>(occupied));
  EXPECT_GT(occupied, 2000);
  EXPECT_GE(static_cast<double>(near), 0.95 * static_cast<double>(occupied));
  // The cloud points carry the classifier's obstacle flags.
  EXPECT_GT(submap->points().size(), 10000u);
}

// The hexacopter's view (f 350 px, b 0.12 m, 60 deg down, 3.5 m up, flying 0.2 m per image):
// ground at 4-4.5 m, where one image's eq. 5.2c error is 3-4 voxels. Fused depth images whose
// points enter the map only within 0.1 m of error lie on the surface where single images pile up
// voxels below it, and still cover most of the ground.
struct FlightMapScore {
  int64_t occupied = 0, near = 0;
  size_t columns = 0;  // distinct 0.1 m ground cells under an occupied voxel
  double near_fraction() const { return static_cast<double>(near) / static_cast<double>(std::max<int64_t>(occupied, 1)); }
};

FlightMapScore MapFlight(const sim::Terrain& terrain, const MappingOptions& o) {
  StereoCamera cam;
  cam.intrinsics.width = 384;
  cam.intrinsics.height = 240;
  cam.intrinsics.fx = cam.intrinsics.fy = 350.0;
  cam.intrinsics.cx = 191.5;
  cam.intrinsics.cy = 119.5;
  cam.baseline = 0.12;
  SwitchRecorder rec;
  LocalMapper mapper(o, cam, "hexacopter1", &rec);
  for (int i = 0; i < 30; ++i) {
    const double x = -4.0 + 0.2 * i, y = 2.0 + 0.05 * i;
    const Eigen::Isometry3d T = ForwardCameraPose({x, y, terrain.Height(x, y) + 3.5}, 0.25, 60.0 * M_PI / 180.0);
    MappingPose pose;
    pose.frame_id = 1;
    pose.T_local_body = T;
    // 0.25 px per image coordinate, what SGM achieves on the simulated images.
    EXPECT_TRUE(mapper.Process(testing::RenderSimulatedDepth(terrain, cam, T, 40 + i, 0.25 * std::sqrt(2.0)), pose).ok());
  }
  const auto submap = mapper.FinishOpenSubmap();
  FlightMapScore score;
  if (submap == nullptr) return score;
  const sim::SurfaceDistance surface(terrain);
  const octomap::OcTree& tree = submap->tree();
  std::set<std::pair<int, int>> columns;
  for (auto it = tree.begin_leafs(tree.getTreeDepth()); it != tree.end_leafs(); ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const octomap::point3d c = it.getCoordinate();
    ++score.occupied;
    score.near += surface.Distance(Eigen::Vector3d(c.x(), c.y(), c.z()), tree.getResolution()) <= tree.getResolution();
    columns.insert({static_cast<int>(std::floor(c.x() * 10.0)), static_cast<int>(std::floor(c.y() * 10.0))});
  }
  score.columns = columns.size();
  return score;
}

TEST(MappingSimTest, FusedDepthKeepsTheHexacoptersGroundThin) {
  const sim::Terrain terrain = World();
  MappingOptions single;
  single.depth.max_depth_error = 0.35;  // configs/hexacopter.yaml
  MappingOptions fused = single;
  fused.fusion.enabled = true;
  fused.depth.max_map_error = 0.1;
  const FlightMapScore a = MapFlight(terrain, single), b = MapFlight(terrain, fused);
  std::printf("hexacopter view: single images %ld occupied voxels, %.1f %% within one voxel, %zu columns; fused %ld, "
              "%.1f %%, %zu columns\n",
              static_cast<long>(a.occupied), 100.0 * a.near_fraction(), a.columns, static_cast<long>(b.occupied),
              100.0 * b.near_fraction(), b.columns);
  // Measured: single images 29.5 %, fused 94.0 % with 54 % of the columns (the far ground, where
  // 30 images do not bring the error under 0.1 m, only clears free space).
  EXPECT_GT(a.columns, 1000u);
  EXPECT_LT(a.near_fraction(), 0.5);
  EXPECT_GE(b.near_fraction(), 0.9);
  EXPECT_GE(static_cast<double>(b.columns), 0.45 * static_cast<double>(a.columns));
}

// Every fourth image of the drive of `cairn bench map` (default world without its lander, 7 m,
// 0.2 px disparity noise): obstacle cells against the true terrain (sim/obstacle_ground_truth.h).
TEST(MappingSimTest, ObstacleCellsMatchTheTrueTerrain) {
  const sim::Terrain terrain = sim::Terrain::Generate(BenchMapWorld());
  const StereoCamera cam = testing::RoverCamera(1.0);
  MappingOptions o;
  DepthProjector projector(o.depth, cam);
  ObstacleClassifier classifier(o.obstacles, cam, projector.error_model(), projector.range());
  CameraPoints pts;
  ObstacleResult result;
  testing::ObstacleScore score, fixed_band;
  const int images = 44;
  for (int i = 0; i < images; i += 4) {
    const double s = 7.0 * i / (images - 1);
    const double x = -8.0 + s, y = 3.0 + std::sin(0.3 * s), yaw = std::atan(0.3 * std::cos(0.3 * s));
    const Eigen::Isometry3d T = ForwardCameraPose({x, y, terrain.Height(x, y) + 1.3}, yaw, kTilt);
    const DepthImage img = testing::RenderSimulatedDepth(terrain, cam, T, static_cast<unsigned>(i + 1), 0.2);
    ASSERT_TRUE(projector.Project(img, T, &pts).ok());
    ASSERT_TRUE(classifier.Classify(img, &pts, &result).ok());
    score.Add(testing::ScoreObstacles(terrain, result, o.obstacles, T, projector.error_model()));
    fixed_band.Add(testing::ScoreObstacles(terrain, result, o.obstacles, T, projector.error_model(), 0.03, false));
  }
  std::printf("obstacle cells vs ground truth: precision %.3f recall %.3f (tp %lld fp %lld fn %lld, %lld unscored: within "
              "the stereo error of h_max, or undetectable edges, %lld of them steep hidden drops whose visible ends are "
              "not (eq. 5.1); %lld misses are hidden drops only); with a fixed 0.03 m band instead: precision %.3f recall "
              "%.3f (tp %lld fp %lld fn %lld)\n",
              score.precision(), score.recall(), static_cast<long long>(score.tp), static_cast<long long>(score.fp),
              static_cast<long long>(score.fn), static_cast<long long>(score.unscored),
              static_cast<long long>(score.unscored_hidden), static_cast<long long>(score.fn_edge_only),
              fixed_band.precision(), fixed_band.recall(),
              static_cast<long long>(fixed_band.tp), static_cast<long long>(fixed_band.fp),
              static_cast<long long>(fixed_band.fn));
  EXPECT_GT(score.tp, 50);
  EXPECT_GE(score.precision(), 0.95);
  EXPECT_GE(fixed_band.precision(), 0.95);
  EXPECT_GE(score.recall(), 0.90);  // the recall target
  EXPECT_GE(fixed_band.recall(), 0.45);
}

}  // namespace
}  // namespace cairn
