#include "stereo/disparity_evaluator.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "stereo/pfm_io.h"
#include "stereo/stereo_image_io.h"
#include "tests/support/scoped_temp_dir.h"

namespace cairn {
namespace {

const float kInf = std::numeric_limits<float>::infinity();

TEST(PfmIoTest, RoundTripKeepsValuesRowOrderAndInfinity) {
  FloatImage img{3, 2, {1.5f, 2.25f, kInf, -4.0f, 0.0f, 1e6f}};
  const testing::ScopedTempDir temp("pfm_rt");
  const std::string path = temp.path() + "/rt.pfm";
  ASSERT_TRUE(WritePfm(path, img).ok());
  auto back = ReadPfm(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->width, 3);
  EXPECT_EQ(back->height, 2);
  EXPECT_EQ(back->data, img.data);
  // Middlebury stores the bottom row first.
  std::ifstream f(path, std::ios::binary);
  std::string header((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  ASSERT_GE(header.size(), 12u);
  EXPECT_EQ(header.rfind("Pf\n3 2\n-1", 0), 0u);
  float first;
  std::memcpy(&first, header.data() + header.size() - 24, 4);
  EXPECT_EQ(first, -4.0f);
}

TEST(PfmIoTest, ReportsBadFiles) {
  const testing::ScopedTempDir temp("pfm_bad");
  EXPECT_EQ(ReadPfm(temp.path() + "/missing.pfm").status().code(), StatusCode::kNotFound);
  const std::string path = temp.path() + "/bad.pfm";
  {
    std::ofstream f(path);
    f << "P6\n2 2\n255\n";
  }
  EXPECT_EQ(ReadPfm(path).status().code(), StatusCode::kDataLoss);
  {
    std::ofstream f(path, std::ios::binary);
    f << "Pf\n4 4\n-1.0\n" << "abcd";  // 4 of 64 bytes
  }
  EXPECT_EQ(ReadPfm(path).status().code(), StatusCode::kDataLoss);
  EXPECT_FALSE(WritePfm(path, FloatImage{2, 2, {1.0f}}).ok());
  EXPECT_FALSE(WritePfm("/nonexistent-dir/x.pfm", FloatImage{1, 1, {1.0f}}).ok());
}

TEST(DisparityEvaluatorTest, CountsBadAndMissingPixels) {
  // Ground truth 10 everywhere except one unknown pixel; mask marks one pixel occluded.
  FloatImage truth{4, 1, {10.0f, 10.0f, 10.0f, kInf}};
  FloatImage estimate{4, 1, {10.4f, 12.0f, kInf, 3.0f}};
  FloatImage mask{4, 1, {255.0f, 255.0f, 128.0f, 255.0f}};
  auto s = DisparityEvaluator::Score(estimate, truth, mask, DisparityMetric::kBad1);
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s->scored_nonocc, 2);
  EXPECT_EQ(s->scored_all, 3);
  EXPECT_DOUBLE_EQ(s->bad_nonocc, 0.5);      // 12 is off by 2
  EXPECT_DOUBLE_EQ(s->bad_all, 2.0 / 3.0);   // and the missing estimate counts as bad
  EXPECT_DOUBLE_EQ(s->density, 0.75);
  s = DisparityEvaluator::Score(estimate, truth, mask, DisparityMetric::kBad4);
  EXPECT_DOUBLE_EQ(s->bad_nonocc, 0.0);
  // KITTI D1 needs both 3 px and 5 %.
  FloatImage far_truth{2, 1, {100.0f, 20.0f}};
  FloatImage far_est{2, 1, {104.0f, 23.5f}};
  s = DisparityEvaluator::Score(far_est, far_truth, FloatImage{}, DisparityMetric::kD1);
  ASSERT_TRUE(s.ok());
  EXPECT_DOUBLE_EQ(s->bad_all, 0.5);
}

TEST(DisparityEvaluatorTest, ScoresTheGivenEstimatesApartFromTheMissingOnes) {
  FloatImage truth{5, 1, {10.0f, 10.0f, 10.0f, 10.0f, 10.0f}};
  FloatImage estimate{5, 1, {10.0f, 13.0f, kInf, kInf, 10.5f}};
  FloatImage mask{5, 1, {255.0f, 255.0f, 255.0f, 255.0f, 128.0f}};
  auto s = DisparityEvaluator::Score(estimate, truth, mask, DisparityMetric::kBad1);
  ASSERT_TRUE(s.ok());
  EXPECT_DOUBLE_EQ(s->bad_nonocc, 0.75);  // one wrong, two missing of four
  EXPECT_EQ(s->estimated_nonocc, 2);      // the occluded pixel does not count
  EXPECT_DOUBLE_EQ(s->bad_estimated, 0.5);
  s = DisparityEvaluator::Score(FloatImage{5, 1, std::vector<float>(5, kInf)}, truth, mask,
                                DisparityMetric::kBad1);
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s->estimated_nonocc, 0);
  EXPECT_DOUBLE_EQ(s->bad_estimated, 0.0);
}

TEST(DisparityEvaluatorTest, RejectsSizeMismatchAndUnknownMetric) {
  FloatImage a{2, 2, {1, 1, 1, 1}}, b{2, 1, {1, 1}};
  EXPECT_FALSE(DisparityEvaluator::Score(a, b, FloatImage{}, DisparityMetric::kBad1).ok());
  EXPECT_FALSE(DisparityEvaluator::Score(a, a, b, DisparityMetric::kBad1).ok());
  EXPECT_FALSE(ParseDisparityMetric("bad5").ok());
  EXPECT_TRUE(ParseDisparityMetric("d1").ok());
}

// KITTI's background interpolation: gaps between estimates take the farther one, the ends of a
// row its nearest, rows above the first and below the last row with estimates copy those; empty
// rows between stay missing.
TEST(DisparityEvaluatorTest, InterpolatesFromTheBackgroundAsKittiDoes) {
  const FloatImage est{6, 5, {kInf, kInf, kInf, kInf, kInf, kInf,   //
                              kInf, 9.0f, kInf, kInf, 4.0f, kInf,     //
                              kInf, kInf, kInf, kInf, kInf, kInf,     //
                              2.0f, kInf, 7.0f, 8.0f, kInf, kInf,     //
                              kInf, kInf, kInf, kInf, kInf, kInf}};
  const FloatImage out = DisparityEvaluator::InterpolateBackground(est);
  const std::vector<float> row1 = {9, 9, 4, 4, 4, 4}, row3 = {2, 2, 7, 8, 8, 8};
  for (int x = 0; x < 6; ++x) {
    EXPECT_EQ(out.at(x, 0), row1[static_cast<size_t>(x)]) << x;  // copies the first row with estimates
    EXPECT_EQ(out.at(x, 1), row1[static_cast<size_t>(x)]) << x;
    EXPECT_FALSE(std::isfinite(out.at(x, 2))) << x;               // between two rows: stays missing
    EXPECT_EQ(out.at(x, 3), row3[static_cast<size_t>(x)]) << x;
    EXPECT_EQ(out.at(x, 4), row3[static_cast<size_t>(x)]) << x;   // copies the last
  }
  const FloatImage none{3, 2, std::vector<float>(6, kInf)};
  for (float v : DisparityEvaluator::InterpolateBackground(none).data) EXPECT_FALSE(std::isfinite(v));
  // Scored after filling: the missing pixel next to a far estimate is right when it is background.
  const FloatImage truth{4, 1, {2.0f, 2.0f, 2.0f, 10.0f}};
  const FloatImage sparse{4, 1, {2.0f, kInf, kInf, 10.0f}};
  const FloatImage all{4, 1, std::vector<float>(4, 255.0f)};
  auto raw = DisparityEvaluator::Score(sparse, truth, all, DisparityMetric::kBad3);
  auto filled = DisparityEvaluator::Score(DisparityEvaluator::InterpolateBackground(sparse), truth, all,
                                          DisparityMetric::kBad3);
  ASSERT_TRUE(raw.ok() && filled.ok());
  EXPECT_DOUBLE_EQ(raw->bad_all, 0.5);
  EXPECT_DOUBLE_EQ(filled->bad_all, 0.0);
  EXPECT_EQ(*ParseDisparityMetric("bad3"), DisparityMetric::kBad3);
  EXPECT_STREQ(DisparityMetricName(DisparityMetric::kBad3), "bad3");
}

TEST(DisparityEvaluatorTest, DerivedMaskMarksPixelsHiddenBehindNearerOnes) {
  // Background disparity 2, a near object (disparity 6) at columns 6..7: background columns
  // 2..5 land on right columns 0..3 and columns 6..7 land on 0..1 too, so 2..3 are hidden.
  FloatImage truth{10, 1, {2, 2, 2, 2, 2, 2, 6, 6, 2, 2}};
  const FloatImage mask = DisparityEvaluator::DeriveNonOccludedMask(truth);
  EXPECT_EQ(mask.data[0], 128.0f);  // lands outside the right image
  EXPECT_EQ(mask.data[2], 128.0f);
  EXPECT_EQ(mask.data[3], 128.0f);
  EXPECT_EQ(mask.data[4], 255.0f);
  EXPECT_EQ(mask.data[6], 255.0f);
  EXPECT_EQ(mask.data[9], 255.0f);
}

TEST(DisparityEvaluatorTest, LoadsScaledPngGroundTruth) {
  const testing::ScopedTempDir temp("disparity_gt");
  const std::string p8 = temp.path() + "/gt8.png", p16 = temp.path() + "/gt16.png";
  cv::Mat g8(1, 3, CV_8UC1);
  g8.at<uint8_t>(0, 0) = 0;
  g8.at<uint8_t>(0, 1) = 40;
  g8.at<uint8_t>(0, 2) = 255;
  ASSERT_TRUE(cv::imwrite(p8, g8));
  auto gt = LoadGroundTruth(p8, 4.0);
  ASSERT_TRUE(gt.ok());
  EXPECT_TRUE(std::isinf(gt->data[0]));
  EXPECT_FLOAT_EQ(gt->data[1], 10.0f);
  cv::Mat g16(1, 2, CV_16UC1);
  g16.at<uint16_t>(0, 0) = 256 * 30 + 128;
  g16.at<uint16_t>(0, 1) = 0;
  ASSERT_TRUE(cv::imwrite(p16, g16));
  gt = LoadGroundTruth(p16, 0.0);  // KITTI default scale 256
  ASSERT_TRUE(gt.ok());
  EXPECT_FLOAT_EQ(gt->data[0], 30.5f);
  EXPECT_TRUE(std::isinf(gt->data[1]));
  EXPECT_EQ(LoadGroundTruth(temp.path() + "/none.png", 1.0).status().code(), StatusCode::kNotFound);
}

TEST(StereoImageIoTest, ReportsUnreadableAndMismatchedPairs) {
  const testing::ScopedTempDir temp("stereo_pair");
  const std::string a = temp.path() + "/a.png", b = temp.path() + "/b.png";
  ASSERT_TRUE(cv::imwrite(a, cv::Mat(10, 12, CV_8UC3, cv::Scalar(1, 2, 3))));
  ASSERT_TRUE(cv::imwrite(b, cv::Mat(10, 13, CV_8UC1, cv::Scalar(5))));
  auto ok = LoadGrayPair(a, a);
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(ok->left.type(), CV_8UC1);  // colour converted to gray
  auto mismatch = LoadGrayPair(a, b);
  EXPECT_EQ(mismatch.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(mismatch.status().message().find("13x10"), std::string::npos);
  EXPECT_EQ(LoadGrayPair(temp.path() + "/nope.png", a).status().code(), StatusCode::kNotFound);
  EXPECT_EQ(LoadGrayPair(a, temp.path() + "/nope.png").status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace cairn
