#include "estimation/vo/two_frame_bundle_adjuster.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "estimation/math/small_cholesky.h"
#include "estimation/math/so3.h"

namespace cairn {
namespace {

// Points nearer than this to either camera's plane make the projection meaningless.
constexpr double kMinDepth = 1e-3;

bool Finite(const StereoObservation& o) {
  return std::isfinite(o.u_left) && std::isfinite(o.u_right) && std::isfinite(o.v);
}

// Inverse of a symmetric positive definite 3x3 matrix; false when it is not.
bool InvertSpd3(const Eigen::Matrix3d& A, Eigen::Matrix3d* inv) {
  Eigen::Matrix3d L;
  if (!small_cholesky::Factor<3>(A, &L)) return false;
  for (int c = 0; c < 3; ++c) {
    Eigen::Vector3d e = Eigen::Vector3d::Unit(c);
    small_cholesky::SolveLower<3>(L, e);
    small_cholesky::SolveLowerTransposed<3>(L, e);
    inv->col(c) = e;
  }
  return true;
}

}  // namespace

TwoFrameBundleAdjuster::TwoFrameBundleAdjuster(const RectifiedStereoCamera& camera, double pixel_sigma)
    : camera_(camera), sigma_col_(pixel_sigma), sigma_row_(pixel_sigma / std::numbers::sqrt2) {}

namespace {

// Whitened stereo residual of point P (in the observing camera) and its Jacobian with respect to P.
struct Projection {
  Eigen::Vector3d r;
  Eigen::Matrix3d J;
};

Projection Project(const RectifiedStereoCamera& c, double sigma_col, double sigma_row,
                   const Eigen::Vector3d& P, const StereoObservation& seen) {
  const double iz = 1.0 / P.z();
  const double x = P.x() * iz, xr = (P.x() - c.baseline) * iz, y = P.y() * iz;
  Projection p;
  p.r << (c.f * x + c.cx - seen.u_left) / sigma_col, (c.f * xr + c.cx - seen.u_right) / sigma_col,
      (c.f * y + c.cy - seen.v) / sigma_row;
  const double a = c.f * iz / sigma_col, b = c.f * iz / sigma_row;
  p.J << a, 0.0, -a * x, a, 0.0, -a * xr, 0.0, b, -b * y;
  return p;
}

}  // namespace

bool TwoFrameBundleAdjuster::Cost(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                  const std::vector<Eigen::Vector3d>& X, double* cost) {
  double sum = 0.0;
  const Eigen::Matrix3d Rt = R.transpose();
  for (size_t k = 0; k < index_.size(); ++k) {
    const Eigen::Vector3d P = Rt * (X[k] - t);
    if (!(X[k].z() > kMinDepth) || !(P.z() > kMinDepth)) return false;
    const double c = Project(camera_, sigma_col_, sigma_row_, X[k], seen_kf_[k]).r.squaredNorm() +
                     Project(camera_, sigma_col_, sigma_row_, P, seen_cur_[k]).r.squaredNorm();
    point_chi2_[static_cast<size_t>(index_[k])] = c;
    sum += c;
  }
  *cost = sum;
  return std::isfinite(sum);
}

bool TwoFrameBundleAdjuster::Reduce(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double lambda,
                                    Matrix6d* S, Vector6d* g_s) {
  Matrix6d H_pp = Matrix6d::Zero();
  Vector6d g_p = Vector6d::Zero();
  Matrix6d S_sub = Matrix6d::Zero();
  Vector6d g_sub = Vector6d::Zero();
  const Eigen::Matrix3d Rt = R.transpose();
  for (size_t k = 0; k < index_.size(); ++k) {
    const Projection a = Project(camera_, sigma_col_, sigma_row_, X_[k], seen_kf_[k]);
    const Eigen::Vector3d P = Rt * (X_[k] - t);
    const Projection b = Project(camera_, sigma_col_, sigma_row_, P, seen_cur_[k]);
    // Current frame: P = R^T (X - t), so dP/dX = R^T, dP/dt = -R^T, and with R <- R Exp(dtheta),
    // dP/dtheta = [P]x.
    const Eigen::Matrix3d A_b = b.J * Rt;
    Eigen::Matrix<double, 3, 6> B;
    B.leftCols<3>() = -A_b;
    B.rightCols<3>() = b.J * so3::Skew(P);
    Eigen::Matrix3d H_xx = a.J.transpose() * a.J + A_b.transpose() * A_b;
    for (int i = 0; i < 3; ++i) H_xx(i, i) *= 1.0 + lambda;
    PointBlock& blk = blocks_[k];
    if (!InvertSpd3(H_xx, &blk.H_inv)) return false;
    blk.H_pose.noalias() = B.transpose() * A_b;
    blk.g.noalias() = a.J.transpose() * a.r + A_b.transpose() * b.r;
    H_pp.noalias() += B.transpose() * B;
    g_p.noalias() += B.transpose() * b.r;
    const Eigen::Matrix<double, 6, 3> HW = blk.H_pose * blk.H_inv;
    S_sub.noalias() += HW * blk.H_pose.transpose();
    g_sub.noalias() += HW * blk.g;
  }
  for (int i = 0; i < 6; ++i) H_pp(i, i) *= 1.0 + lambda;
  *S = H_pp - S_sub;
  *S = 0.5 * (*S + S->transpose()).eval();
  *g_s = g_p - g_sub;
  return S->allFinite() && g_s->allFinite();
}

bool TwoFrameBundleAdjuster::Adjust(std::span<const StereoObservation> kf_seen,
                                    std::span<const StereoObservation> cur_seen,
                                    std::span<const StereoPoint> kf_points, std::span<const uint8_t> mask,
                                    const Eigen::Matrix3d& R0, const Eigen::Vector3d& t0, int max_iterations,
                                    BundleResult* result) {
  const size_t n = std::min({kf_seen.size(), cur_seen.size(), kf_points.size(), mask.size()});
  point_chi2_.assign(n, 0.0);
  index_.clear();
  seen_kf_.clear();
  seen_cur_.clear();
  X_.clear();
  for (size_t i = 0; i < n; ++i) {
    if (!mask[i]) continue;
    if (!Finite(kf_seen[i]) || !Finite(cur_seen[i]) || !kf_points[i].p.allFinite()) {
      point_chi2_[i] = std::numeric_limits<double>::infinity();
      continue;
    }
    index_.push_back(static_cast<int>(i));
    seen_kf_.push_back(kf_seen[i]);
    seen_cur_.push_back(cur_seen[i]);
    X_.push_back(kf_points[i].p);
  }
  if (index_.size() < 3 || camera_.f <= 0.0 || camera_.baseline <= 0.0) return false;
  blocks_.resize(index_.size());
  X_trial_.resize(index_.size());

  Eigen::Matrix3d R = R0;
  Eigen::Vector3d t = t0;
  double cost = 0.0;
  if (!Cost(R, t, X_, &cost)) return false;
  double lambda = 1e-4;
  int iterations = 0;
  Matrix6d S;
  Vector6d g_s;
  while (iterations < max_iterations && lambda < 1e8) {
    ++iterations;
    Matrix6d L;
    if (!Reduce(R, t, lambda, &S, &g_s) || !small_cholesky::Factor<6>(S, &L)) {
      lambda *= 10.0;
      continue;
    }
    Vector6d dp = -g_s;
    small_cholesky::SolveLower<6>(L, dp);
    small_cholesky::SolveLowerTransposed<6>(L, dp);
    const Eigen::Vector3d t_trial = t + dp.head<3>();
    const Eigen::Matrix3d R_trial = R * so3::Exp(dp.tail<3>());
    for (size_t k = 0; k < index_.size(); ++k) {
      const PointBlock& blk = blocks_[k];
      X_trial_[k] = X_[k] - blk.H_inv * (blk.g + blk.H_pose.transpose() * dp);
    }
    double trial = 0.0;
    if (dp.allFinite() && Cost(R_trial, t_trial, X_trial_, &trial) && trial <= cost) {
      const double decrease = cost - trial;
      R = R_trial;
      t = t_trial;
      X_.swap(X_trial_);
      cost = trial;
      lambda = std::max(lambda * 0.1, 1e-9);
      if (decrease <= 1e-10 * std::max(cost, 1.0)) break;
    } else {
      lambda *= 10.0;
    }
  }
  // The undamped reduced system at the result: the pose information with the points marginalized.
  if (!Reduce(R, t, 0.0, &S, &g_s) || !Cost(R, t, X_, &cost)) return false;
  result->R = R;
  result->t = t;
  result->information = S;
  result->chi2 = cost;
  result->points = static_cast<int>(index_.size());
  result->iterations = iterations;
  return true;
}

}  // namespace cairn
