#pragma once
// Two unit axes perpendicular to a unit vector n, chosen the same way everywhere (planes' tangent
// spaces, lines' perpendicular errors): u level, along n's intersection with the horizontal, unless
// n is within about 6 deg of vertical, where u follows x instead; v = n x u.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cairn {

template <class Scalar>
void TangentAxes(const Eigen::Matrix<Scalar, 3, 1>& n, Eigen::Matrix<Scalar, 3, 1>* u,
                 Eigen::Matrix<Scalar, 3, 1>* v) {
  using V3 = Eigen::Matrix<Scalar, 3, 1>;
  V3 h = V3::UnitZ().cross(n);
  if (h.squaredNorm() < Scalar(0.01)) h = V3::UnitX() - n.x() * n;
  *u = h.normalized();
  *v = n.cross(*u);
}

}  // namespace cairn
