#include "detection/tag_error_model.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

namespace cairn {
namespace {

std::shared_ptr<const TagErrorTable> FlatTable(double sigma) {
  auto t = std::make_shared<TagErrorTable>("rover", 1024, 508, 1080.0, 1080.0, 0.16, 1.0, 10.0, 2, 0.0, 1.0, 2);
  t->set_corner_rms(0.25);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) t->cell(i, j).sigma.setConstant(sigma);
  return t;
}

TEST(TagErrorModelTest, NamesParseAndUnknownOnesAreRefused) {
  for (const char* name : {"combined", "propagated", "thesis", "table", "online", "constant", "quadratic"}) {
    const auto k = ParseTagErrorKind(name);
    ASSERT_TRUE(k.ok()) << name;
    EXPECT_STREQ(TagErrorKindName(*k), name);
  }
  const auto bad = ParseTagErrorKind("lut");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("combined, propagated, thesis, table"), std::string::npos);
  EXPECT_FALSE(TagErrorModel::Create(TagErrorKind::kPropagated, nullptr).ok());
  EXPECT_FALSE(TagErrorModel::Create(TagErrorKind::kCombined, nullptr).ok());
  EXPECT_FALSE(TagErrorModel::Create(TagErrorKind::kTable, std::make_shared<TagErrorTable>()).ok());
  EXPECT_FALSE(TagErrorModel::Create(TagErrorKind::kThesis, nullptr).ok());
  EXPECT_FALSE(TagErrorModel::Create(TagErrorKind::kCombined, FlatTable(0.01), 0.0).ok());
  EXPECT_TRUE(TagErrorModel::Create(TagErrorKind::kQuadratic, nullptr).ok());
  EXPECT_TRUE(TagErrorModel::Create(TagErrorKind::kOnline, nullptr).ok());
}

TEST(TagErrorModelTest, EachModelGivesItsCovariance) {
  TagPose pose;
  pose.distance = 2.0;
  pose.view_angle = 0.3;
  Eigen::Matrix<double, 6, 1> online;
  online << 0.001, 0.05, 0.001, 0.2, 0.001, 0.001;  // sigmas
  pose.covariance = online.cwiseAbs2().asDiagonal();
  const auto table = FlatTable(0.01);
  const auto cov = [&](TagErrorKind k) { return TagErrorModel::Create(k, table)->Covariance(pose, 0.16); };
  EXPECT_NEAR(cov(TagErrorKind::kConstant)(0, 0), 1e-4, 1e-12);
  EXPECT_NEAR(cov(TagErrorKind::kConstant)(5, 5), 5e-4, 1e-12);
  EXPECT_NEAR(cov(TagErrorKind::kQuadratic)(0, 0), 9e-4, 1e-12);
  EXPECT_NEAR(cov(TagErrorKind::kOnline)(1, 1), 0.05 * 0.05, 1e-12);
  EXPECT_NEAR(cov(TagErrorKind::kTable)(1, 1), 1e-4, 1e-12);
  // Combined: the spread rescaled from 0.5 px to the table's 0.25 px, its variances raised to the
  // table's; correlations kept.
  pose.sample_covariance = Matrix6d::Identity() * 0.0016;
  pose.sample_covariance(1, 1) = 0.04;
  pose.sample_covariance(0, 3) = pose.sample_covariance(3, 0) = 0.001;
  const Matrix6d m = TagErrorModel::Create(TagErrorKind::kCombined, table, 0.5)->Covariance(pose, 0.16);
  EXPECT_NEAR(m(0, 0), 4e-4, 1e-12);
  EXPECT_NEAR(m(1, 1), 0.01, 1e-12);
  EXPECT_NEAR(m(0, 3), 0.00025, 1e-12);
  pose.sample_covariance = Matrix6d::Identity() * 1e-8;  // steadier than the table: the table holds
  EXPECT_NEAR(TagErrorModel::Create(TagErrorKind::kCombined, table, 0.5)->Covariance(pose, 0.16)(2, 2), 1e-4, 1e-12);
  // Propagated: this detection's propagation J J^T, scaled so that the median coordinate matches
  // the table (1e-4 everywhere), plus 5 % of the table; correlations kept.
  pose.corner_jacobian.setZero();
  pose.corner_jacobian.col(0) << 0.01, 0.0, 0.0, 0.01, 0.0, 0.0;  // moves x and pitch together
  pose.corner_jacobian(1, 1) = 0.01;
  pose.corner_jacobian(2, 2) = pose.corner_jacobian(4, 4) = pose.corner_jacobian(5, 5) = 0.02;
  // Variances 1, 1, 4, 1, 4, 4 (x 1e-4): the table's ratios 1, 1, 0.25, 1, 0.25, 0.25; median 0.625.
  const Matrix6d p = TagErrorModel::Create(TagErrorKind::kPropagated, table)->Covariance(pose, 0.16);
  EXPECT_NEAR(p(0, 0), 0.625e-4 + 0.05e-4, 1e-13);
  EXPECT_NEAR(p(5, 5), 2.5e-4 + 0.05e-4, 1e-13);
  EXPECT_NEAR(p(0, 3), 0.625e-4, 1e-13);
  EXPECT_EQ(p(1, 2), 0.0);
  pose.corner_jacobian.setZero();  // no propagation (sampling off): the table's diagonal
  EXPECT_NEAR(TagErrorModel::Create(TagErrorKind::kPropagated, table)->Covariance(pose, 0.16)(2, 2), 1e-4, 1e-12);
  // Thesis: the larger of the two, coordinate by coordinate.
  const Matrix6d c = cov(TagErrorKind::kThesis);
  EXPECT_NEAR(c(0, 0), 1e-4, 1e-12);
  EXPECT_NEAR(c(1, 1), 0.05 * 0.05, 1e-12);
  EXPECT_NEAR(c(3, 3), 0.04, 1e-12);
  EXPECT_EQ(c(0, 1), 0.0);
  // A tag twice the size: the table's translation sigmas double at the same picture.
  EXPECT_NEAR(TagErrorModel::Create(TagErrorKind::kTable, table)->Covariance(pose, 0.32)(0, 0), 4e-4, 1e-12);
}

TEST(TagErrorModelTest, ACameraOfHalfTheResolutionLooksUpTwiceTheDistance) {
  auto t = std::make_shared<TagErrorTable>("rover", 1024, 508, 1080.0, 1080.0, 0.16, 1.0, 3.0, 3, 0.0, 1.0, 2);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) t->cell(i, j).sigma.setConstant(0.01 * (i + 1));
  TagPose pose;
  pose.distance = 1.0;
  const auto full = TagErrorModel::Create(TagErrorKind::kTable, t, 0.5, 1.0);
  const auto half = TagErrorModel::Create(TagErrorKind::kTable, t, 0.5, 0.5);
  ASSERT_TRUE(full.ok() && half.ok());
  EXPECT_NEAR(full->Covariance(pose, 0.16)(3, 3), 1e-4, 1e-12);
  EXPECT_NEAR(half->Covariance(pose, 0.16)(3, 3), 4e-4, 1e-12);  // as the table's camera at 2 m
  EXPECT_FALSE(TagErrorModel::Create(TagErrorKind::kTable, t, 0.5, 1.5).ok());
  EXPECT_FALSE(TagErrorModel::Create(TagErrorKind::kTable, t, 0.5, 0.0).ok());
}

TEST(TagErrorModelTest, CompetingMinimaWidenTheCombinedCovarianceAlongTheirDifference) {
  const auto table = FlatTable(0.01);  // corner error 0.25 px
  TagPose pose;
  pose.distance = 5.0;
  pose.T_cam_tag.translation() = Eigen::Vector3d(0, 0, 5);
  pose.has_alternative = true;
  pose.T_cam_tag_alternative = pose.T_cam_tag * Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitX());
  const auto model = TagErrorModel::Create(TagErrorKind::kCombined, table, 0.5);
  ASSERT_TRUE(model.ok());
  // Both explain the corners equally: a quarter of the squared difference is added.
  pose.reprojection_error = pose.alternative_reprojection_error = 0.1;
  EXPECT_NEAR(model->Covariance(pose, 0.16)(3, 3), 1e-4 + 0.25 * 0.36, 1e-9);
  // The other explains them far worse (1 px against 0.1 px at 0.25 px noise): nothing added.
  pose.alternative_reprojection_error = 1.0;
  EXPECT_NEAR(model->Covariance(pose, 0.16)(3, 3), 1e-4, 1e-9);
  // The propagated model also weighs the perturbed corner sets that jumped to it: 64 of 256 add
  // 0.25 * 0.75 of it; the combined model, whose spread holds those jumps already, does not.
  pose.solved_samples = 256;
  pose.flipped_samples = 64;
  EXPECT_NEAR(model->Covariance(pose, 0.16)(3, 3), 1e-4, 1e-9);
  const auto propagated = TagErrorModel::Create(TagErrorKind::kPropagated, table);
  EXPECT_NEAR(propagated->Covariance(pose, 0.16)(3, 3), 1e-4 + 0.1875 * 0.36, 1e-9);
}

TEST(TagErrorModelTest, TheResidualIsChiSquareAgainstTheTablesCornerError) {
  TagPose pose;
  pose.reprojection_error = 0.25;  // px RMS over the corners, the table's corner error
  EXPECT_NEAR(TagErrorModel::Create(TagErrorKind::kCombined, FlatTable(0.01))->ResidualChi2(pose), 4.0, 1e-12);
  pose.reprojection_error = 0.65;
  EXPECT_GT(TagErrorModel::Create(TagErrorKind::kTable, FlatTable(0.01))->ResidualChi2(pose), 13.8);
  EXPECT_TRUE(std::isnan(TagErrorModel::Create(TagErrorKind::kOnline, nullptr)->ResidualChi2(pose)));
}

}  // namespace
}  // namespace cairn
