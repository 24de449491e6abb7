#include "estimation/graph/noise_scale.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "estimation/graph/pairwise_consistency.h"

namespace cairn {
namespace {

// `count` log-normal values exp(mu + sigma * n), then `outliers` values of exp(mu + 20 + i).
std::vector<double> LogNormal(int count, double mu, double sigma, int outliers, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<double> r2;
  for (int i = 0; i < count; ++i) r2.push_back(std::exp(mu + sigma * n(rng)));
  for (int i = 0; i < outliers; ++i) r2.push_back(std::exp(mu + 20.0 + i % 10));
  return r2;
}

TEST(NoiseScaleTest, ChiSquareAndNormalQuantilesMatchTables) {
  EXPECT_NEAR(ChiSquareCdf(16.812, 6), 0.99, 1e-4);
  EXPECT_NEAR(ChiSquareCdf(5.348, 6), 0.5, 1e-4);
  EXPECT_NEAR(ChiSquareCdf(3.841, 1), 0.95, 1e-4);
  EXPECT_EQ(ChiSquareCdf(0.0, 3), 0.0);
  EXPECT_NEAR(NormalQuantile(0.999), 3.0902, 1e-4);
  EXPECT_NEAR(NormalQuantile(0.75), 0.6745, 1e-4);
  EXPECT_NEAR(NormalQuantile(0.5), 0.0, 1e-9);
}

TEST(NoiseScaleTest, FindsTheLogNormalQuantile) {
  for (double mu : {-9.6, 0.0, 2.9}) {
    for (double sigma : {0.6, 1.2}) {
      const NoiseScaleEstimate e = EstimateNoiseScale(LogNormal(4000, mu, sigma, 0, 5), 6, 0.999);
      const double expected = std::exp(mu + NormalQuantile(0.999) * sigma);
      EXPECT_NEAR(std::log(e.threshold / expected), 0.0, 0.1) << "mu " << mu << " sigma " << sigma;
      EXPECT_NEAR(e.scale, e.threshold / ChiSquareQuantile(0.999, 6), 1e-9 * e.scale);
      EXPECT_GE(e.inliers, 3980);
    }
  }
}

TEST(NoiseScaleTest, FalseResidualsOnlyRaiseTheThresholdAsDocumented) {
  // 25 % false residuals far above: the median and lower quartile of the mixture are the true
  // ones' 2/3 and 1/3 quantiles, so the threshold lies 1.29 sigma (in log r2) above the true
  // one's, never below it, and every false residual stays beyond it.
  for (double sigma : {0.6, 1.2}) {
    const auto r2 = LogNormal(3000, 0.0, sigma, 1000, 5);
    const NoiseScaleEstimate e = EstimateNoiseScale(r2, 6, 0.999);
    const double excess = std::log(e.threshold) - NormalQuantile(0.999) * sigma;
    EXPECT_GT(excess, 1.1 * sigma) << sigma;
    EXPECT_LT(excess, 1.5 * sigma) << sigma;
    EXPECT_EQ(e.inliers, 3000);
  }
}

TEST(NoiseScaleTest, ChiSquareResidualsGiveAConservativeScaleOfTheirVariance) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int dof : {3, 6}) {
    std::vector<double> r2;
    for (int i = 0; i < 5000; ++i) {
      double s = 0.0;
      for (int d = 0; d < dof; ++d) {
        const double x = n(rng);
        s += x * x;
      }
      r2.push_back(s);
    }
    const double unit = EstimateNoiseScale(r2, dof, 0.999).scale;
    EXPECT_GT(unit, 1.5) << dof;  // 1.8 for 6 dof, 3.1 for 3 (noise_scale.h)
    EXPECT_LT(unit, 3.6) << dof;
    // Scale-invariant: residuals 1e-4 times smaller, a scale 1e-4 times smaller.
    for (double& x : r2) x *= 1e-4;
    EXPECT_NEAR(EstimateNoiseScale(r2, dof, 0.999).scale, 1e-4 * unit, 1e-9 * unit);
  }
}

TEST(NoiseScaleTest, TooFewResidualsMeanTheInformationAsGiven) {
  EXPECT_EQ(EstimateNoiseScale({}, 6, 0.999).scale, 1.0);
  EXPECT_EQ(EstimateNoiseScale({0.0, 0.0, 0.0, 0.0, 1.0}, 6, 0.999).scale, 1.0);
}

}  // namespace
}  // namespace cairn
