#pragma once
// Angles are radians inside; configs, tests and reports that speak in degrees multiply by this.

#include <cmath>
#include <numbers>

namespace cairn {

inline constexpr double kDegree = std::numbers::pi / 180.0;  // one degree in radians

// a - b, wrapped into [-pi, pi].
inline double AngleDifference(double a, double b) { return std::remainder(a - b, 2.0 * std::numbers::pi); }

}  // namespace cairn
