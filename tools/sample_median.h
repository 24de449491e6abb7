#pragma once
// The median the commands print for a sample of timings or errors.

#include <vector>

namespace cairn {

// The middle value, or the mean of the two middle values of an even count; NaN for no values, so
// that an empty sample never prints as a measured zero.
double Median(std::vector<double> values);

}  // namespace cairn
