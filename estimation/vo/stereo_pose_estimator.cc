#include "estimation/vo/stereo_pose_estimator.h"

#include <algorithm>
#include <cmath>

#include <ceres/ceres.h>

#include "estimation/math/small_cholesky.h"
#include "estimation/math/so3.h"
#include "estimation/math/symmetric_eigen.h"
#include "estimation/vo/point_pair_residual.h"

namespace cairn {
namespace {

// Inverse Cholesky factor of the combined covariance of a pair under rotation R.
bool Whitening(const StereoPoint& kf, const StereoPoint& cur, const Eigen::Matrix3d& R, Eigen::Matrix3d* W) {
  const Eigen::Matrix3d S = kf.cov + R * cur.cov * R.transpose();
  Eigen::Matrix3d L;
  if (!small_cholesky::Factor<3>(S, &L)) return false;
  // W = L^-1: W^T = L^-T, i.e. the identity times L^-T.
  Eigen::Matrix3d Wt = Eigen::Matrix3d::Identity();
  small_cholesky::SolveLowerTransposedRight<3, 3>(L, Wt);
  *W = Wt.transpose();
  return true;
}

// Small, reproducible generator (std distributions differ between standard libraries).
struct SplitMix {
  uint64_t s;
  uint64_t Next() {
    uint64_t z = (s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  size_t Below(size_t n) { return static_cast<size_t>(Next() % n); }
};

}  // namespace

StereoPoseEstimator::StereoPoseEstimator(const VoOptions& options, const RectifiedStereoCamera& camera)
    : options_(options), bundle_(camera, options.pixel_sigma) {}

bool StereoPoseEstimator::GaussNewtonStep(std::span<const StereoPoint> kf, std::span<const StereoPoint> cur,
                                          const std::vector<uint8_t>& mask, Eigen::Matrix3d* R,
                                          Eigen::Vector3d* t) const {
  Matrix6d H = Matrix6d::Zero();
  Vector6d g = Vector6d::Zero();
  for (size_t i = 0; i < kf.size(); ++i) {
    if (!mask[i]) continue;
    Eigen::Matrix3d W;
    if (!Whitening(kf[i], cur[i], *R, &W)) continue;
    Eigen::Matrix<double, 3, 6> J;
    J.leftCols<3>() = W;
    J.rightCols<3>() = -W * *R * so3::Skew(cur[i].p);
    H.noalias() += J.transpose() * J;
    g.noalias() += J.transpose() * (W * (*R * cur[i].p + *t - kf[i].p));
  }
  // H = L L^T: dx = -L^-T L^-1 g.
  Matrix6d L;
  if (!small_cholesky::Factor<6>(H, &L)) return false;
  Vector6d dx = -g;
  small_cholesky::SolveLower<6>(L, dx);
  small_cholesky::SolveLowerTransposed<6>(L, dx);
  if (!dx.allFinite()) return false;
  *t += dx.head<3>();
  *R = *R * so3::Exp(dx.tail<3>());
  return true;
}

int StereoPoseEstimator::Score(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, std::span<const StereoPoint> kf,
                               std::span<const StereoPoint> cur, std::vector<uint8_t>* mask) const {
  int n = 0;
  for (size_t i = 0; i < kf.size(); ++i) {
    const Eigen::Vector3d d = R * cur[i].p + t - kf[i].p;
    const double d2 = d.squaredNorm();
    bool in = false;
    // The trace bounds the largest eigenvalue of the combined covariance, so a difference
    // beyond it is an outlier without the exact test. The covariances are elongated along the
    // viewing rays, so the exact test needs the hypothesis' rotation.
    if (d2 < options_.inlier_chi2 * trace_bound_[i]) {
      const Eigen::Matrix3d S = kf[i].cov + R * cur[i].cov * R.transpose();
      Eigen::Matrix3d L;
      Eigen::Vector3d z = d;
      if (small_cholesky::Factor<3>(S, &L)) {
        small_cholesky::SolveLower<3>(L, z);
        in = z.squaredNorm() < options_.inlier_chi2;
      }
    }
    (*mask)[i] = in ? 1 : 0;
    n += in ? 1 : 0;
  }
  return n;
}

bool StereoPoseEstimator::Refine(std::span<const StereoPoint> kf, std::span<const StereoPoint> cur,
                                 Eigen::Matrix3d* R, Eigen::Vector3d* t) const {
  Eigen::Quaterniond q(*R);
  q.normalize();
  Eigen::Vector3d tt = *t;
  ceres::Problem::Options po;
  ceres::Problem problem(po);
  int used = 0;
  for (size_t i = 0; i < kf.size(); ++i) {
    if (!inliers_[i]) continue;
    Eigen::Matrix3d W;
    if (!Whitening(kf[i], cur[i], *R, &W)) continue;
    problem.AddResidualBlock(new PointPairResidual(kf[i].p, cur[i].p, W), nullptr, q.coeffs().data(), tt.data());
    ++used;
  }
  if (used < 3) return false;
  problem.SetManifold(q.coeffs().data(), new ceres::EigenQuaternionManifold);
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = static_cast<int>(options_.refine_iterations);
  so.logging_type = ceres::SILENT;
  so.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  if (!summary.IsSolutionUsable()) return false;
  *R = q.normalized().toRotationMatrix();
  *t = tt;
  return true;
}

Matrix6d StereoPoseEstimator::AlignmentInformation(std::span<const StereoPoint> kf,
                                                   std::span<const StereoPoint> cur, const Eigen::Matrix3d& R,
                                                   const Eigen::Vector3d& t, double* chi2) const {
  // J = W [I, -R [p_cur]x] for [dt; dtheta] with R <- R Exp(dtheta).
  Matrix6d H = Matrix6d::Zero();
  *chi2 = 0.0;
  for (size_t i = 0; i < kf.size(); ++i) {
    if (!inliers_[i]) continue;
    Eigen::Matrix3d W;
    if (!Whitening(kf[i], cur[i], R, &W)) continue;
    Eigen::Matrix<double, 3, 6> J;
    J.leftCols<3>() = W;
    J.rightCols<3>() = -W * R * so3::Skew(cur[i].p);
    H.noalias() += J.transpose() * J;
    *chi2 += (W * (R * cur[i].p + t - kf[i].p)).squaredNorm();
  }
  return H;
}

bool StereoPoseEstimator::Adjust(std::span<const StereoObservation> kf_seen,
                                 std::span<const StereoObservation> cur_seen, std::span<const StereoPoint> kf,
                                 Eigen::Matrix3d* R, Eigen::Vector3d* t, Matrix6d* information, double* chi2,
                                 int* inliers) {
  BundleResult b;
  const int iterations = static_cast<int>(options_.bundle_iterations);
  if (!bundle_.Adjust(kf_seen, cur_seen, kf, inliers_, *R, *t, iterations, &b)) return false;
  // A pair the alignment accepted can still disagree with the pixels of the other frame once the
  // points are free; about chi-square(3) per pair, so the same threshold.
  const std::vector<double>& c = bundle_.point_chi2();
  bool dropped = false;
  for (size_t i = 0; i < inliers_.size(); ++i) {
    if (inliers_[i] && !(c[i] < options_.inlier_chi2)) {
      inliers_[i] = 0;
      dropped = true;
    }
  }
  if (dropped && !bundle_.Adjust(kf_seen, cur_seen, kf, inliers_, b.R, b.t, iterations, &b)) return false;
  *R = b.R;
  *t = b.t;
  *information = b.information;
  *chi2 = b.chi2;
  *inliers = b.points;
  return true;
}

PoseEstimate StereoPoseEstimator::Estimate(std::span<const StereoObservation> kf_seen,
                                           std::span<const StereoObservation> cur_seen,
                                           std::span<const StereoPoint> kf, std::span<const StereoPoint> cur,
                                           uint64_t seed) {
  PoseEstimate out;
  const size_t n = std::min({kf.size(), cur.size(), kf_seen.size(), cur_seen.size()});
  kf = kf.first(n);
  cur = cur.first(n);
  kf_seen = kf_seen.first(n);
  cur_seen = cur_seen.first(n);
  inliers_.assign(n, 0);
  candidate_.assign(n, 0);
  if (n < static_cast<size_t>(std::max<int64_t>(3, options_.min_inliers))) {
    out.status = VoStatus::kTooFewInliers;
    return out;
  }
  trace_bound_.resize(n);
  for (size_t i = 0; i < n; ++i) trace_bound_[i] = kf[i].cov.trace() + cur[i].cov.trace();

  // RANSAC: minimal samples of 3 pairs, Umeyama (no scale) per sample, adaptive stopping.
  SplitMix rng{seed};
  Eigen::Matrix3d best_R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d best_t = Eigen::Vector3d::Zero();
  int best = -1;
  int64_t needed = options_.ransac_iterations;
  int it = 0;
  Eigen::Matrix3d src, dst;
  for (; it < needed; ++it) {
    size_t idx[3];
    idx[0] = rng.Below(n);
    do idx[1] = rng.Below(n); while (idx[1] == idx[0]);
    do idx[2] = rng.Below(n); while (idx[2] == idx[0] || idx[2] == idx[1]);
    for (int k = 0; k < 3; ++k) {
      src.col(k) = cur[idx[k]].p;
      dst.col(k) = kf[idx[k]].p;
    }
    // A sliver triangle fixes no rotation about its long axis.
    const double area = (src.col(1) - src.col(0)).cross(src.col(2) - src.col(0)).norm();
    if (area < 1e-4) continue;
    const Eigen::Matrix4d T = Eigen::umeyama(src, dst, false);
    const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
    const Eigen::Vector3d t = T.topRightCorner<3, 1>();
    int score = Score(R, t, kf, cur, &candidate_);
    if (score > best) {
      best = score;
      best_R = R;
      best_t = t;
      inliers_.swap(candidate_);
      // Local optimization: a minimal sample of noisy points is a rough hypothesis; refitting
      // on its inliers usually gathers many more.
      for (int lo = 0; lo < 3 && best >= 3; ++lo) {
        Eigen::Matrix3d R2 = best_R;
        Eigen::Vector3d t2 = best_t;
        if (!GaussNewtonStep(kf, cur, inliers_, &R2, &t2) || !GaussNewtonStep(kf, cur, inliers_, &R2, &t2)) break;
        score = Score(R2, t2, kf, cur, &candidate_);
        if (score <= best) break;
        best = score;
        best_R = R2;
        best_t = t2;
        inliers_.swap(candidate_);
      }
      score = best;
      const double w = static_cast<double>(score) / static_cast<double>(n);
      const double p_fail = 1.0 - w * w * w;
      if (p_fail <= 1e-12) {
        needed = std::min<int64_t>(needed, it + 1);
      } else if (p_fail < 1.0) {
        const double k = std::log(1.0 - options_.ransac_confidence) / std::log(p_fail);
        if (k < static_cast<double>(options_.ransac_iterations)) needed = static_cast<int64_t>(std::ceil(k)) + 1;
      }
    }
  }
  out.ransac_iterations = it;
  if (best < options_.min_inliers) {
    out.status = VoStatus::kTooFewInliers;
    out.inliers = std::max(best, 0);
    return out;
  }

  // Refine on the inliers, re-select them with the exact per-pair covariance, refine again.
  Eigen::Matrix3d R = best_R;
  Eigen::Vector3d t = best_t;
  for (int round = 0; round < 2; ++round) {
    if (!Refine(kf, cur, &R, &t)) {
      out.status = VoStatus::kDegenerate;
      return out;
    }
    int count = 0;
    bool changed = false;
    for (size_t i = 0; i < n; ++i) {
      Eigen::Matrix3d W;
      bool in = false;
      if (Whitening(kf[i], cur[i], R, &W)) in = (W * (R * cur[i].p + t - kf[i].p)).squaredNorm() < options_.inlier_chi2;
      changed = changed || (in != (inliers_[i] != 0));
      inliers_[i] = in ? 1 : 0;
      count += in ? 1 : 0;
    }
    best = count;
    if (!changed) break;
  }
  out.inliers = best;
  if (best < options_.min_inliers) {
    out.status = VoStatus::kTooFewInliers;
    return out;
  }

  // Covariance: the inverse of the information of the stage that gave the pose.
  Matrix6d H;
  double chi2 = 0.0;
  if (options_.bundle_iterations > 0) {
    if (!Adjust(kf_seen, cur_seen, kf, &R, &t, &H, &chi2, &best)) {
      out.status = VoStatus::kDegenerate;
      return out;
    }
    out.inliers = best;
    if (best < options_.min_inliers) {
      out.status = VoStatus::kTooFewInliers;
      return out;
    }
  } else {
    H = AlignmentInformation(kf, cur, R, t, &chi2);
  }
  out.rms_mahalanobis = std::sqrt(chi2 / (3.0 * best));
  Vector6d ev;
  Matrix6d V;
  if (!SymmetricEigen(H, &ev, &V) || ev.minCoeff() <= 1e-12 * std::max(1.0, ev.maxCoeff())) {
    out.status = VoStatus::kDegenerate;
    return out;
  }
  out.covariance = V * ev.cwiseInverse().asDiagonal() * V.transpose();
  out.covariance = 0.5 * (out.covariance + out.covariance.transpose()).eval();
  out.T_kf_cur.linear() = R;
  out.T_kf_cur.translation() = t;
  const Eigen::Matrix3d cov_t = out.covariance.topLeftCorner<3, 3>(), cov_r = out.covariance.bottomRightCorner<3, 3>();
  const double sigma_t = std::sqrt(SymmetricEigenvalues(cov_t).maxCoeff());
  const double sigma_r = std::sqrt(SymmetricEigenvalues(cov_r).maxCoeff());
  if (sigma_t > options_.max_sigma_translation || sigma_r * 180.0 / M_PI > options_.max_sigma_rotation_deg) {
    out.status = VoStatus::kDegenerate;
    return out;
  }
  out.status = VoStatus::kOk;
  return out;
}

}  // namespace cairn
