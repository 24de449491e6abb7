#include "mapping/matching/submap_suitability.h"

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "mapping/matching/keypoint_extractor.h"
#include "mapping/occupancy_integrator.h"
#include "mapping/testing/rock_field_scene.h"

namespace cairn {
namespace {

std::shared_ptr<const Submap> MakeSubmap(std::vector<CloudPoint> points) {
  return std::make_shared<const Submap>(SubmapMetadata{}, std::move(points),
                                        MakeOccupancyTree(SubmapOptions{}));
}

CloudPoint Point(float x, float y, float z, bool obstacle) {
  CloudPoint c;
  c.p = Eigen::Vector3f(x, y, z);
  c.r = c.g = c.b = 128;
  c.obstacle = obstacle ? 1 : 0;
  return c;
}

// Ground on a 0.05 m grid over [0, w) x [0, h).
std::vector<CloudPoint> Ground(float w, float h) {
  std::vector<CloudPoint> out;
  for (float x = 0.0f; x < w; x += 0.05f) {
    for (float y = 0.0f; y < h; y += 0.05f) out.push_back(Point(x, y, 0.0f, false));
  }
  return out;
}

// A vertical wall of obstacle points from (x0, y0) to (x1, y1), 0.6 m high.
void AddWall(float x0, float y0, float x1, float y1, std::vector<CloudPoint>* out) {
  const float len = std::hypot(x1 - x0, y1 - y0);
  for (float s = 0.0f; s <= len; s += 0.05f) {
    for (float z = 0.05f; z < 0.6f; z += 0.05f) {
      out->push_back(Point(x0 + (x1 - x0) * s / len, y0 + (y1 - y0) * s / len, z, true));
    }
  }
}

SuitabilityResult Evaluate(const Submap& submap) {
  KeypointExtractorOptions ko;
  ko.min_known_fraction = 0.0;  // these trees are empty; suitability is what is tested
  const SubmapKeypoints keypoints = KeypointExtractor(ko).Extract(submap);
  return SubmapSuitability().Check(submap, keypoints.points);
}

TEST(SubmapSuitabilityTest, EmptySubmapHasTooFewPoints) {
  const SuitabilityResult r = Evaluate(*MakeSubmap({}));
  EXPECT_EQ(r.reason, SuitabilityReason::kTooFewPoints);
  EXPECT_FALSE(r.suitable());
  EXPECT_EQ(r.points, 0);
  EXPECT_NE(r.message.find("0 points, fewer than 1000"), std::string::npos) << r.message;
  EXPECT_EQ(SuitabilityReasonName(r.reason), "too few points");
}

TEST(SubmapSuitabilityTest, PlanarGroundHasTooFewObstaclePoints) {
  const SuitabilityResult r = Evaluate(*MakeSubmap(Ground(5.0f, 5.0f)));
  EXPECT_EQ(r.reason, SuitabilityReason::kTooFewObstaclePoints) << r.message;
  EXPECT_GE(r.points, 1000);
  EXPECT_EQ(r.obstacle_points, 0);
}

TEST(SubmapSuitabilityTest, StraightWallIsALine) {
  std::vector<CloudPoint> points = Ground(6.0f, 6.0f);
  AddWall(0.5f, 0.5f, 5.0f, 4.0f, &points);  // diagonal, so no axis is special
  const SuitabilityResult r = Evaluate(*MakeSubmap(points));
  EXPECT_EQ(r.reason, SuitabilityReason::kKeypointsOnLine) << r.message;
  EXPECT_GE(r.keypoints, 50);
  EXPECT_LT(r.off_line_keypoints, 10);
}

TEST(SubmapSuitabilityTest, RowOfStonesIsALine) {
  std::vector<CloudPoint> points = Ground(8.0f, 3.0f);
  for (float x = 0.5f; x < 7.5f; x += 1.0f) {
    for (float dx = -0.15f; dx <= 0.15f; dx += 0.05f) {
      for (float dy = -0.15f; dy <= 0.15f; dy += 0.05f)
        points.push_back(Point(x + dx, 1.5f + dy, 0.2f, true));
    }
  }
  const SuitabilityResult r = Evaluate(*MakeSubmap(points));
  EXPECT_EQ(r.reason, SuitabilityReason::kKeypointsOnLine) << r.message;
}

TEST(SubmapSuitabilityTest, TwoWallsAtAnAngleAreSuitable) {
  std::vector<CloudPoint> points = Ground(6.0f, 6.0f);
  AddWall(0.5f, 0.5f, 5.0f, 0.5f, &points);
  AddWall(0.5f, 0.5f, 0.5f, 5.0f, &points);
  const SuitabilityResult r = Evaluate(*MakeSubmap(points));
  EXPECT_TRUE(r.suitable()) << r.message;
  EXPECT_GE(r.off_line_keypoints, 10);
}

TEST(SubmapSuitabilityTest, RockFieldIsSuitable) {
  testing::RockFieldOptions o;
  o.x_min = -3.0;
  o.x_max = 3.0;
  o.y_min = -3.0;
  o.y_max = 3.0;
  o.rocks = 10;
  o.boxes = 3;
  const auto submap = testing::SceneSubmap(testing::RockField(o), Eigen::Isometry3d::Identity(), {});
  const SuitabilityResult r = Evaluate(*submap);
  EXPECT_TRUE(r.suitable()) << r.message;
}

TEST(SubmapSuitabilityTest, FewKeypointsAndOneSpot) {
  const SubmapSuitability s;
  std::vector<Eigen::Vector3f> few(5, Eigen::Vector3f(1.0f, 2.0f, 0.0f));
  EXPECT_EQ(s.CheckKeypoints(few).reason, SuitabilityReason::kTooFewKeypoints);
  // A single stone: many keypoints, all within a small disc, some stacked in xy.
  std::vector<Eigen::Vector3f> stone;
  for (int i = 0; i < 40; ++i)
    stone.emplace_back(0.1f * static_cast<float>(i % 4), 0.1f * static_cast<float>(i / 10),
                       0.1f * static_cast<float>(i % 3));
  const SuitabilityResult r = s.CheckKeypoints(stone);
  EXPECT_EQ(r.reason, SuitabilityReason::kKeypointsOnLine) << r.message;
  EXPECT_EQ(r.off_line_keypoints, 0);
}

TEST(SubmapSuitabilityTest, NonFinitePointsAreSkippedAndCounted) {
  std::vector<CloudPoint> points = Ground(6.0f, 6.0f);
  AddWall(0.5f, 0.5f, 5.0f, 0.5f, &points);
  AddWall(0.5f, 0.5f, 0.5f, 5.0f, &points);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  points.push_back(Point(nan, 0.0f, 0.0f, true));
  points.push_back(Point(1.0f, inf, 0.0f, false));
  points.push_back(Point(1.0f, 1.0f, -inf, true));
  const SuitabilityResult r = Evaluate(*MakeSubmap(points));
  EXPECT_EQ(r.non_finite_points, 3);
  EXPECT_TRUE(r.suitable()) << r.message;
  std::vector<Eigen::Vector3f> keypoints(20, Eigen::Vector3f(nan, nan, nan));
  EXPECT_EQ(SubmapSuitability().CheckKeypoints(keypoints).reason, SuitabilityReason::kTooFewKeypoints);
}

TEST(SubmapSuitabilityTest, ThresholdsComeFromTheOptions) {
  SuitabilityOptions o;
  o.min_points = 10;
  o.min_obstacle_points = 0;
  o.min_off_line_keypoints = 0;
  std::vector<CloudPoint> points = Ground(1.0f, 1.0f);
  EXPECT_TRUE(SubmapSuitability(o).Check(*MakeSubmap(points), {}).suitable());
  o.min_points = 100000;
  EXPECT_EQ(SubmapSuitability(o).Check(*MakeSubmap(points), {}).reason, SuitabilityReason::kTooFewPoints);
}

}  // namespace
}  // namespace cairn
