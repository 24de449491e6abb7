#include "estimation/math/inverse_depth_point.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cairn {
namespace {

// Azimuth and elevation of a direction `v` of any length, and their Jacobian with respect to v
// (scale-free, so callers may pass unnormalized rays and chain through linear maps).
Eigen::Vector2d InverseDepthAnglesOf(const Eigen::Vector3d& v, Eigen::Matrix<double, 2, 3>* J) {
  const double h2 = v.x() * v.x() + v.y() * v.y();
  const double h = std::sqrt(h2);
  const double n2 = h2 + v.z() * v.z();
  if (J) {
    *J << -v.y() / h2, v.x() / h2, 0.0,  //
        -v.z() * v.x() / (h * n2), -v.z() * v.y() / (h * n2), h / n2;
  }
  return {std::atan2(v.y(), v.x()), std::atan2(v.z(), h)};
}

}  // namespace

InverseDepthPoint::InverseDepthPoint(const Eigen::Vector3d& anchor_w, const Eigen::Vector3d& ray_w,
                                     double rho) {
  state_.head<3>() = anchor_w;
  state_.segment<2>(3) = InverseDepthAnglesOf(ray_w, nullptr);
  state_(5) = rho;
}

InverseDepthPoint InverseDepthPoint::FromObservation(const Eigen::Isometry3d& T_w_c,
                                                     const Eigen::Vector2d& xy, double sigma_xy,
                                                     double rho_init, double sigma_rho, Matrix6* cov,
                                                     const Eigen::Matrix3d& anchor_cov) {
  const Eigen::Matrix3d& R = T_w_c.linear();
  const Eigen::Vector3d ray_w = R * Eigen::Vector3d(xy.x(), xy.y(), 1.0);
  Eigen::Matrix<double, 2, 3> J_angles_ray;
  Vector6 state;
  state << T_w_c.translation(), InverseDepthAnglesOf(ray_w, &J_angles_ray), rho_init;
  if (cov) {
    // d ray_w / d(x, y) is the first two columns of R.
    const Eigen::Matrix2d G = J_angles_ray * R.leftCols<2>();
    cov->setZero();
    cov->topLeftCorner<3, 3>() = anchor_cov;
    cov->block<2, 2>(3, 3) = (sigma_xy * sigma_xy) * G * G.transpose();
    (*cov)(5, 5) = sigma_rho * sigma_rho;
  }
  return InverseDepthPoint(state);
}

InverseDepthPoint InverseDepthPoint::FromStereo(const Eigen::Isometry3d& T_w_c, const Eigen::Vector3d& p_c,
                                                const Eigen::Matrix3d& cov_c, Matrix6* cov) {
  const Eigen::Matrix3d& R = T_w_c.linear();
  const double r = p_c.norm();
  Eigen::Matrix<double, 2, 3> J_angles_ray;
  Vector6 state;
  state << T_w_c.translation(), InverseDepthAnglesOf(R * p_c, &J_angles_ray), 1.0 / r;
  if (cov) {
    Eigen::Matrix3d J;  // (theta, phi, rho) with respect to p_c
    J.topRows<2>() = J_angles_ray * R;
    J.row(2) = -p_c.transpose() / (r * r * r);
    cov->setZero();
    cov->bottomRightCorner<3, 3>() = J * cov_c * J.transpose();
  }
  return InverseDepthPoint(state);
}

InverseDepthPoint InverseDepthPoint::FromEuclidean(const Eigen::Vector3d& anchor_w,
                                                   const Eigen::Vector3d& p_w) {
  const Eigen::Vector3d d = p_w - anchor_w;
  return InverseDepthPoint(anchor_w, d, 1.0 / d.norm());
}

Eigen::Vector3d InverseDepthPoint::Ray() const {
  const double cp = std::cos(phi());
  return {cp * std::cos(theta()), cp * std::sin(theta()), std::sin(phi())};
}

Eigen::Vector3d InverseDepthPoint::Euclidean(Matrix36* J) const {
  const double ct = std::cos(theta()), st = std::sin(theta());
  const double cp = std::cos(phi()), sp = std::sin(phi());
  const Eigen::Vector3d m(cp * ct, cp * st, sp);
  const double inv_rho = 1.0 / rho();
  if (J) {
    J->leftCols<3>().setIdentity();
    J->col(3) = inv_rho * Eigen::Vector3d(-cp * st, cp * ct, 0.0);
    J->col(4) = inv_rho * Eigen::Vector3d(-sp * ct, -sp * st, cp);
    J->col(5) = -inv_rho * inv_rho * m;
  }
  return anchor() + inv_rho * m;
}

bool InverseDepthPoint::Project(const Eigen::Isometry3d& T_w_c, Eigen::Vector2d* xy, Matrix26* H) const {
  const double ct = std::cos(theta()), st = std::sin(theta());
  const double cp = std::cos(phi()), sp = std::sin(phi());
  const Eigen::Vector3d m(cp * ct, cp * st, sp);
  const Eigen::Matrix3d Rt = T_w_c.linear().transpose();
  const Eigen::Vector3d anchor_from_camera = anchor() - T_w_c.translation();
  // rho * (p - t) in the camera frame: the same direction as p - t for rho > 0, finite at rho = 0.
  const Eigen::Vector3d h = Rt * (rho() * anchor_from_camera + m);
  if (!(h.z() > 1e-9 * h.norm())) return false;
  const double inv_z = 1.0 / h.z();
  *xy = h.head<2>() * inv_z;
  if (H) {
    Eigen::Matrix<double, 2, 3> J_xy_h;
    J_xy_h << inv_z, 0.0, -h.x() * inv_z * inv_z,  //
        0.0, inv_z, -h.y() * inv_z * inv_z;
    Eigen::Matrix<double, 3, 6> J_h_state;
    J_h_state.leftCols<3>() = rho() * Rt;
    J_h_state.col(3) = Rt * Eigen::Vector3d(-cp * st, cp * ct, 0.0);
    J_h_state.col(4) = Rt * Eigen::Vector3d(-sp * ct, -sp * st, cp);
    J_h_state.col(5) = Rt * anchor_from_camera;
    *H = J_xy_h * J_h_state;
  }
  return true;
}

bool InverseDepthPoint::ProjectPixels(const Eigen::Isometry3d& T_w_c, double f, double cx, double cy,
                                      Eigen::Vector2d* uv, Matrix26* H) const {
  Eigen::Vector2d xy;
  if (!Project(T_w_c, &xy, H)) return false;
  *uv = Eigen::Vector2d(f * xy.x() + cx, f * xy.y() + cy);
  if (H) *H *= f;
  return true;
}

double InverseDepthPoint::EuclideanLinearityIndex(const Matrix6& cov, const Eigen::Isometry3d& T_w_c) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (!(rho() > 0.0)) return kInf;
  Matrix36 J;
  const Eigen::Vector3d p_w = Euclidean(&J);
  const Eigen::Vector3d axis_w = T_w_c.linear().col(2);
  const double z = axis_w.dot(p_w - T_w_c.translation());
  if (!(z > 0.0)) return kInf;
  const Eigen::Matrix<double, 1, 6> dz = axis_w.transpose() * J;
  const double var_z = dz * cov * dz.transpose();
  return 2.0 * std::sqrt(std::max(var_z, 0.0)) / z;
}

}  // namespace cairn
