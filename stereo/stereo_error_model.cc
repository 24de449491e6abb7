#include "stereo/stereo_error_model.h"

#include <cmath>

namespace cairn {

Eigen::Vector3d StereoErrorModel::PointError(const Eigen::Vector3d& p) const {
  const double k = dp_ * p.z() / (f_ * b_);
  return {k * std::sqrt((b_ - p.x()) * (b_ - p.x()) + p.x() * p.x()),
          k * std::sqrt(2.0 * p.y() * p.y() + 0.5 * b_ * b_),
          k * p.z() * std::sqrt(2.0)};
}

double StereoErrorModel::DepthError(double depth) const {
  return dp_ * depth * depth * std::sqrt(2.0) / (f_ * b_);
}

double StereoErrorModel::MaxDepthForError(double max_depth_error) const {
  return std::sqrt(max_depth_error * f_ * b_ / (dp_ * std::sqrt(2.0)));
}

// Each point is reconstructed from its left column, right column and (averaged) row; the terms
// below are the squared derivatives of the distance with respect to those six image
// coordinates. The sign of the z term in A follows from differentiating; the thesis' printed
// eq. 5.4b carries a transcription slip there (and a 't' for the baseline b).
double StereoErrorModel::DistanceError(const Eigen::Vector3d& p, const Eigen::Vector3d& q) const {
  const Eigen::Vector3d dqp = q - p;
  const double d = dqp.norm();
  if (d == 0.0) return 0.0;
  const auto sq = [](double x) { return x * x; };
  const double a = sq(dqp.x() * (b_ - q.x()) - dqp.y() * q.y() - dqp.z() * q.z());
  const double bb = sq(dqp.x() * q.x() + dqp.y() * q.y() + dqp.z() * q.z());
  const double c = 0.5 * sq(b_ * dqp.y());
  const double dd = sq(dqp.x() * (b_ - p.x()) - dqp.y() * p.y() - dqp.z() * p.z());
  const double e = sq(dqp.x() * p.x() + dqp.y() * p.y() + dqp.z() * p.z());
  return dp_ / (d * f_ * b_) * std::sqrt(sq(q.z()) * (a + bb + c) + sq(p.z()) * (c + dd + e));
}

}  // namespace cairn
