#include "stereo/stereo_rectifier.h"

#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "drivers/replay/euroc_dataset.h"
#include "stereo/sgm_matcher.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

StereoCalibration AlignedRig() {
  StereoCalibration c;
  for (CameraCalibration* cam : {&c.left, &c.right}) {
    cam->intrinsics.width = 64;
    cam->intrinsics.height = 48;
    cam->intrinsics.fx = cam->intrinsics.fy = 60.0;
    cam->intrinsics.cx = 31.5;
    cam->intrinsics.cy = 23.5;
  }
  c.right.T_body_cam.translation() = Eigen::Vector3d(0.1, 0, 0);
  return c;
}

TEST(StereoRectifierTest, AlignedUndistortedRigIsLeftUnchanged) {
  auto r = StereoRectifier::Create(AlignedRig());
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_NEAR(r->baseline(), 0.1, 1e-12);
  EXPECT_NEAR(r->focal_px(), 60.0, 1e-6);
  cv::Mat img(48, 64, CV_8UC1);
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 64; ++x) img.at<uint8_t>(y, x) = static_cast<uint8_t>(3 * x + 2 * y);
  }
  cv::Mat l, rr;
  ASSERT_TRUE(r->Rectify(img, img, &l, &rr).ok());
  cv::Mat diff;
  cv::absdiff(img(cv::Rect(2, 2, 60, 44)), l(cv::Rect(2, 2, 60, 44)), diff);
  double max_diff = 0;
  cv::minMaxLoc(diff, nullptr, &max_diff);
  EXPECT_LE(max_diff, 1.0);
}

TEST(StereoRectifierTest, RejectsBadCalibrationAndImages) {
  StereoCalibration c = AlignedRig();
  c.right.intrinsics.width = 65;
  EXPECT_FALSE(StereoRectifier::Create(c).ok());
  c = AlignedRig();
  c.left.intrinsics.fx = 0;
  EXPECT_FALSE(StereoRectifier::Create(c).ok());
  c = AlignedRig();
  c.right.T_body_cam.translation().setZero();
  EXPECT_FALSE(StereoRectifier::Create(c).ok());
  auto r = StereoRectifier::Create(AlignedRig());
  ASSERT_TRUE(r.ok());
  cv::Mat l, rr;
  EXPECT_FALSE(r->Rectify(cv::Mat(48, 63, CV_8UC1), cv::Mat(48, 64, CV_8UC1), &l, &rr).ok());
  EXPECT_FALSE(r->Rectify(cv::Mat(48, 64, CV_8UC3), cv::Mat(48, 64, CV_8UC1), &l, &rr).ok());
}

// Real EuRoC pair: after rectification SGM finds a dense, plausible disparity field (the scene
// is a room 2 to 6 m away: with f ~ 460 px and b = 0.11 m that is about 8 to 25 px).
TEST(StereoRectifierTest, RectifiedEurocPairMatches) {
  const std::string root = cairn::testing::EurocMicro();
  if (!std::filesystem::exists(root + "/mav0")) GTEST_SKIP() << "missing " << root;
  auto ds = EurocDataset::Open(root);
  ASSERT_TRUE(ds.ok()) << ds.status().ToString();
  ASSERT_FALSE(ds->stereo().empty());
  auto r = StereoRectifier::Create(ds->stereo_calibration());
  ASSERT_TRUE(r.ok());
  const cv::Mat left = cv::imread(ds->stereo()[0].left_path, cv::IMREAD_GRAYSCALE);
  const cv::Mat right = cv::imread(ds->stereo()[0].right_path, cv::IMREAD_GRAYSCALE);
  cv::Mat l, rr;
  ASSERT_TRUE(r->Rectify(left, right, &l, &rr).ok());
  SgmOptions o;
  o.num_disparities = 64;
  auto m = SgmMatcher::Create(o);
  ASSERT_TRUE(m.ok());
  StereoMatcherInput in;
  in.left = l.data;
  in.right = rr.data;
  in.width = l.cols;
  in.height = l.rows;
  in.stride = static_cast<int>(l.step[0]);
  in.focal_px = r->focal_px();
  in.baseline_m = r->baseline();
  StereoMatcherOutput out;
  ASSERT_TRUE((*m)->Match(in, &out).ok());
  std::vector<float> depths;
  for (float z : out.depth) {
    if (std::isfinite(z)) depths.push_back(z);
  }
  EXPECT_GT(depths.size(), out.depth.size() / 2);
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  const float median_depth = depths[depths.size() / 2];
  EXPECT_GT(median_depth, 1.0f);
  EXPECT_LT(median_depth, 8.0f);
}

}  // namespace
}  // namespace cairn
