#include "mapping/matching/gravity_shot_descriptor.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <limits>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "mapping/matching/four_dof_transform.h"
#include "mapping/matching/keypoint_extractor.h"
#include "mapping/testing/rock_field_scene.h"

namespace cairn {
namespace {

TEST(GravityShotDescriptorTest, DescriptorIsNormalizedAndNonNegative) {
  const testing::ScenePair pair = testing::OverlappingSubmaps(7, /*cast_rays=*/false);
  const SubmapKeypoints k = KeypointExtractor().VoxelKeypoints(pair.a->points());
  GravityShotDescriptor describer(pair.a->points());
  const DescribedKeypoints d = describer.ComputeAll(k.points);
  ASSERT_GT(d.size(), 200u);
  EXPECT_EQ(d.size() + static_cast<size_t>(d.dropped), k.points.size());
  for (size_t i = 0; i < d.size(); ++i) {
    double norm = 0.0;
    for (float v : d.descriptors[i]) {
      ASSERT_GE(v, 0.0f);
      norm += static_cast<double>(v) * v;
    }
    EXPECT_NEAR(norm, 1.0, 1e-4);
    EXPECT_EQ(GravityShotDescriptor::Distance(d.descriptors[i], d.descriptors[i]), 0.0f);
    EXPECT_GE(d.frames[i].support, 20);
  }
  EXPECT_GT(GravityShotDescriptor::Distance(d.descriptors[0], d.descriptors[d.size() / 2]), 0.05f);
}

// Turning the cloud about gravity turns the local frames with it and leaves the descriptors.
TEST(GravityShotDescriptorTest, InvariantToYaw) {
  const testing::ScenePair pair = testing::OverlappingSubmaps(7, /*cast_rays=*/false);
  const std::vector<CloudPoint>& cloud = pair.a->points();
  const SubmapKeypoints k = KeypointExtractor().VoxelKeypoints(cloud);
  GravityShotDescriptor base(cloud);
  const DescribedKeypoints d0 = base.ComputeAll(k.points);
  for (double yaw : {0.9, 2.5, -1.7}) {
    const Eigen::Isometry3f T = testing::YawPose(yaw, Eigen::Vector3d(3.0, -2.0, 0.5)).cast<float>();
    std::vector<CloudPoint> turned = cloud;
    for (CloudPoint& c : turned) c.p = T * c.p;
    GravityShotDescriptor describer(turned);
    int checked = 0, same = 0, same_yaw = 0;
    double worst = 0.0;
    for (size_t i = 0; i < d0.size(); ++i) {
      if (d0.frames[i].slope < 0.05f) continue;  // flat: x is arbitrary
      GravityShot d;
      GravityShotFrame f;
      ASSERT_TRUE(describer.Compute(T * d0.points[i], &d, &f));
      ++checked;
      const double dist = GravityShotDescriptor::Distance(d0.descriptors[i], d);
      worst = std::max(worst, dist);
      if (dist < 1e-3) ++same;
      if (std::abs(WrapAngle(f.yaw - d0.frames[i].yaw - yaw)) < 1e-3) ++same_yaw;
    }
    std::printf(
        "[ yaw     ] turned by %.1f rad: %d of %d descriptors within 0.001 (worst %.4f), %d frames turned by "
        "it\n",
        yaw, same, checked, worst, same_yaw);
    ASSERT_GT(checked, 200);
    EXPECT_GE(same, checked * 99 / 100);
    EXPECT_GE(same_yaw, checked * 99 / 100);
  }
}

// The 6-DoF variant's frames follow any rotation, not only a yaw; the gravity frames do not.
TEST(GravityShotDescriptorTest, FullFramesAreInvariantToAnyRotation) {
  const testing::ScenePair pair = testing::OverlappingSubmaps(7, /*cast_rays=*/false);
  const std::vector<CloudPoint>& cloud = pair.a->points();
  const SubmapKeypoints k = KeypointExtractor().VoxelKeypoints(cloud);
  GravityShotDescriptor base(cloud, {}, ShotFrame::kFull);
  const DescribedKeypoints d0 = base.ComputeAll(k.points);
  EXPECT_FALSE(d0.gravity_frames);
  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  T.linear() = (Eigen::AngleAxisf(0.9f, Eigen::Vector3f::UnitZ()) * Eigen::AngleAxisf(0.3f, Eigen::Vector3f(1, 1, 0).normalized()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3f(3.0f, -2.0f, 0.5f);
  std::vector<CloudPoint> turned = cloud;
  for (CloudPoint& c : turned) c.p = T * c.p;
  GravityShotDescriptor full(turned, {}, ShotFrame::kFull), level(turned);
  const DescribedKeypoints d_level0 = GravityShotDescriptor(cloud).ComputeAll(k.points);
  int checked = 0, same = 0, same_frame = 0, same_level = 0;
  for (size_t i = 0; i < d0.size(); ++i) {
    GravityShot d;
    GravityShotFrame f;
    if (!full.Compute(T * d0.points[i], &d, &f)) continue;
    ++checked;
    if (GravityShotDescriptor::Distance(d0.descriptors[i], d) < 1e-3) ++same;
    if ((f.axes - T.linear() * d0.frames[i].axes).cwiseAbs().maxCoeff() < 1e-3f) ++same_frame;
    GravityShot g;
    if (level.Compute(T * d0.points[i], &g) && i < d_level0.size() &&
        GravityShotDescriptor::Distance(d_level0.descriptors[i], g) < 1e-3)
      ++same_level;
  }
  std::printf("[ tilt    ] full frames: %d of %d descriptors and %d frames unchanged; gravity frames: %d\n", same,
              checked, same_frame, same_level);
  ASSERT_GT(checked, 200);
  // A few keypoints have two nearly equal axes, where the frame may flip under rounding.
  EXPECT_GE(same, checked * 95 / 100);
  EXPECT_GE(same_frame, checked * 95 / 100);
  EXPECT_LT(same_level, checked / 10);
}

// Two submaps of the same place with their own noise, voxel grid and origin: the descriptor at a
// place in A is nearest to the descriptor at the same place in B.
TEST(GravityShotDescriptorTest, SamePlaceIsNearestAcrossSubmaps) {
  const testing::ScenePair pair = testing::OverlappingSubmaps(7, /*cast_rays=*/false);
  const Eigen::Isometry3f T_b_a = pair.T_b_a().cast<float>();
  const Eigen::Isometry3f T_w_a = pair.T_world_a.cast<float>();
  const SubmapKeypoints k = KeypointExtractor().VoxelKeypoints(pair.a->points());
  GravityShotDescriptor in_a(pair.a->points()), in_b(pair.b->points());
  std::vector<GravityShot> da, db;
  std::vector<GravityShotFrame> fa, fb;
  for (const Eigen::Vector3f& p : k.points) {
    const float x_world = (T_w_a * p).x();
    if (x_world < -1.6f || x_world > 1.6f) continue;  // whole sphere seen by both
    GravityShot a, b;
    GravityShotFrame frame_a, frame_b;
    if (!in_a.Compute(p, &a, &frame_a) || !in_b.Compute(T_b_a * p, &b, &frame_b)) continue;
    da.push_back(a);
    db.push_back(b);
    fa.push_back(frame_a);
    fb.push_back(frame_b);
  }
  ASSERT_GT(da.size(), 100u);
  const double true_yaw = std::atan2(T_b_a.linear()(1, 0), T_b_a.linear()(0, 0));
  int well = 0, well_top1 = 0, top1 = 0, yaw_ok = 0;
  for (size_t i = 0; i < da.size(); ++i) {
    size_t best = 0;
    float best_d = std::numeric_limits<float>::max();
    for (size_t j = 0; j < db.size(); ++j) {
      const float d = GravityShotDescriptor::Distance(da[i], db[j]);
      if (d < best_d) {
        best_d = d;
        best = j;
      }
    }
    const bool hit = best == i;
    top1 += hit ? 1 : 0;
    if (std::abs(WrapAngle(fb[i].yaw - fa[i].yaw - true_yaw)) < 0.2) ++yaw_ok;
    // Well supported: a dense sphere with a clear horizontal direction.
    if (fa[i].support >= 60 && fa[i].slope >= 0.3f) {
      ++well;
      well_top1 += hit ? 1 : 0;
    }
  }
  std::printf(
      "[ repeat  ] %zu places: top-1 %.0f %% (well supported %d: %.0f %%), frame yaw within 0.2 rad %.0f "
      "%%\n",
      da.size(), 100.0 * top1 / static_cast<double>(da.size()), well, 100.0 * well_top1 / std::max(1, well),
      100.0 * yaw_ok / static_cast<double>(da.size()));
  ASSERT_GT(well, 50);
  EXPECT_GE(well_top1, well * 70 / 100);
}

TEST(GravityShotDescriptorTest, NonFinitePointsAndThinSupport) {
  std::vector<CloudPoint> cloud;
  for (float x = -0.3f; x <= 0.3f; x += 0.05f) {
    for (float y = -0.3f; y <= 0.3f; y += 0.05f) {
      CloudPoint c;
      c.p = Eigen::Vector3f(x, y, 0.2f * std::exp(-10.0f * (x * x + y * y)));
      c.r = 200;
      cloud.push_back(c);
    }
  }
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  CloudPoint bad;
  bad.p = Eigen::Vector3f(nan, 0.0f, 0.0f);
  cloud.push_back(bad);
  bad.p = Eigen::Vector3f(0.0f, -inf, 0.0f);
  cloud.push_back(bad);
  GravityShotDescriptor describer(cloud);
  EXPECT_EQ(describer.non_finite_points(), 2);
  EXPECT_EQ(describer.indexed_points(), cloud.size() - 2);
  GravityShot d;
  EXPECT_TRUE(describer.Compute({0.0f, 0.0f, 0.2f}, &d));
  EXPECT_FALSE(describer.Compute({5.0f, 0.0f, 0.0f}, &d));  // nothing around
  EXPECT_FALSE(describer.Compute({nan, 0.0f, 0.0f}, &d));
  const DescribedKeypoints all =
      describer.ComputeAll({{0.0f, 0.0f, 0.2f}, {5.0f, 0.0f, 0.0f}, {0.0f, inf, 0.0f}});
  EXPECT_EQ(all.size(), 1u);
  EXPECT_EQ(all.dropped, 2);
  EXPECT_EQ(all.keypoint_index[0], 0u);

  GravityShotDescriptor empty(std::vector<CloudPoint>{});
  EXPECT_FALSE(empty.Compute({0.0f, 0.0f, 0.0f}, &d));
}

// Keypoints and descriptors of a submap of about 50,000 points: median of five runs, wall clock
// and CPU time (the CPU time is the steadier figure on a shared machine).
TEST(GravityShotDescriptorTest, TimingOfKeypointsAndDescriptors) {
  testing::SceneSubmapOptions so;
  so.viewpoints = {{-4.0, -2.0, 1.5}, {-2.0, 2.0, 1.5}, {0.0, -2.0, 1.5}, {2.0, 2.0, 1.5}, {4.0, -2.0, 1.5}};
  const auto submap = testing::SceneSubmap(testing::RockField({}), Eigen::Isometry3d::Identity(), so);
  std::vector<double> wall, cpu, wall_keypoints;
  size_t keypoints = 0, described = 0;
  for (int run = 0; run < 5; ++run) {
    const std::clock_t c0 = std::clock();
    const auto t0 = std::chrono::steady_clock::now();
    const SubmapKeypoints k = KeypointExtractor().Extract(*submap);
    const auto t1 = std::chrono::steady_clock::now();
    GravityShotDescriptor describer(submap->points());
    const DescribedKeypoints d = describer.ComputeAll(k.points);
    const auto t2 = std::chrono::steady_clock::now();
    const std::clock_t c2 = std::clock();
    wall_keypoints.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    wall.push_back(std::chrono::duration<double, std::milli>(t2 - t0).count());
    cpu.push_back(1000.0 * static_cast<double>(c2 - c0) / CLOCKS_PER_SEC);
    keypoints = k.points.size();
    described = d.size();
  }
  std::sort(wall_keypoints.begin(), wall_keypoints.end());
  std::sort(wall.begin(), wall.end());
  std::sort(cpu.begin(), cpu.end());
  std::printf(
      "[ timing  ] %zu points: %zu keypoints, %zu descriptors; keypoints %.1f ms, keypoints + descriptors "
      "%.1f ms wall, %.1f ms CPU (median of 5)\n",
      submap->points().size(), keypoints, described, wall_keypoints[2], wall[2], cpu[2]);
  EXPECT_GT(described, keypoints / 2);
}

}  // namespace
}  // namespace cairn
