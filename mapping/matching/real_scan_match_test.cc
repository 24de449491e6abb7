// Submap matching on real geometry: crops of a real outdoor laser scan (OctoMap's scan.dat), each
// seen from its own gravity-aligned origin, must match to the transform between those origins.

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mapping/matching/submap_feature_extractor.h"
#include "common/angles.h"
#include "mapping/matching/submap_matcher.h"
#include "mapping/testing/real_scan.h"
#include "mapping/testing/rock_field_scene.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

class RealScanMatchTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string path = testing::DataDir() + "/octomap/scan.dat.bz2";
    CAIRN_REQUIRE_PATH(path);
    if (scan_ == nullptr) {
      scan_ = new std::vector<Eigen::Vector3d>(testing::ReadBzip2Scan(path));
      obstacle_ = new std::vector<bool>(testing::HeightGridObstacles(*scan_));
    }
    ASSERT_GT(scan_->size(), 80000u) << path;
  }

  static SubmapFeatures Features(const Eigen::AlignedBox2d& xy, const Eigen::Isometry3d& T_world_submap) {
    const auto submap = testing::ScanSubmap(*scan_, *obstacle_, {xy, T_world_submap});
    return SubmapFeatureExtractor().Extract(*submap);
  }

  static std::vector<Eigen::Vector3d>* scan_;
  static std::vector<bool>* obstacle_;
};
std::vector<Eigen::Vector3d>* RealScanMatchTest::scan_ = nullptr;
std::vector<bool>* RealScanMatchTest::obstacle_ = nullptr;

TEST_F(RealScanMatchTest, OverlappingCropsMatchToTheirRelativePose) {
  struct Case {
    Eigen::AlignedBox2d a, b;
    Eigen::Isometry3d T_world_a, T_world_b;
  };
  const std::vector<Case> cases = {
      {Eigen::AlignedBox2d(Eigen::Vector2d(0, -12), Eigen::Vector2d(14, 12)),
       Eigen::AlignedBox2d(Eigen::Vector2d(6, -12), Eigen::Vector2d(27, 12)),
       testing::YawPose(0.3, {2.0, 1.0, 0.0}), testing::YawPose(-0.8, {12.0, -2.0, 0.3})},
      {Eigen::AlignedBox2d(Eigen::Vector2d(0, -15), Eigen::Vector2d(27, 3)),
       Eigen::AlignedBox2d(Eigen::Vector2d(0, -4), Eigen::Vector2d(27, 17)),
       testing::YawPose(2.9, {5.0, -6.0, -0.2}), testing::YawPose(-2.5, {9.0, 8.0, 0.1})},
  };
  for (const Case& c : cases) {
    const SubmapFeatures fa = Features(c.a, c.T_world_a), fb = Features(c.b, c.T_world_b);
    ASSERT_TRUE(fa.suitable()) << fa.suitability.message;
    ASSERT_TRUE(fb.suitable()) << fb.suitability.message;
    const SubmapMatchResult r = SubmapMatcher().Match(fa, fb);
    const FourDofTransform truth =
        FourDofTransform::FromIsometry(c.T_world_a.inverse() * c.T_world_b, 1e-9).value();
    std::printf("[ match   ] real scan: %s (%s); keypoints %zu / %zu; %.0f + %.0f ms features, %.0f ms match\n",
                std::string(MatchStatusName(r.status)).c_str(), r.reason.c_str(), fa.described.size(),
                fb.described.size(), fa.keypoint_ms + fa.descriptor_ms, fb.keypoint_ms + fb.descriptor_ms,
                r.times.total_ms);
    ASSERT_TRUE(r.matched()) << r.reason;
    const double dt = (r.T_a_b.translation() - truth.translation()).norm();
    const double dyaw = std::abs(WrapAngle(r.T_a_b.yaw() - truth.yaw()));
    std::printf("[ match   ] real scan: error %.4f m, %.4f deg\n", dt, dyaw / kDegree);
    EXPECT_LT(dt, 0.01);
    EXPECT_LT(dyaw, 0.1 * kDegree);
  }
}

TEST_F(RealScanMatchTest, CropsWithoutOverlapDoNotMatch) {
  const SubmapFeatures fa = Features(Eigen::AlignedBox2d(Eigen::Vector2d(0, -15), Eigen::Vector2d(10, 0)),
                                     testing::YawPose(0.4, {3.0, -5.0, 0.0}));
  const SubmapFeatures fb = Features(Eigen::AlignedBox2d(Eigen::Vector2d(0, 1), Eigen::Vector2d(10, 17)),
                                     testing::YawPose(-1.2, {4.0, 6.0, 0.0}));
  ASSERT_TRUE(fa.suitable() && fb.suitable()) << fa.suitability.message << " / " << fb.suitability.message;
  const SubmapMatchResult r = SubmapMatcher().Match(fa, fb);
  std::printf("[ match   ] real scan, disjoint: %s (%s)\n", std::string(MatchStatusName(r.status)).c_str(),
              r.reason.c_str());
  EXPECT_EQ(r.status, MatchStatus::kNoMatch);
}

}  // namespace
}  // namespace cairn
