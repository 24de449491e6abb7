#include "mapping/matching/line_associator.h"

#include <algorithm>
#include <cmath>

#include "estimation/math/so3.h"
#include "estimation/math/tangent_axes.h"
#include "mapping/matching/unambiguous_pairs.h"

namespace cairn {
namespace {

using LineAssociatorVector6 = Eigen::Matrix<double, 6, 1>;

// The error e of the line through p along unit v, against the line through c along the direction
// whose tangent axes are (u, w): v on (u, w), and the offset of the line's point closest to c.
Eigen::Vector4d LineErrorAt(const Eigen::Vector3d& p, const Eigen::Vector3d& v, const Eigen::Vector3d& c,
                            const Eigen::Vector3d& u, const Eigen::Vector3d& w) {
  const Eigen::Vector3d offset = p + (c - p).dot(v) * v - c;
  return {u.dot(v), w.dot(v), u.dot(offset), w.dot(offset)};
}

Eigen::Vector3d LineAt(const SubmapLine& l, double t) {
  const Eigen::Vector3d v = l.direction.cast<double>();
  return l.anchor.cast<double>() + v.cross(l.moment.cast<double>()) + t * v;
}

}  // namespace

bool LineAssociator::Eligible(const SubmapLine& l) const {
  return l.anchor.allFinite() && l.moment.allFinite() && l.direction.allFinite() && std::isfinite(l.t_min) &&
         std::isfinite(l.t_max) && l.covariance.allFinite() && l.length() >= options_.min_length &&
         static_cast<int64_t>(l.sightings) >= options_.min_sightings;
}

Eigen::Vector3d LineAssociator::Middle(const SubmapLine& l) {
  return LineAt(l, 0.5 * (static_cast<double>(l.t_min) + static_cast<double>(l.t_max)));
}

Eigen::Matrix4d LineAssociator::Covariance(const SubmapLine& l) const {
  // The point at abscissa t of the line p0 + v x n + t v moves by v x dn + dv x n + t dv (first
  // order, |v| = 1 and n . v = 0 held by the covariance); e takes its components on (u, w) and
  // those of dv. The components of dn and dv that break the constraints have no variance.
  const Eigen::Vector3d v = l.direction.cast<double>(), n = l.moment.cast<double>();
  const double t = 0.5 * (static_cast<double>(l.t_min) + static_cast<double>(l.t_max));
  Eigen::Vector3d u, w;
  TangentAxes(v, &u, &w);
  Eigen::Matrix<double, 4, 6> J = Eigen::Matrix<double, 4, 6>::Zero();
  J.block<1, 3>(0, 3) = u.transpose();
  J.block<1, 3>(1, 3) = w.transpose();
  J.block<1, 3>(2, 0) = u.cross(v).transpose();  // u . (v x dn) = (u x v) . dn
  J.block<1, 3>(3, 0) = w.cross(v).transpose();
  J.block<1, 3>(2, 3) = (n.cross(u) + t * u).transpose();  // u . (dv x n) = (n x u) . dv
  J.block<1, 3>(3, 3) = (n.cross(w) + t * w).transpose();
  Eigen::Matrix4d c = J * l.covariance.cast<double>() * J.transpose();
  c = 0.5 * (c + c.transpose());
  const double r2 = options_.min_direction_sigma * options_.min_direction_sigma;
  const double t2 = options_.min_offset_sigma * options_.min_offset_sigma;
  c.diagonal() += Eigen::Vector4d(r2, r2, t2, t2);
  return c;
}

double LineAssociator::Distance(const SubmapLine& la, const SubmapPlacement& placed_a, const SubmapLine& lb,
                                const SubmapPlacement& placed_b) const {
  const Eigen::Isometry3d T_a_b = placed_a.T_world_submap.inverse() * placed_b.T_world_submap;
  const Eigen::Vector3d va = la.direction.cast<double>(), ca = Middle(la);
  const Eigen::Vector3d vb = lb.direction.cast<double>(), cb = Middle(lb);
  // Extents: B's ends projected onto A's line, against A's extent widened by the margin.
  const Eigen::Vector3d qa = LineAt(la, 0.0);
  const double s0 = va.dot(T_a_b * LineAt(lb, lb.t_min) - qa), s1 = va.dot(T_a_b * LineAt(lb, lb.t_max) - qa);
  const double m = options_.extent_margin;
  if (std::min(s0, s1) > la.t_max + m || std::max(s0, s1) < la.t_min - m) return -1.0;

  Eigen::Vector3d ua, wa, ub, wb;
  TangentAxes(va, &ua, &wa);
  TangentAxes(vb, &ub, &wb);
  // An edge seen from either side: B's direction turned towards A's, once for all the differences.
  const double sign = (T_a_b.linear() * vb).dot(va) < 0.0 ? -1.0 : 1.0;
  // The error of B's line (with its own error eb about its middle, and perturbations of both
  // origins) against A's line at A's middle, in A's axes.
  auto error = [&](const Eigen::Vector4d& eb, const LineAssociatorVector6& da,
                   const LineAssociatorVector6& db) {
    const Eigen::Vector3d v = sign * (vb + eb[0] * ub + eb[1] * wb).normalized();
    const Eigen::Vector3d p = cb + eb[2] * ub + eb[3] * wb;
    const Eigen::Isometry3d T =
        PerturbedOrigin(placed_a.T_world_submap, da).inverse() * PerturbedOrigin(placed_b.T_world_submap, db);
    return LineErrorAt(T * p, T.linear() * v, ca, ua, wa);
  };
  return PairingChi2<4>(error, Covariance(la), Covariance(lb), placed_a, placed_b);
}

std::vector<LineAssociation> LineAssociator::Associate(const std::vector<SubmapLine>& a,
                                                       const SubmapPlacement& placed_a,
                                                       const std::vector<SubmapLine>& b,
                                                       const SubmapPlacement& placed_b) const {
  std::vector<LineAssociation> candidates;
  for (size_t i = 0; i < a.size(); ++i) {
    if (!Eligible(a[i])) continue;
    for (size_t j = 0; j < b.size(); ++j) {
      if (!Eligible(b[j])) continue;
      candidates.push_back(LineAssociation{static_cast<int>(i), static_cast<int>(j),
                                           Distance(a[i], placed_a, b[j], placed_b)});
    }
  }
  return UnambiguousPairs(candidates, options_.gate_chi2, options_.ambiguity_chi2);
}

}  // namespace cairn
