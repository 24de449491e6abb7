#include "mapping/depth_projector.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "mapping/testing/mapping_test_scenes.h"

namespace cairn {
namespace {

TEST(DepthImageTest, FromFixedPointDisparity) {
  // f b = 1080 * 0.09 = 97.2: 16 px -> 6.075 m; 1/16 px units; 0 -> beyond range; INT16_MIN invalid.
  const int16_t d[4] = {16 * 16, 16 * 32 + 8, 0, std::numeric_limits<int16_t>::min()};
  auto img = DepthImage::FromDisparity(d, 2, 2, 1080.0, 0.09);
  ASSERT_TRUE(img.ok());
  EXPECT_FLOAT_EQ(img->depth[0], static_cast<float>(97.2 / 16.0));
  EXPECT_FLOAT_EQ(img->depth[1], static_cast<float>(97.2 / 32.5));
  EXPECT_TRUE(std::isinf(img->depth[2]));
  EXPECT_TRUE(std::isnan(img->depth[3]));
  EXPECT_FALSE(DepthImage::FromDisparity(d, 3, 2, 1080.0, 0.09).ok());
  EXPECT_FALSE(DepthImage::FromDisparity(d, 2, 2, 0.0, 0.09).ok());
}

TEST(DepthImageTest, ValidateNamesTheProblem) {
  DepthImage img;
  img.width = 2;
  img.height = 1;
  img.depth = {1.0f, -2.0f};
  const Status s = img.Validate();
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("(1, 0)"), std::string::npos) << s.message();
}

TEST(DepthProjectorTest, PointsCarryEquation52ErrorAndRespectTheErrorLimit) {
  StereoCamera cam = testing::RoverCamera(0.25);
  DepthPointOptions o;
  o.max_depth_error = 0.15;
  DepthProjector proj(o, cam);
  // f = 270 px at this scale: the 0.15 m limit is at sqrt(0.15 * 24.3 / (0.5 sqrt 2)) = 2.27 m.
  EXPECT_NEAR(proj.range(), std::sqrt(0.15 * 270.0 * 0.09 / (0.5 * std::sqrt(2.0))), 1e-9);
  DepthImage img;
  img.width = cam.intrinsics.width;
  img.height = cam.intrinsics.height;
  img.depth.assign(static_cast<size_t>(img.width * img.height), 2.0f);
  img.depth[5] = 3.0f;                                     // beyond the error limit
  img.depth[6] = std::numeric_limits<float>::quiet_NaN();  // invalid
  img.depth[7] = 0.1f;                                     // closer than min_depth
  Eigen::Isometry3d T_local_body = Eigen::Isometry3d::Identity();
  T_local_body.translation() = Eigen::Vector3d(1, 2, 3);
  CameraPoints pts;
  ASSERT_TRUE(proj.Project(img, T_local_body, &pts).ok());
  EXPECT_EQ(pts.size(), static_cast<size_t>(img.width * img.height - 3));
  const double expected = 0.5 * 4.0 * std::sqrt(2.0) / (270.0 * 0.09);  // eq. 5.2c at 2 m
  for (size_t i = 0; i < pts.size(); i += 97) {
    EXPECT_NEAR(pts.depth_error[i], expected, 1e-6);
    EXPECT_NEAR(pts.p_cam[i].z(), 2.0f, 1e-6);
    EXPECT_TRUE((pts.p_local[i] - pts.p_cam[i] - Eigen::Vector3f(1, 2, 3)).norm() < 1e-5);
  }
  // The pixel beyond range becomes a free-space ray end at the range limit (stride 4: pixel 4
  // of row 0 is on the grid, pixel 5 is not).
  EXPECT_TRUE(pts.far_local.empty());
  img.depth[4] = std::numeric_limits<float>::infinity();
  ASSERT_TRUE(proj.Project(img, Eigen::Isometry3d::Identity(), &pts).ok());
  ASSERT_EQ(pts.far_local.size(), 1u);
  EXPECT_NEAR(pts.far_local[0].norm(), proj.range(), 1e-4);
}

}  // namespace
}  // namespace cairn
