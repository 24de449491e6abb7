#pragma once
// Angles are radians inside; configs, tests and reports that speak in degrees multiply by this.

#include <numbers>

namespace cairn {

inline constexpr double kDegree = std::numbers::pi / 180.0;  // one degree in radians

}  // namespace cairn
