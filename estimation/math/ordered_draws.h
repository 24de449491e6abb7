#pragma once
// Random vectors drawn in one fixed order, for seeded data (`cairn graph inject`, bench and test
// scenarios). The arguments of a call are evaluated in an unspecified order (GCC right to left,
// Clang left to right), so Eigen::Vector3d(n(rng), n(rng), n(rng)) is other data for each compiler
// and a seed names no file. These draw the last component first, the order GCC builds always used,
// so that earlier outputs and figures stay what they were.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cairn {

template <class Distribution, class Engine>
Eigen::Vector2d DrawVector2(Distribution& d, Engine& rng) {
  const double y = d(rng);
  const double x = d(rng);
  return {x, y};
}

template <class Distribution, class Engine>
Eigen::Vector3d DrawVector3(Distribution& d, Engine& rng) {
  const double z = d(rng);
  const double y = d(rng);
  const double x = d(rng);
  return {x, y, z};
}

// Not normalized.
template <class Distribution, class Engine>
Eigen::Quaterniond DrawQuaternion(Distribution& d, Engine& rng) {
  const double z = d(rng);
  const double y = d(rng);
  const double x = d(rng);
  const double w = d(rng);
  return Eigen::Quaterniond(w, x, y, z);
}

}  // namespace cairn
