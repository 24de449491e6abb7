#include "estimation/eval/trajectory_evaluator.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "estimation/math/so3.h"
#include "estimation/math/symmetric_eigen.h"

namespace cairn {
namespace {

double AngleDeg(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle() * 180.0 / M_PI; }

// Rotation about z (yaw) and translation that best map `est` positions onto `gt` ones.
Eigen::Isometry3d AlignFourDof(const std::vector<Eigen::Vector3d>& gt, const std::vector<Eigen::Vector3d>& est) {
  Eigen::Vector3d mg = Eigen::Vector3d::Zero(), me = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < gt.size(); ++i) {
    mg += gt[i];
    me += est[i];
  }
  mg /= static_cast<double>(gt.size());
  me /= static_cast<double>(gt.size());
  double s = 0.0, c = 0.0;
  for (size_t i = 0; i < gt.size(); ++i) {
    const Eigen::Vector3d a = est[i] - me, b = gt[i] - mg;
    c += a.x() * b.x() + a.y() * b.y();
    s += a.x() * b.y() - a.y() * b.x();
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(std::atan2(s, c), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = mg - T.linear() * me;
  return T;
}

// Rotation and translation that best map `est` positions onto `gt` ones (least squares, Umeyama
// 1991 without scale), from the 3x3 cross-covariance only: fixed-size matrices keep this file
// cheap to compile. Fewer than 3 distinct positions, or all on a line, leave the rotation free:
// then `fallback` (the first poses' alignment) is used.
Eigen::Isometry3d AlignSe3(const std::vector<Eigen::Vector3d>& gt, const std::vector<Eigen::Vector3d>& est,
                           const Eigen::Isometry3d& fallback) {
  const double n = static_cast<double>(gt.size());
  Eigen::Vector3d mg = Eigen::Vector3d::Zero(), me = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < gt.size(); ++i) {
    mg += gt[i];
    me += est[i];
  }
  mg /= n;
  me /= n;
  Eigen::Matrix3d cross = Eigen::Matrix3d::Zero(), scatter = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < gt.size(); ++i) {
    const Eigen::Vector3d a = est[i] - me, b = gt[i] - mg;
    cross += b * a.transpose();
    scatter += a * a.transpose();
  }
  // Singular values of the centred positions are the square roots of the scatter's eigenvalues.
  const Eigen::Vector3d lambda = SymmetricEigenvalues(scatter);
  const double s1 = std::sqrt(std::max(lambda(1), 0.0)), s0 = std::sqrt(std::max(lambda(2), 0.0));
  if (gt.size() < 3 || s1 < 1e-6 * std::max(1.0, s0)) return fallback;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cross / n, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d d = Eigen::Vector3d::Ones();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) d(2) = -1.0;  // no reflection
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = svd.matrixU() * d.asDiagonal() * svd.matrixV().transpose();
  T.translation() = mg - T.linear() * me;
  return T;
}

}  // namespace

Expected<TrajectoryAlignment> ParseTrajectoryAlignment(const std::string& name) {
  if (name == "se3") return TrajectoryAlignment::kSe3;
  if (name == "4dof") return TrajectoryAlignment::kFourDof;
  if (name == "none") return TrajectoryAlignment::kNone;
  return InvalidArgumentError("unknown alignment '" + name + "' (se3, 4dof or none)");
}

Expected<TrajectoryEvalResult> EvaluateTrajectory(const Trajectory& ground_truth, const Trajectory& estimate,
                                                  const TrajectoryEvalOptions& options) {
  std::vector<StampedPose> gt = ground_truth.poses;
  const auto by_time = [](const StampedPose& a, const StampedPose& b) { return a.time < b.time; };
  std::sort(gt.begin(), gt.end(), by_time);
  // Associate each estimate with the nearest ground-truth pose in time.
  std::vector<Eigen::Isometry3d> G, E;
  std::vector<double> times;
  for (const StampedPose& e : estimate.poses) {
    auto it = std::lower_bound(gt.begin(), gt.end(), e, by_time);
    const StampedPose* best = nullptr;
    if (it != gt.end()) best = &*it;
    if (it != gt.begin()) {
      const StampedPose* prev = &*(it - 1);
      if (best == nullptr || (e.time - prev->time).seconds() < (best->time - e.time).seconds()) best = prev;
    }
    if (best == nullptr || std::abs((best->time - e.time).seconds()) > options.max_time_difference) continue;
    if (!times.empty() && e.time.seconds() <= times.back()) continue;  // keep time order, no duplicates
    G.push_back(best->T_frame_body);
    E.push_back(e.T_frame_body);
    times.push_back(e.time.seconds());
  }
  TrajectoryEvalResult r;
  r.associated = static_cast<int>(G.size());
  if (r.associated < 2) {
    return InvalidArgumentError("only " + std::to_string(r.associated) + " of " +
                                std::to_string(estimate.poses.size()) +
                                " estimated poses have a ground-truth pose within " +
                                std::to_string(options.max_time_difference) + " s (do the time stamps match?)");
  }
  r.duration = times.back() - times.front();
  std::vector<Eigen::Vector3d> pg, pe;
  for (size_t i = 0; i < G.size(); ++i) {
    pg.push_back(G[i].translation());
    pe.push_back(E[i].translation());
  }
  switch (options.alignment) {
    case TrajectoryAlignment::kSe3:
      r.T_gt_est = AlignSe3(pg, pe, G.front() * E.front().inverse());
      break;
    case TrajectoryAlignment::kFourDof:
      r.T_gt_est = AlignFourDof(pg, pe);
      break;
    case TrajectoryAlignment::kNone:
      break;
  }
  double sum2 = 0.0, sum = 0.0;
  for (size_t i = 0; i < G.size(); ++i) {
    const double e = (pg[i] - r.T_gt_est * pe[i]).norm();
    sum2 += e * e;
    sum += e;
    r.ate_max = std::max(r.ate_max, e);
    if (i > 0) r.path_length += (pg[i] - pg[i - 1]).norm();
  }
  r.ate_rmse = std::sqrt(sum2 / static_cast<double>(G.size()));
  r.ate_mean = sum / static_cast<double>(G.size());

  // Relative pose errors over ground-truth path segments of each length.
  std::vector<double> dist(G.size(), 0.0);
  for (size_t i = 1; i < G.size(); ++i) dist[i] = dist[i - 1] + (pg[i] - pg[i - 1]).norm();
  for (double L : options.segment_lengths) {
    SegmentError s;
    s.length = L;
    size_t j = 0;
    for (size_t i = 0; i < G.size(); ++i) {
      j = std::max(j, i + 1);
      while (j < G.size() && dist[j] - dist[i] < L) ++j;
      if (j >= G.size()) break;
      const Eigen::Isometry3d dg = G[i].inverse() * G[j], de = E[i].inverse() * E[j];
      const Eigen::Isometry3d err = dg.inverse() * de;
      const double len = dist[j] - dist[i];
      s.translation_percent += err.translation().norm() / len * 100.0;
      s.rotation_deg_per_m += AngleDeg(err.linear()) / len;
      ++s.pairs;
    }
    if (s.pairs > 0) {
      s.translation_percent /= s.pairs;
      s.rotation_deg_per_m /= s.pairs;
    }
    r.segments.push_back(s);
  }
  // Drift from the first to the last pose, expressed in the ground truth's first body frame.
  const Eigen::Isometry3d dg = G.front().inverse() * G.back(), de = E.front().inverse() * E.back();
  r.drift_translation = (de.translation() - dg.translation()).norm();
  const Eigen::Matrix3d R_err = dg.linear().transpose() * de.linear();
  r.drift_rotation_deg = AngleDeg(R_err);
  // Yaw: the error rotation seen from the world, about the world's vertical.
  const Eigen::Vector3d w = G.back().linear() * so3::Log(R_err);
  r.drift_yaw_deg = std::abs(w.z()) * 180.0 / M_PI;
  return r;
}

}  // namespace cairn
