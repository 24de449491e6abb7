#include "mapping/submap_line_fuser.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/LU>

namespace cairn {
namespace {

constexpr double kLineFuserPi = 3.14159265358979323846;

// Two unit vectors across `d`, the same for the same d: the axes of an edge's shift and tilt.
Eigen::Matrix<double, 3, 2> AcrossBasis(const Eigen::Vector3d& d) {
  const Eigen::Vector3d helper = std::abs(d.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d u1 = d.cross(helper).normalized();
  Eigen::Matrix<double, 3, 2> U;
  U.col(0) = u1;
  U.col(1) = d.cross(u1);
  return U;
}

bool FiniteSighting(const LineSighting& s) {
  return s.a.allFinite() && s.b.allFinite() && s.cov_a.allFinite() && s.cov_b.allFinite() &&
         s.cov_ab.allFinite() && s.viewpoint.allFinite();
}

// Both endpoints' offsets across the line through p along d (U = AcrossBasis(d)), their joint
// covariance, and the offsets' Jacobian with respect to the line's shift and tilt.
struct AcrossOffsets {
  Eigen::Vector4d r;
  Eigen::Matrix4d cov;
  Eigen::Matrix4d J;
};
AcrossOffsets Offsets(const Eigen::Vector3d& p, const Eigen::Vector3d& d,
                      const Eigen::Matrix<double, 3, 2>& U, const Eigen::Vector3d& a,
                      const Eigen::Vector3d& b, const Eigen::Matrix<double, 6, 6>& cov) {
  AcrossOffsets o;
  o.r << U.transpose() * (a - p), U.transpose() * (b - p);
  Eigen::Matrix<double, 4, 6> P = Eigen::Matrix<double, 4, 6>::Zero();
  P.topLeftCorner<2, 3>() = U.transpose();
  P.bottomRightCorner<2, 3>() = U.transpose();
  o.cov = P * cov * P.transpose();
  const double sa = d.dot(a - p), sb = d.dot(b - p);
  o.J << -Eigen::Matrix2d::Identity(), -sa * Eigen::Matrix2d::Identity(), -Eigen::Matrix2d::Identity(),
      -sb * Eigen::Matrix2d::Identity();
  return o;
}

Eigen::Matrix<double, 6, 6> JointCovariance(const LineSighting& s) {
  Eigen::Matrix<double, 6, 6> c;
  c << s.cov_a, s.cov_ab, s.cov_ab.transpose(), s.cov_b;
  return c;
}

}  // namespace

SubmapLineFuser::SubmapLineFuser(const LineFusionOptions& options)
    : options_(options), cos_max_angle_(std::cos(options.max_angle * kLineFuserPi / 180.0)) {
  edges_.reserve(static_cast<size_t>(options.max_lines));
}

void SubmapLineFuser::Reset() {
  for (size_t i = 0; i < used_; ++i) edges_[i].segments.clear();  // capacity kept for the next submap
  used_ = 0;
}

double SubmapLineFuser::Distance(const Edge& e, const LineSighting& s) const {
  const Eigen::Vector3d ds = (s.b - s.a).normalized();
  if (std::abs(ds.dot(e.direction)) < cos_max_angle_) return -1.0;
  const double ta = e.direction.dot(s.a - e.point), tb = e.direction.dot(s.b - e.point);
  const double lo = e.direction.dot(e.lo - e.point), hi = e.direction.dot(e.hi - e.point);
  if (std::max(ta, tb) < lo - options_.max_gap || std::min(ta, tb) > hi + options_.max_gap) return -1.0;
  const AcrossOffsets o =
      Offsets(e.point, e.direction, AcrossBasis(e.direction), s.a, s.b, JointCovariance(s));
  // The edge's own uncertainty adds through the same Jacobian (a shift plus abscissa times a tilt).
  const Eigen::Matrix4d S = o.cov + o.J * e.covariance * o.J.transpose();
  return o.r.dot(S.ldlt().solve(o.r));
}

void SubmapLineFuser::Refit(Edge* e) {
  // Gauss-Newton on the edge's four degrees of freedom: p' = p + U t, d' = normalize(d + U w). An
  // endpoint x at abscissa s = d . (x - p) is off the line by r = U^T (x - p), dr/d(t, w) = [-I, -s I];
  // a segment's two endpoints are one residual block (their errors are correlated).
  Eigen::Matrix4d H = Eigen::Matrix4d::Identity();
  double chi2 = 0.0;
  for (int iteration = 0; iteration < 4; ++iteration) {
    const Eigen::Matrix<double, 3, 2> U = AcrossBasis(e->direction);
    H.setZero();
    Eigen::Vector4d g = Eigen::Vector4d::Zero();
    chi2 = 0.0;
    for (const Segment& x : e->segments) {
      const AcrossOffsets o = Offsets(e->point, e->direction, U, x.a, x.b, x.cov);
      const Eigen::Matrix4d W = o.cov.inverse();
      H += o.J.transpose() * W * o.J;
      g += o.J.transpose() * W * o.r;
      chi2 += o.r.dot(W * o.r);
    }
    const Eigen::Vector4d step = -H.ldlt().solve(g);
    if (!step.allFinite()) return;
    e->point += U * step.head<2>();
    e->direction = (e->direction + U * step.tail<2>()).normalized();
    if (step.norm() < 1e-9) break;
  }
  // The reference point at the ends' mean keeps shift and tilt nearly uncorrelated.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Segment& x : e->segments) mean += x.a + x.b;
  mean /= 2.0 * static_cast<double>(e->segments.size());
  const Eigen::Vector3d moved = e->point + e->direction * e->direction.dot(mean - e->point);
  // Moving the reference along the line by s turns a shift t into t + s w: re-express the covariance.
  const double s = e->direction.dot(moved - e->point);
  Eigen::Matrix4d A = Eigen::Matrix4d::Identity();
  A.topRightCorner<2, 2>() = s * Eigen::Matrix2d::Identity();
  e->point = moved;
  Eigen::Matrix4d covariance = A * H.inverse() * A.transpose();
  const double dof = 4.0 * static_cast<double>(e->segments.size()) - 4.0;
  if (dof > 0.0 && chi2 > dof) covariance *= chi2 / dof;
  if (covariance.allFinite()) e->covariance = covariance;
}

void SubmapLineFuser::Extend(Edge* e, const Eigen::Vector3d& p) {
  const double t = e->direction.dot(p - e->point);
  if (t < e->direction.dot(e->lo - e->point)) e->lo = p;
  if (t > e->direction.dot(e->hi - e->point)) e->hi = p;
}

bool SubmapLineFuser::Add(const LineSighting& s) {
  if (!FiniteSighting(s) || (s.b - s.a).norm() < 1e-6) return false;
  int best = -1;
  double best_chi2 = options_.gate_chi2;
  for (size_t i = 0; i < used_; ++i) {
    const double chi2 = Distance(edges_[i], s);
    if (chi2 >= 0.0 && chi2 < best_chi2) {
      best_chi2 = chi2;
      best = static_cast<int>(i);
    }
  }
  if (best < 0) {
    if (used_ >= static_cast<size_t>(options_.max_lines)) return false;
    if (used_ == edges_.size()) edges_.emplace_back();
    Edge& e = edges_[used_++];
    e.anchor = s.viewpoint;
    e.point = 0.5 * (s.a + s.b);
    e.direction = (s.b - s.a).normalized();
    e.lo = s.a;
    e.hi = s.b;
    e.segments.reserve(static_cast<size_t>(options_.max_segments));
    e.segments.clear();
    e.segments.push_back({s.a, s.b, JointCovariance(s)});
    e.sightings = 1;
    Refit(&e);
    return true;
  }
  Edge& e = edges_[static_cast<size_t>(best)];
  ++e.sightings;
  if (e.segments.size() < static_cast<size_t>(options_.max_segments)) {
    e.segments.push_back({s.a, s.b, JointCovariance(s)});
    Refit(&e);
  }
  Extend(&e, s.a);
  Extend(&e, s.b);
  return true;
}

SubmapLine SubmapLineFuser::ToLine(const Edge& e) {
  const Eigen::Vector3d& d = e.direction;
  const Eigen::Vector3d n = (e.point - e.anchor).cross(d);
  const Eigen::Vector3d closest = e.anchor + d.cross(n);
  SubmapLine l;
  l.anchor = e.anchor.cast<float>();
  l.moment = n.cast<float>();
  l.direction = d.cast<float>();
  l.t_min = static_cast<float>(d.dot(e.lo - closest));
  l.t_max = static_cast<float>(d.dot(e.hi - closest));
  // (n, v) from the fit's (shift t, tilt w): n = (p + U t - p0) x (d + U w), v = d + U w.
  const Eigen::Matrix<double, 3, 2> U = AcrossBasis(d);
  Eigen::Matrix<double, 6, 4> J = Eigen::Matrix<double, 6, 4>::Zero();
  for (int i = 0; i < 2; ++i) {
    J.block<3, 1>(0, i) = U.col(i).cross(d);
    J.block<3, 1>(0, 2 + i) = (e.point - e.anchor).cross(U.col(i));
    J.block<3, 1>(3, 2 + i) = U.col(i);
  }
  l.covariance = (J * e.covariance * J.transpose()).cast<float>();
  l.sightings = e.sightings;
  return l;
}

std::vector<SubmapLine> SubmapLineFuser::Lines() const {
  std::vector<SubmapLine> out;
  for (size_t i = 0; i < used_; ++i) {
    const Edge& e = edges_[i];
    if (e.sightings < static_cast<uint32_t>(options_.min_sightings)) continue;
    SubmapLine l = ToLine(e);
    if (l.length() < options_.min_length) continue;
    out.push_back(l);
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const SubmapLine& a, const SubmapLine& b) { return a.length() > b.length(); });
  return out;
}

}  // namespace cairn
