#include "sim/bspline_trajectory.h"

#include <algorithm>
#include <cmath>

namespace cairn::sim {
namespace {

// Value, first and second derivative (per unit u) of the four uniform cubic B-spline basis
// functions at u in [0, 1].
struct Basis {
  double b[4], d1[4], d2[4];
};

Basis CubicBasis(double u) {
  const double u2 = u * u, u3 = u2 * u, m = 1.0 - u;
  Basis r{};
  r.b[0] = m * m * m / 6.0;
  r.b[1] = (3 * u3 - 6 * u2 + 4) / 6.0;
  r.b[2] = (-3 * u3 + 3 * u2 + 3 * u + 1) / 6.0;
  r.b[3] = u3 / 6.0;
  r.d1[0] = -m * m / 2.0;
  r.d1[1] = (3 * u2 - 4 * u) / 2.0;
  r.d1[2] = (-3 * u2 + 2 * u + 1) / 2.0;
  r.d1[3] = u2 / 2.0;
  r.d2[0] = m;
  r.d2[1] = 3 * u - 2;
  r.d2[2] = -3 * u + 1;
  r.d2[3] = u;
  return r;
}

}  // namespace

BSplineTrajectory::BSplineTrajectory(double knot_interval, std::vector<Eigen::Vector3d> positions,
                                     std::vector<Eigen::Vector3d> euler)
    : dt_(knot_interval), p_(std::move(positions)), e_(std::move(euler)) {}

double BSplineTrajectory::duration() const {
  return p_.size() < 4 ? 0.0 : static_cast<double>(p_.size() - 3) * dt_;
}

Eigen::Matrix3d BSplineTrajectory::EulerToRotation(const Eigen::Vector3d& ypr) {
  return (Eigen::AngleAxisd(ypr[0], Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(ypr[1], Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(ypr[2], Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

TrajectoryState BSplineTrajectory::Evaluate(double t) const {
  const double s = std::clamp(t / dt_, 0.0, static_cast<double>(p_.size() - 3));
  const size_t seg = std::min(static_cast<size_t>(s), p_.size() - 4);
  const Basis B = CubicBasis(s - static_cast<double>(seg));
  Eigen::Vector3d p = Eigen::Vector3d::Zero(), v = p, a = p, e = p, ed = p;
  for (size_t k = 0; k < 4; ++k) {
    p += B.b[k] * p_[seg + k];
    v += B.d1[k] * p_[seg + k];
    a += B.d2[k] * p_[seg + k];
    e += B.b[k] * e_[seg + k];
    ed += B.d1[k] * e_[seg + k];
  }
  v /= dt_;
  a /= dt_ * dt_;
  ed /= dt_;
  TrajectoryState st;
  st.T_world_body.linear() = EulerToRotation(e);
  st.T_world_body.translation() = p;
  st.velocity = v;
  st.acceleration = a;
  // Body rates of ZYX Euler angles: w = [r' - y' sp, p' cr + y' cp sr, -p' sr + y' cp cr].
  const double pitch = e[1], roll = e[2];
  const double yd = ed[0], pd = ed[1], rd = ed[2];
  st.omega_body = Eigen::Vector3d(rd - yd * std::sin(pitch),
                                  pd * std::cos(roll) + yd * std::cos(pitch) * std::sin(roll),
                                  -pd * std::sin(roll) + yd * std::cos(pitch) * std::cos(roll));
  return st;
}

}  // namespace cairn::sim
