#pragma once
// Ceres cost functors on 6-D poses (the reference residuals; Create() gives the analytic cost
// functions of pose_cost_functions.h, which tests check against AutoDiff() of these). A pose parameter block
// is 7 doubles [tx ty tz qx qy qz qw] on PoseManifold() (R^3 x unit quaternion; the quaternion increment is
// applied on the left, so covariances are in the world frame for rotation). Residual conventions:
//  - Relative pose (geodesic): E = T_ij^-1 T_i^-1 T_j, r = sqrt(Info) [t(E); Log(R(E))]. Used for
//    every binary factor of the thesis (w, v, d, o, c, u) and EDGE_SE3 in the default objective.
//  - Chordal (SE-Sync): r = [sqrt(tau)(R_i^T (t_j - t_i) - t_ij); sqrt(8 kappa) vec(q_ij^-1 q_i^-1 q_j)]
//    (quaternion with w >= 0), so that 2 x Ceres' cost is the SE-Sync objective: |R_i^T (t_j - t_i) - t_ij|
//    = |t_j - t_i - R_i t_ij| and ||R_j - R_i R_ij||_F^2 = 8 sin^2(theta/2) = 8 |vec(q)|^2 for the
//    rotation error by angle theta. Not the 12 residuals [t_j - t_i - R_i t_ij; vec(R_j - R_i R_ij)]
//    of the same sum: their Gauss-Newton model is poor away from the optimum's small residuals
//    (sphere2500: 13 iterations converging linearly instead of 2).
//  - Absolute pose: E = Z^-1 T, r = sqrt(Info) [t(E); Log(R(E))] (prior, GNSS pose, known landmark).
//  - Absolute position: r = sqrt(Info) (t - z) (total-station position fix).
//  - GNSS position, on the datum E = T_world_enu and the pose x: r = sqrt(Info) (R_E^T (t_x + R_x l -
//    t_E) - z) for the antenna at l in the body; z in the datum's east-north-up axes.

#include <memory>

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include "estimation/graph/pose_cost_functions.h"
#include "estimation/graph/pose_graph.h"

namespace cairn {

// R^3 x EigenQuaternion, matching the 7-double layout above.
std::unique_ptr<ceres::Manifold> MakePoseManifold();

// Upper-triangular S with S^T S = information (the residual weight).
Matrix6d SqrtInformation(const Matrix6d& information);

namespace pose_factors_internal {

// q (x y z w) * v and quaternion products on raw arrays, templated for Jets.
template <class T>
Eigen::Quaternion<T> Q(const T* p) {
  return Eigen::Quaternion<T>(p[6], p[3], p[4], p[5]);
}

template <class T>
Eigen::Matrix<T, 3, 1> LogQ(const Eigen::Quaternion<T>& q_in) {
  // Shortest rotation; ceres' conversion is exact and smooth at the identity for Jets.
  Eigen::Quaternion<T> q = q_in;
  if (q.w() < T(0)) q.coeffs() = -q.coeffs();
  const T wxyz[4] = {q.w(), q.x(), q.y(), q.z()};
  Eigen::Matrix<T, 3, 1> aa;
  ceres::QuaternionToAngleAxis(wxyz, aa.data());
  return aa;
}

}  // namespace pose_factors_internal

struct RelativePoseResidual {
  RelativePoseResidual(const Pose3& T_i_j, const Matrix6d& information)
      : t_ij(T_i_j.t), q_ji(T_i_j.q.conjugate()), sqrt_info(SqrtInformation(information)) {}

  template <class T>
  bool operator()(const T* pi, const T* pj, T* out) const {
    using namespace pose_factors_internal;
    using V3 = Eigen::Matrix<T, 3, 1>;
    const Eigen::Quaternion<T> qi = Q(pi), qj = Q(pj);
    const Eigen::Quaternion<T> qi_inv = qi.conjugate();
    const V3 t_rel = qi_inv * (V3(pj[0], pj[1], pj[2]) - V3(pi[0], pi[1], pi[2]));
    const Eigen::Quaternion<T> qji = q_ji.cast<T>();
    Eigen::Matrix<T, 6, 1> e;
    e.template head<3>() = qji * (t_rel - t_ij.cast<T>());
    e.template tail<3>() = LogQ<T>(qji * (qi_inv * qj));
    Eigen::Map<Eigen::Matrix<T, 6, 1>>{out} = sqrt_info.cast<T>() * e;
    return true;
  }

  static ceres::CostFunction* Create(const Pose3& T_i_j, const Matrix6d& information) {
    return new RelativePoseCost(T_i_j, information);
  }

  Eigen::Vector3d t_ij;
  Eigen::Quaterniond q_ji;
  Matrix6d sqrt_info;
};

struct ChordalResidual {
  ChordalResidual(const Pose3& T_i_j, double kappa, double tau)
      : t_ij(T_i_j.t), q_ji(T_i_j.q.conjugate()), sqrt_8kappa(std::sqrt(8.0 * kappa)), sqrt_tau(std::sqrt(tau)) {}

  template <class T>
  bool operator()(const T* pi, const T* pj, T* out) const {
    using namespace pose_factors_internal;
    using V3 = Eigen::Matrix<T, 3, 1>;
    const Eigen::Quaternion<T> qi_inv = Q(pi).conjugate();
    const V3 et = qi_inv * (V3(pj[0], pj[1], pj[2]) - V3(pi[0], pi[1], pi[2])) - t_ij.cast<T>();
    Eigen::Quaternion<T> qe = q_ji.cast<T>() * (qi_inv * Q(pj));
    if (qe.w() < T(0)) qe.coeffs() = -qe.coeffs();
    for (int k = 0; k < 3; ++k) out[k] = T(sqrt_tau) * et[k];
    for (int k = 0; k < 3; ++k) out[3 + k] = T(sqrt_8kappa) * qe.vec()[k];
    return true;
  }

  static ceres::CostFunction* Create(const Pose3& T_i_j, double kappa, double tau) {
    return new ChordalCost(T_i_j, kappa, tau);
  }

  Eigen::Vector3d t_ij;
  Eigen::Quaterniond q_ji;
  double sqrt_8kappa, sqrt_tau;
};

struct AbsolutePoseResidual {
  AbsolutePoseResidual(const Pose3& Z, const Matrix6d& information)
      : t(Z.t), q_inv(Z.q.conjugate()), sqrt_info(SqrtInformation(information)) {}

  template <class T>
  bool operator()(const T* p, T* out) const {
    using namespace pose_factors_internal;
    using V3 = Eigen::Matrix<T, 3, 1>;
    const Eigen::Quaternion<T> qz = q_inv.cast<T>();
    Eigen::Matrix<T, 6, 1> e;
    e.template head<3>() = qz * (V3(p[0], p[1], p[2]) - t.cast<T>());
    e.template tail<3>() = LogQ<T>(qz * Q(p));
    Eigen::Map<Eigen::Matrix<T, 6, 1>>{out} = sqrt_info.cast<T>() * e;
    return true;
  }

  static ceres::CostFunction* Create(const Pose3& Z, const Matrix6d& information) {
    return new AbsolutePoseCost(Z, information);
  }

  Eigen::Vector3d t;
  Eigen::Quaterniond q_inv;
  Matrix6d sqrt_info;
};

struct AbsolutePositionResidual {
  AbsolutePositionResidual(const Eigen::Vector3d& z, const Eigen::Matrix3d& information);

  template <class T>
  bool operator()(const T* p, T* out) const {
    const Eigen::Matrix<T, 3, 1> e(p[0] - T(z_[0]), p[1] - T(z_[1]), p[2] - T(z_[2]));
    Eigen::Map<Eigen::Matrix<T, 3, 1>>{out} = sqrt_info.cast<T>() * e;
    return true;
  }

  // Defined in the .cc: the autodiff cost function is instantiated once, not in every includer.
  static ceres::CostFunction* Create(const Eigen::Vector3d& z, const Eigen::Matrix3d& information);

  Eigen::Vector3d z_;
  Eigen::Matrix3d sqrt_info;
};

struct GnssPositionResidual {
  GnssPositionResidual(const Eigen::Vector3d& z_enu, const Eigen::Matrix3d& information,
                       const Eigen::Vector3d& antenna);

  template <class T>
  bool operator()(const T* datum, const T* pose, T* out) const {
    using namespace pose_factors_internal;
    using V3 = Eigen::Matrix<T, 3, 1>;
    const V3 antenna_world = V3(pose[0], pose[1], pose[2]) + Q(pose) * antenna_.cast<T>();
    const V3 enu = Q(datum).conjugate() * (antenna_world - V3(datum[0], datum[1], datum[2]));
    Eigen::Map<Eigen::Matrix<T, 3, 1>>{out} = sqrt_info.cast<T>() * (enu - z_.cast<T>());
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& z_enu, const Eigen::Matrix3d& information,
                                     const Eigen::Vector3d& antenna);

  Eigen::Vector3d z_;
  Eigen::Matrix3d sqrt_info;
  Eigen::Vector3d antenna_;
};

// Pose <-> parameter block.
inline void PoseToBlock(const Pose3& p, double* b) {
  b[0] = p.t.x(); b[1] = p.t.y(); b[2] = p.t.z();
  b[3] = p.q.x(); b[4] = p.q.y(); b[5] = p.q.z(); b[6] = p.q.w();
}
inline Pose3 BlockToPose(const double* b) {
  return {Eigen::Vector3d(b[0], b[1], b[2]), Eigen::Quaterniond(b[6], b[3], b[4], b[5]).normalized()};
}

}  // namespace cairn
