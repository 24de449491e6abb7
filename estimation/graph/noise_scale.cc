#include "estimation/graph/noise_scale.h"

#include <algorithm>
#include <cmath>

#include "estimation/graph/pairwise_consistency.h"

namespace cairn {

double NormalQuantile(double probability) {
  // The square of a standard normal variable is chi-square with one degree of freedom.
  if (probability < 0.5) return -NormalQuantile(1.0 - probability);
  return std::sqrt(ChiSquareQuantile(2.0 * probability - 1.0, 1));
}

NoiseScaleEstimate EstimateNoiseScale(const std::vector<double>& r2, int dof, double confidence) {
  NoiseScaleEstimate out;
  const double chi2_quantile = ChiSquareQuantile(confidence, dof);
  out.threshold = chi2_quantile;
  std::vector<double> logs;
  for (double x : r2) {
    if (x > 0.0) logs.push_back(std::log(x));
  }
  if (logs.size() < 4) {
    out.inliers = static_cast<int>(std::count_if(r2.begin(), r2.end(), [&](double x) { return x <= chi2_quantile; }));
    return out;
  }
  std::sort(logs.begin(), logs.end());
  // Order statistics at fractions p of the sorted logs, linearly interpolated.
  auto at = [&](double p) {
    const double i = p * static_cast<double>(logs.size() - 1);
    const size_t k = static_cast<size_t>(i);
    const double f = i - static_cast<double>(k);
    return k + 1 < logs.size() ? (1.0 - f) * logs[k] + f * logs[k + 1] : logs[k];
  };
  const double median = at(0.5);
  const double sigma = (median - at(0.25)) / NormalQuantile(0.75);
  out.threshold = std::exp(median + NormalQuantile(confidence) * sigma);
  out.scale = out.threshold / chi2_quantile;
  out.inliers = static_cast<int>(std::count_if(r2.begin(), r2.end(), [&](double x) { return x <= out.threshold; }));
  return out;
}

}  // namespace cairn
