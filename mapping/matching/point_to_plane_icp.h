#pragma once
// The point-to-plane ICP loop shared by the matcher's 4-DoF refinement (four_dof_icp.h, which
// documents the method) and its 6-DoF variant (six_dof_icp.h). A Model says what moves: its
// transform type, the Jacobian of one residual r = n . (q - a) with respect to its parameters,
// how a Gauss-Newton step updates the transform, and how observable the paired geometry is.
//
// Model requirements (all static):
//   kDof; using Transform; const char* kParameters ("x, y, z, yaw")
//   Eigen::Vector3d Translation(const Transform&)
//   bool Finite(const Transform&)
//   Eigen::Matrix<double, kDof, 1> Jacobian(const Eigen::Vector3d& n, const Eigen::Vector3d& v)  // v = R p
//   Transform Step(const Transform&, const Eigen::Matrix<double, kDof, 1>& step)
//   double RotationChange(const Transform&, const Transform&)  // rad
//   double Observability(const IcpPass<kDof>&, const Transform&)

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "estimation/math/small_cholesky.h"
#include "mapping/matching/icp_options.h"
#include "mapping/matching/icp_target.h"

namespace cairn {

// The normal equations of one correspondence pass, and what the observability check needs.
template <int N>
struct IcpPass {
  size_t n = 0;
  Eigen::Matrix<double, N, N> H = Eigen::Matrix<double, N, N>::Zero();  // J^T J
  Eigen::Matrix<double, N, 1> g = Eigen::Matrix<double, N, 1>::Zero();  // J^T r
  double sum_r2 = 0.0;
  Eigen::Vector3d sum_q = Eigen::Vector3d::Zero();
  double sum_qh2 = 0.0;  // sum of |q_xy|^2
  double sum_qz2 = 0.0;  // sum of q_z^2
};

template <class Transform, int N>
struct IcpOutcome {
  // Ok when converged on well-constrained geometry. Otherwise: kInvalidArgument (options),
  // kFailedPrecondition (too few finite points or target normals; or degenerate geometry, then
  // `degenerate` is set), kNotFound (fewer than min_correspondences overlapping points), kTimeout
  // (not converged within max_iterations), kInternal (a singular system).
  Status status;
  Transform T_a_b;  // the last estimate (the initial one when no step was made)
  Eigen::Matrix<double, N, N> covariance = Eigen::Matrix<double, N, N>::Zero();  // set when ok
  bool converged = false;
  bool degenerate = false;
  int64_t iterations = 0;  // Gauss-Newton steps
  size_t inliers = 0;      // correspondences of the final pass
  double rms = 0.0;        // m; RMS point-to-plane residual of the final pass
  double overlap = 0.0;    // inliers / finite source points
  double observability = 0.0;
  size_t skipped_source = 0;  // non-finite points
  size_t skipped_target = 0;
  size_t target_normals = 0;  // target points with a good normal

  bool ok() const { return status.ok(); }
};

std::string IcpNumber(double v);

template <class Model>
IcpOutcome<typename Model::Transform, Model::kDof> AlignPointToPlane(
    const IcpOptions& options, std::span<const Eigen::Vector3d> target_a,
    std::span<const Eigen::Vector3d> source_b, const typename Model::Transform& T_a_b_initial) {
  constexpr int N = Model::kDof;
  using Transform = typename Model::Transform;
  using Vector = Eigen::Matrix<double, N, 1>;
  using Matrix = Eigen::Matrix<double, N, N>;
  IcpOutcome<Transform, N> res;
  res.T_a_b = T_a_b_initial;
  if (Status s = options.Validate(); !s.ok()) {
    res.status = s;
    return res;
  }
  if (!Model::Finite(T_a_b_initial)) {
    res.status = InvalidArgumentError("icp: non-finite initial transform");
    return res;
  }
  const IcpTarget target(target_a, options);
  const std::vector<Eigen::Vector3d> source = IcpTarget::FinitePoints(source_b, &res.skipped_source);
  res.skipped_target = target.skipped();
  const size_t min_points = static_cast<size_t>(options.min_correspondences);
  const auto too_few = [&](const char* name, size_t finite, size_t skipped) {
    if (finite >= min_points) return false;
    const std::string what = finite == 0 && skipped == 0
                                 ? std::string("is empty")
                                 : "has " + std::to_string(finite) + " finite points (" + std::to_string(skipped) +
                                       " non-finite skipped)";
    res.status = FailedPreconditionError(std::string("icp: ") + name + " cloud " + what + ", need " +
                                         std::to_string(min_points));
    return true;
  };
  if (too_few("source", source.size(), res.skipped_source) ||
      too_few("target", target.size(), res.skipped_target))
    return res;
  res.target_normals = target.good_normals();
  if (res.target_normals < min_points) {
    res.status = FailedPreconditionError("icp: only " + std::to_string(res.target_normals) + " of " +
                                         std::to_string(target.size()) +
                                         " target points have a planar neighbourhood, need " +
                                         std::to_string(min_points));
    return res;
  }

  IcpPairs pairs(target, source.size(), options.unique_targets);
  const auto accumulate = [&](const Transform& T) {
    IcpPass<N> pass;
    for (const auto& [s, idx] : pairs.pairs()) {
      const Eigen::Vector3d q = T * source[s];
      const Eigen::Vector3d& nrm = target.normal(idx);
      const double r = nrm.dot(q - target.point(idx));
      const Vector J = Model::Jacobian(nrm, q - Model::Translation(T));
      pass.H.noalias() += J * J.transpose();
      pass.g += J * r;
      pass.sum_r2 += r * r;
      pass.sum_q += q;
      pass.sum_qh2 += q.template head<2>().squaredNorm();
      pass.sum_qz2 += q.z() * q.z();
      ++pass.n;
    }
    return pass;
  };

  Transform T = T_a_b_initial;
  double gate = options.max_correspondence_distance;
  Vector step = Vector::Zero();
  Matrix L = Matrix::Zero();  // Cholesky factor of the last usable pass's J^T J
  // Checks one pass; false (with the status set) when it cannot be used.
  const auto usable = [&](const IcpPass<N>& pass, double gate_used) {
    res.inliers = pass.n;
    if (pass.n < min_points) {
      res.status = NotFoundError("icp: too few overlapping points: " + std::to_string(pass.n) + " within " +
                                 IcpNumber(gate_used) + " m, need " + std::to_string(min_points));
      return false;
    }
    res.observability = Model::Observability(pass, T);
    if (res.observability < options.min_observability) {
      res.degenerate = true;
      res.status = FailedPreconditionError("icp: degenerate geometry: observability " +
                                           IcpNumber(res.observability) + " < " +
                                           IcpNumber(options.min_observability) + " (the clouds leave a combination of " +
                                           Model::kParameters + " free)");
      return false;
    }
    if (!small_cholesky::Factor<N>(pass.H, &L)) {
      res.status = InternalError("icp: singular normal equations");
      return false;
    }
    return true;
  };
  // Within the tolerances: no motion worth another pass.
  const auto same = [&](const Transform& a, const Transform& b) {
    return (Model::Translation(a) - Model::Translation(b)).norm() < options.translation_tolerance &&
           Model::RotationChange(a, b) < options.yaw_tolerance;
  };
  // Near the optimum the pairs can cycle through a few sets, and the estimate with them, by
  // less than its standard deviation but for ever: after freeze_after passes at the gate's floor
  // the pairs stay as they are and Gauss-Newton converges on them.
  int64_t passes_at_floor = 0;
  bool frozen = false;
  const auto pass_at = [&](const Transform& T_now) {
    if (!frozen) pairs.Pair([&](const Eigen::Vector3d& p) { return Eigen::Vector3d(T_now * p); }, source, gate);
    return accumulate(T_now);
  };
  for (int64_t it = 0; it < options.max_iterations; ++it) {
    const IcpPass<N> pass = pass_at(T);
    if (!usable(pass, gate)) return res;
    step = -pass.g;
    small_cholesky::SolveLower<N>(L, step);
    small_cholesky::SolveLowerTransposed<N>(L, step);
    const Transform previous = T;
    T = Model::Step(T, step);
    res.T_a_b = T;
    res.iterations = it + 1;
    if (gate <= options.min_correspondence_distance) {
      // The step in standard deviations of the estimate: step^T (J^T J / sigma^2) step, where
      // step^T J^T J step = -step . J^T r for the Gauss-Newton step.
      const double sigma2 = pass.sum_r2 / (static_cast<double>(pass.n) - N);
      const double step_sigmas2 = -step.dot(pass.g) / sigma2;
      if (same(T, previous) || step_sigmas2 < options.max_step_sigmas * options.max_step_sigmas) {
        res.converged = true;
        break;
      }
      frozen = frozen || ++passes_at_floor >= options.freeze_after;
    }
    gate = std::max(options.min_correspondence_distance, gate * options.gate_shrink);
  }

  // The final pass at the final estimate: inliers, residual and covariance.
  const IcpPass<N> pass = pass_at(T);
  if (!usable(pass, gate)) return res;
  const double n = static_cast<double>(pass.n);
  res.rms = std::sqrt(pass.sum_r2 / n);
  res.overlap = n / static_cast<double>(source.size());
  if (!res.converged) {
    res.status = TimeoutError("icp: not converged within " + std::to_string(options.max_iterations) +
                              " iterations (last step " + IcpNumber(step.template head<3>().norm()) + " m, " +
                              IcpNumber(step.template tail<N - 3>().norm()) + " rad)");
    return res;
  }
  // Sigma = sigma^2 (J^T J)^-1, column by column from the Cholesky factor of J^T J.
  const double sigma2 = pass.sum_r2 / (n - N);
  Matrix inverse;
  for (int i = 0; i < N; ++i) {
    Vector e = Vector::Unit(i);
    small_cholesky::SolveLower<N>(L, e);
    small_cholesky::SolveLowerTransposed<N>(L, e);
    inverse.col(i) = e;
  }
  res.covariance = sigma2 * 0.5 * (inverse + inverse.transpose());
  res.status = Status::Ok();
  return res;
}

}  // namespace cairn
