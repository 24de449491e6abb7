#pragma once
// Robust estimate of how far a graph's information matrices misstate the noise of its loop
// closures, from the squared whitened residuals r2 = e^T Info e of the closures at a solution.
//
// Outlier thresholds are quantiles of the chi-square distribution of r2 and so only mean what
// they say when the information is right. Real benchmark graphs are not: parking-garage's
// residuals are about 1e-4 of what its information predicts (a threshold of 22.46 then lets false
// closures in), the ARGoS 2-robot sets' about 10 times more (true closures fail it). Nor are
// their residuals chi-square: their upper tails reach hundreds of times the median (mixed
// leverage, translation and rotation misstated by different factors, and a closure that loses
// weight no longer pulls the solution to it), where chi-square(6)'s 99.9 % quantile is 4.2 times
// its median. A threshold at a multiple of a chi-square scale rejects many true closures there.
//
// Model: log r2 of true closures is normal (r2 log-normal), fitted robustly from the median and
// the lower quartile of log r2, which false closures (large residuals) do not move while they are
// fewer than half. The threshold is the fit's `confidence` quantile; the noise scale reported is
// that threshold over chi-square(dof)'s quantile, the factor every chi-square threshold of the
// information as given is multiplied by. For a chi-square sample the fit is conservative: its
// 99.9 % quantile is 1.8 (6 dof) to 3.1 (3 dof) times chi-square's.
//
// Assumptions: one factor for all closures (one sensor, one model); most closures are true. A
// fraction e of false closures moves the median and lower quartile up to the true closures'
// 0.5 / (1 - e) and 0.25 / (1 - e) quantiles: the threshold rises (1.29 sigma of log r2 for
// e = 25 %), never falls.

#include <vector>

namespace cairn {

struct NoiseScaleEstimate {
  double scale = 1.0;      // threshold / chi-square quantile: actual over stated noise variance
  double threshold = 0.0;  // on r2
  int inliers = 0;         // residuals within the threshold
};

// `r2` non-negative; fewer than 4 positive values give scale 1 (the information as given).
// dof >= 1, confidence in (0.5, 1).
NoiseScaleEstimate EstimateNoiseScale(const std::vector<double>& r2, int dof, double confidence);

// Quantile of the standard normal distribution, probability in (0, 1).
double NormalQuantile(double probability);

}  // namespace cairn
