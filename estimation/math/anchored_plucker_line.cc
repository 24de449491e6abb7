#include "estimation/math/anchored_plucker_line.h"

#include <algorithm>
#include <cmath>

#include "estimation/math/so3.h"

namespace cairn {

namespace {

// K^-1 of the Pluecker intrinsic matrix: K = f^2 Kc^-T, so K^-1 = Kc^T / f^2.
Eigen::Matrix3d AnchoredPluckerIntrinsicInverse(const LinePinhole& cam) {
  Eigen::Matrix3d k_inv;
  const double f2 = cam.f * cam.f;
  k_inv << 1.0 / cam.f, 0.0, 0.0, 0.0, 1.0 / cam.f, 0.0, cam.cx / f2, cam.cy / f2, 1.0 / f2;
  return k_inv;
}

// Ray direction (camera frame, z = 1) of pixel u.
Eigen::Vector3d AnchoredPluckerPixelRay(const LinePinhole& cam, const Eigen::Vector2d& u) {
  return Eigen::Vector3d((u.x() - cam.cx) / cam.f, (u.y() - cam.cy) / cam.f, 1.0);
}

}  // namespace

AnchoredPluckerLine::AnchoredPluckerLine(const Eigen::Vector3d& p0, const Eigen::Vector3d& n,
                                         const Eigen::Vector3d& v) {
  x_ << p0, n, v;
}

AnchoredPluckerLine AnchoredPluckerLine::ThroughPoints(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                       const Eigen::Vector3d& anchor) {
  const Eigen::Vector3d v = b - a;
  AnchoredPluckerLine line(anchor, (a - anchor).cross(v), v);
  line.t_ = Eigen::Vector2d(line.Abscissa(a), line.Abscissa(b));
  return line;
}

Eigen::Vector3d AnchoredPluckerLine::ClosestPointToAnchor() const {
  const Eigen::Vector3d v = this->v();
  return anchor() + v.cross(n()) / v.squaredNorm();
}

AnchoredPluckerLine AnchoredPluckerLine::Transformed(const Eigen::Isometry3d& T_a_b) const {
  const Eigen::Matrix3d R = T_a_b.linear();
  AnchoredPluckerLine out(T_a_b * anchor(), R * n(), R * v());
  out.t_ = t_;
  return out;
}

Eigen::Matrix<double, 6, 1> AnchoredPluckerLine::Unanchored() const {
  Eigen::Matrix<double, 6, 1> plucker;
  plucker << n() + anchor().cross(v()), v();
  return plucker;
}

Eigen::Matrix3d AnchoredPluckerLine::PluckerIntrinsic(const LinePinhole& cam) {
  Eigen::Matrix3d k;
  k << cam.f, 0.0, 0.0, 0.0, cam.f, 0.0, -cam.f * cam.cx, -cam.f * cam.cy, cam.f * cam.f;
  return k;
}

Eigen::Vector3d AnchoredPluckerLine::Project(const LinePinhole& cam, const Eigen::Isometry3d& T_w_c,
                                             Eigen::Matrix<double, 3, 9>* J) const {
  const Eigen::Matrix3d KRt = PluckerIntrinsic(cam) * T_w_c.linear().transpose();
  const Eigen::Vector3d d = anchor() - T_w_c.translation();  // p0 - T
  if (J != nullptr) {
    J->block<3, 3>(0, 0) = -KRt * so3::Skew(v());
    J->block<3, 3>(0, 3) = KRt;
    J->block<3, 3>(0, 6) = KRt * so3::Skew(d);
  }
  return KRt * (n() + d.cross(v()));
}

Eigen::Vector2d AnchoredPluckerLine::SegmentResidual(const LinePinhole& cam, const Eigen::Isometry3d& T_w_c,
                                                     const Eigen::Vector2d& u1, const Eigen::Vector2d& u2,
                                                     Eigen::Matrix<double, 2, 9>* J) const {
  Eigen::Matrix<double, 3, 9> J_l;
  const Eigen::Vector3d l = Project(cam, T_w_c, J != nullptr ? &J_l : nullptr);
  const double rho = std::hypot(l.x(), l.y());
  Eigen::Vector2d r;
  Eigen::Matrix<double, 2, 3> dr_dl;
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector3d x = (i == 0 ? u1 : u2).homogeneous();
    const double lx = l.dot(x);
    r(i) = lx / rho;
    dr_dl.row(i) = x.transpose() / rho - (lx / (rho * rho * rho)) * Eigen::RowVector3d(l.x(), l.y(), 0.0);
  }
  if (J != nullptr) *J = dr_dl * J_l;
  return r;
}

bool AnchoredPluckerLine::UpdateWithSegment(const LinePinhole& cam, const Eigen::Isometry3d& T_w_c,
                                            const Eigen::Vector2d& u1, const Eigen::Vector2d& u2,
                                            double pixel_sigma, Matrix9* cov, double* nis) {
  Eigen::Matrix<double, 2, 9> H;
  const Eigen::Vector2d r = SegmentResidual(cam, T_w_c, u1, u2, &H);
  const double noise = pixel_sigma * pixel_sigma;
  const Eigen::Matrix<double, 9, 2> PHt = *cov * H.transpose();
  const Eigen::Matrix2d S = H * PHt + noise * Eigen::Matrix2d::Identity();
  const double det = S.determinant();
  if (!(det > 0.0) || !std::isfinite(det)) return false;
  const Eigen::Matrix2d S_inv = S.inverse();
  const Eigen::Matrix<double, 9, 2> K = PHt * S_inv;
  if (nis != nullptr) *nis = r.dot(S_inv * r);
  x_ -= K * r;  // the measurement is r = 0
  // Joseph form: keeps the rank-deficient (gauge) covariance symmetric and positive semi-definite.
  const Matrix9 IKH = Matrix9::Identity() - K * H;
  Matrix9 P = IKH * *cov * IKH.transpose() + noise * K * K.transpose();
  *cov = 0.5 * (P + P.transpose());
  EnforcePluckerConstraint(cov);
  return true;
}

AnchoredPluckerLine::Vector9 AnchoredPluckerLine::ConstrainedState(const Vector9& x, Matrix9* J) {
  const Eigen::Vector3d n = x.segment<3>(3);
  const Eigen::Vector3d v = x.tail<3>();
  const double vv = v.squaredNorm();
  const double nv = n.dot(v);
  Vector9 out = x;
  out.segment<3>(3) = n - (nv / vv) * v;
  if (J != nullptr) {
    J->setIdentity();
    J->block<3, 3>(3, 3) = Eigen::Matrix3d::Identity() - v * v.transpose() / vv;
    J->block<3, 3>(3, 6) = -(v * n.transpose() + nv * Eigen::Matrix3d::Identity()) / vv +
                           (2.0 * nv / (vv * vv)) * v * v.transpose();
  }
  return out;
}

void AnchoredPluckerLine::EnforcePluckerConstraint(Matrix9* cov) {
  Matrix9 G;
  x_ = ConstrainedState(x_, &G);
  if (cov != nullptr) {
    const Matrix9 P = G * *cov * G.transpose();
    *cov = 0.5 * (P + P.transpose());
  }
}

bool AnchoredPluckerLine::BackProject(const LinePinhole& cam, const Eigen::Isometry3d& T_w_c,
                                      const Eigen::Vector2d& u1, const Eigen::Vector2d& u2,
                                      const Eigen::Vector2d& beta, Vector9* x,
                                      Eigen::Matrix<double, 9, 6>* J) {
  const Eigen::Vector3d x1 = u1.homogeneous();
  const Eigen::Vector3d x2 = u2.homogeneous();
  const Eigen::Matrix3d K_inv = AnchoredPluckerIntrinsicInverse(cam);
  // eq. 14 with l = x1 x x2: n_raw = (Kc^-1 x1) x (Kc^-1 x2), the normal of the plane of both rays.
  const Eigen::Vector3d n_raw = K_inv * x1.cross(x2);
  const double n_norm = n_raw.norm();
  if ((u2 - u1).norm() < 1e-6 || !(n_norm > 0.0)) return false;
  const Eigen::Vector3d n_c = n_raw / n_norm;
  const double rho = std::hypot(n_c.x(), n_c.y());
  if (rho < 1e-12) return false;
  // eqs. 16-17: e1 parallel to the image plane, e2 completing a basis of the plane normal to n^c.
  const Eigen::Vector3d e1 = Eigen::Vector3d(n_c.y(), -n_c.x(), 0.0) / rho;
  const Eigen::Vector3d e2 = n_c.cross(e1);
  const Eigen::Vector3d v_c = beta.x() * e1 + beta.y() * e2;  // eq. 15
  const Eigen::Matrix3d R = T_w_c.linear();
  *x << T_w_c.translation(), R * n_c, R * v_c;  // eq. 19
  if (J != nullptr) {
    Eigen::Matrix<double, 3, 4> dl_du;
    dl_du.leftCols<2>() = -so3::Skew(x2).leftCols<2>();
    dl_du.rightCols<2>() = so3::Skew(x1).leftCols<2>();
    const Eigen::Matrix<double, 3, 4> dn_du =
        (Eigen::Matrix3d::Identity() - n_c * n_c.transpose()) / n_norm * K_inv * dl_du;
    Eigen::Matrix3d W = Eigen::Matrix3d::Zero();
    W(0, 1) = 1.0;
    W(1, 0) = -1.0;
    const Eigen::Matrix3d de1_dn = (Eigen::Matrix3d::Identity() - e1 * e1.transpose()) * W / rho;
    const Eigen::Matrix3d de2_dn = -so3::Skew(e1) + so3::Skew(n_c) * de1_dn;
    J->setZero();
    J->block<3, 4>(3, 0) = R * dn_du;
    J->block<3, 4>(6, 0) = R * (beta.x() * de1_dn + beta.y() * de2_dn) * dn_du;
    J->block<3, 1>(6, 4) = R * e1;
    J->block<3, 1>(6, 5) = R * e2;
  }
  return true;
}

bool AnchoredPluckerLine::InitializeFromSegment(const LinePinhole& cam, const Eigen::Isometry3d& T_w_c,
                                                const Eigen::Vector2d& u1, const Eigen::Vector2d& u2,
                                                double pixel_sigma, const LineBetaPrior& prior,
                                                const Eigen::Matrix3d& anchor_cov, AnchoredPluckerLine* line,
                                                Matrix9* cov) {
  Vector9 x;
  Eigen::Matrix<double, 9, 6> J;
  if (!BackProject(cam, T_w_c, u1, u2, prior.beta, &x, &J)) return false;
  Eigen::Matrix<double, 6, 1> variances;
  const double pixel_var = pixel_sigma * pixel_sigma;
  variances << pixel_var, pixel_var, pixel_var, pixel_var, prior.sigma.cwiseAbs2();
  *cov = J * variances.asDiagonal() * J.transpose();
  cov->topLeftCorner<3, 3>() += anchor_cov;
  *line = AnchoredPluckerLine(x);
  // The rays lie in the line's support plane, so they meet it (unless parallel to it).
  const Eigen::Vector3d origin = T_w_c.translation();
  Eigen::Vector2d t = Eigen::Vector2d::Zero();
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector3d ray = T_w_c.linear() * AnchoredPluckerPixelRay(cam, i == 0 ? u1 : u2);
    if (!line->AbscissaOfRay(origin, ray, &t(i))) t(i) = 0.0;
  }
  line->t_ = t;
  return true;
}

bool AnchoredPluckerLine::InitializeFromStereo(const Eigen::Isometry3d& T_w_c, const Eigen::Vector3d& p1_c,
                                               const Eigen::Matrix3d& cov1, const Eigen::Vector3d& p2_c,
                                               const Eigen::Matrix3d& cov2, const Eigen::Matrix3d& anchor_cov,
                                               AnchoredPluckerLine* line, Matrix9* cov) {
  const Eigen::Vector3d n_c = p1_c.cross(p2_c);
  const Eigen::Vector3d v_c = p2_c - p1_c;
  if (!(v_c.norm() > 1e-9) || !(n_c.norm() > 1e-12 * p1_c.norm() * p2_c.norm())) return false;
  const Eigen::Matrix3d R = T_w_c.linear();
  *line = AnchoredPluckerLine(T_w_c.translation(), R * n_c, R * v_c);
  line->t_ = Eigen::Vector2d(line->Abscissa(T_w_c * p1_c), line->Abscissa(T_w_c * p2_c));
  Eigen::Matrix<double, 9, 6> J = Eigen::Matrix<double, 9, 6>::Zero();
  J.block<3, 3>(3, 0) = -R * so3::Skew(p2_c);
  J.block<3, 3>(3, 3) = R * so3::Skew(p1_c);
  J.block<3, 3>(6, 0) = -R;
  J.block<3, 3>(6, 3) = R;
  *cov = J.leftCols<3>() * cov1 * J.leftCols<3>().transpose() +
         J.rightCols<3>() * cov2 * J.rightCols<3>().transpose();
  cov->topLeftCorner<3, 3>() += anchor_cov;
  return true;
}

std::array<Eigen::Vector3d, 2> AnchoredPluckerLine::Endpoints() const {
  const Eigen::Vector3d q = ClosestPointToAnchor();
  const Eigen::Vector3d u = UnitDirection();
  return {q + t_.x() * u, q + t_.y() * u};
}

double AnchoredPluckerLine::Abscissa(const Eigen::Vector3d& p) const {
  return (p - ClosestPointToAnchor()).dot(UnitDirection());
}

bool AnchoredPluckerLine::AbscissaOfRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                        double* t) const {
  const Eigen::Vector3d u = UnitDirection();
  const Eigen::Vector3d w0 = ClosestPointToAnchor() - origin;
  const double b = u.dot(dir);
  const double c = dir.squaredNorm();
  const double denom = c - b * b;
  if (!(denom > 1e-12 * c)) return false;
  *t = (b * dir.dot(w0) - c * u.dot(w0)) / denom;
  return true;
}

void AnchoredPluckerLine::ExtendEndpoints(const Eigen::Vector3d& p) {
  const double t = Abscissa(p);
  const int lo = t_.x() <= t_.y() ? 0 : 1;
  const int hi = 1 - lo;
  if (t < t_(lo)) {
    t_(lo) = t;
  } else if (t > t_(hi)) {
    t_(hi) = t;
  }
}

Eigen::Vector4d AnchoredPluckerLine::MinimalError(const AnchoredPluckerLine& truth,
                                                  Eigen::Matrix<double, 4, 9>* J) const {
  const Eigen::Vector3d u = truth.UnitDirection();
  const Eigen::Vector3d n_t = truth.n() - truth.n().dot(u) * u;
  // A line through its own anchor has no support plane: any normal of u will do.
  const Eigen::Vector3d b2 =
      n_t.norm() > 1e-12 * truth.v().norm() ? Eigen::Vector3d(n_t.normalized()) : u.unitOrthogonal();
  const Eigen::Vector3d b1 = u.cross(b2);
  Eigen::Matrix<double, 2, 3> B;
  B << b1.transpose(), b2.transpose();
  const Eigen::Vector3d r = truth.ClosestPointToAnchor();

  const Eigen::Vector3d p0 = anchor();
  const Eigen::Vector3d v = this->v();
  const Eigen::Vector3d m = n() + (p0 - r).cross(v);  // moment about r
  const double c = u.dot(v);
  const double vv = v.squaredNorm();
  const Eigen::Vector3d w = v.cross(m);
  Eigen::Vector4d e;
  e.head<2>() = B * v / c;
  e.tail<2>() = B * w / vv;
  if (J != nullptr) {
    J->setZero();
    J->block<2, 3>(0, 6) = B / c - (B * v / (c * c)) * u.transpose();
    const Eigen::Matrix3d Sv = so3::Skew(v);
    J->block<2, 3>(2, 0) = -B * Sv * Sv / vv;
    J->block<2, 3>(2, 3) = B * Sv / vv;
    J->block<2, 3>(2, 6) =
        B * ((-so3::Skew(m) + Sv * so3::Skew(p0 - r)) / vv - (2.0 / (vv * vv)) * w * v.transpose());
  }
  return e;
}

}  // namespace cairn
