#include "stereo/stereo_error_model.h"

#include <cmath>

#include <gtest/gtest.h>

namespace cairn {
namespace {

// Reconstructs a point from its stereo image coordinates (left column, right column, row), the
// inverse of the projection the error model differentiates.
Eigen::Vector3d Triangulate(double ul, double ur, double v, double f, double b) {
  const double z = f * b / (ul - ur);
  return {ul * z / f, v * z / f, z};
}

// Numeric first-order propagation: perturb each image coordinate by its own sigma.
double NumericDistanceError(const Eigen::Vector3d& p, const Eigen::Vector3d& q, double f,
                            double b, double dp) {
  const auto coords = [&](const Eigen::Vector3d& x) {
    return Eigen::Vector3d(f * x.x() / x.z(), f * (x.x() - b) / x.z(), f * x.y() / x.z());
  };
  const Eigen::Vector3d cp = coords(p), cq = coords(q);
  const double sig[3] = {dp, dp, dp / std::sqrt(2.0)};  // the row is the mean of both images
  const double h = 1e-6;
  double var = 0.0;
  for (int which = 0; which < 2; ++which) {
    for (int i = 0; i < 3; ++i) {
      Eigen::Vector3d c1 = which == 0 ? cp : cq, c0 = c1;
      c1[i] += h;
      c0[i] -= h;
      const Eigen::Vector3d other = which == 0 ? q : p;
      const double d1 = (Triangulate(c1[0], c1[1], c1[2], f, b) - other).norm();
      const double d0 = (Triangulate(c0[0], c0[1], c0[2], f, b) - other).norm();
      const double deriv = (d1 - d0) / (2.0 * h);
      var += deriv * deriv * sig[i] * sig[i];
    }
  }
  return std::sqrt(var);
}

TEST(StereoErrorModelTest, DepthErrorMatchesEquation52cByHand) {
  // f = 1080 px, b = 0.09 m, 0.5 px: at 3 m, 0.5 * 9 * sqrt(2) / 97.2 = 0.0654735 m.
  const StereoErrorModel m(1080.0, 0.09, 0.5);
  EXPECT_NEAR(m.DepthError(3.0), 0.5 * 9.0 * std::sqrt(2.0) / 97.2, 1e-12);
  EXPECT_NEAR(m.PointError({0.0, 0.0, 3.0}).z(), m.DepthError(3.0), 1e-15);
  EXPECT_NEAR(m.DepthError(m.MaxDepthForError(0.15)), 0.15, 1e-12);
}

TEST(StereoErrorModelTest, PointErrorMatchesEquation52ByHand) {
  const StereoErrorModel m(500.0, 0.1, 1.0);
  const Eigen::Vector3d e = m.PointError({0.4, -0.3, 2.0});
  const double k = 2.0 / 50.0;
  EXPECT_NEAR(e.x(), k * std::sqrt(0.09 + 0.16), 1e-15);
  EXPECT_NEAR(e.y(), k * std::sqrt(2.0 * 0.09 + 0.005), 1e-15);
}

TEST(StereoErrorModelTest, DistanceErrorAgreesWithNumericPropagation) {
  const StereoErrorModel m(1080.0, 0.09, 0.5);
  const Eigen::Vector3d pairs[][2] = {
      {{0.1, 0.4, 2.0}, {0.15, 0.2, 2.1}},
      {{-0.5, 0.6, 4.0}, {-0.45, 0.7, 4.3}},
      {{0.3, -0.2, 1.5}, {0.9, 0.5, 3.0}},
  };
  for (const auto& pq : pairs) {
    const double expected = NumericDistanceError(pq[0], pq[1], 1080.0, 0.09, 0.5);
    EXPECT_NEAR(m.DistanceError(pq[0], pq[1]), expected, 1e-6 * expected + 1e-9);
    EXPECT_DOUBLE_EQ(m.DistanceError(pq[0], pq[1]), m.DistanceError(pq[1], pq[0]));
  }
  EXPECT_EQ(m.DistanceError({1, 2, 3}, {1, 2, 3}), 0.0);
}

TEST(StereoErrorModelTest, DistanceErrorGrowsWithRange) {
  const StereoErrorModel m(1080.0, 0.09, 0.5);
  const Eigen::Vector3d near(0.0, 0.5, 2.0), far(0.0, 0.5, 6.0);
  // A step across the line of sight scales with depth (like eq. 5.2b), one along it with the
  // square of the depth (like eq. 5.2c): three times farther is three and nine times worse.
  const Eigen::Vector3d across(0.0, 0.1, 0.0), along(0.0, 0.0, 0.1);
  EXPECT_NEAR(m.DistanceError(far, far + across) / m.DistanceError(near, near + across), 3.0, 0.05);
  EXPECT_NEAR(m.DistanceError(far, far + along) / m.DistanceError(near, near + along), 9.0, 0.5);
}

}  // namespace
}  // namespace cairn
