#pragma once
// The median and percentiles the commands print for a sample of timings or errors.

#include <vector>

namespace cairn {

// The middle value, or the mean of the two middle values of an even count; NaN for no values, so
// that an empty sample never prints as a measured zero.
double Median(std::vector<double> values);
// The nearest-rank percentile, q in [0, 1] (0: the smallest); NaN for no values.
double NearestRankPercentile(std::vector<double> values, double q);

}  // namespace cairn
