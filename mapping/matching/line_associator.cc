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

LineAssociator::Prepared LineAssociator::Prepare(const SubmapLine& l, int index) const {
  return Prepared{index, Middle(l), l.direction.cast<double>(), Covariance(l)};
}

double LineAssociator::Distance(const SubmapLine& la, const SubmapPlacement& placed_a, const SubmapLine& lb,
                                const SubmapPlacement& placed_b) const {
  return Distance(la, Prepare(la, 0), placed_a, lb, Prepare(lb, 0), placed_b,
                  placed_a.T_world_submap.inverse() * placed_b.T_world_submap);
}

double LineAssociator::LowerBound(const SubmapLine& la, const SubmapPlacement& placed_a, const SubmapLine& lb,
                                  const SubmapPlacement& placed_b) const {
  return LowerBound(Prepare(la, 0), placed_a, Prepare(lb, 0), placed_b,
                    placed_a.T_world_submap.inverse() * placed_b.T_world_submap);
}

double LineAssociator::LowerBound(const Prepared& a, const SubmapPlacement& placed_a, const Prepared& b,
                                  const SubmapPlacement& placed_b, const Eigen::Isometry3d& T_a_b) const {
  // The chi2 is at least that of its direction part alone, and of its offset part alone; each of
  // those is at least |e|^2 over the trace of the part's covariance. The traces are bounded with
  // the norms of the Jacobians, which are simple: a turn of either line or origin by dr turns the
  // direction by at most |dr|; it moves B's point nearest A's middle by at most (lever + 2 r) |dr|,
  // lever being the point's distance from the turning origin and r that between the two middles;
  // a shift moves it by at most the shift. Cross-covariances enter through Cauchy-Schwarz,
  // tr(J P J^T) <= (sqrt(tr Jt Ptt Jt^T) + sqrt(tr Jr Prr Jr^T))^2.
  const Eigen::Vector3d p = T_a_b * b.middle, v = T_a_b.linear() * b.direction;
  const Eigen::Vector3d& ca = a.middle;
  const Eigen::Vector3d& va = a.direction;
  const double cosine = va.dot(v);
  const double direction_error2 = std::max(0.0, 1.0 - cosine * cosine);
  const Eigen::Vector3d offset = p + (ca - p).dot(v) * v - ca;
  const double along = va.dot(offset);
  const double offset_error2 = std::max(0.0, offset.squaredNorm() - along * along);

  auto trace2 = [](const Eigen::Matrix4d& c, int first) { return c(first, first) + c(first + 1, first + 1); };
  const double dir_a = trace2(a.covariance, 0), off_a = trace2(a.covariance, 2);
  const double dir_b = trace2(b.covariance, 0), off_b = trace2(b.covariance, 2);
  const double shift_a = placed_a.covariance.topLeftCorner<3, 3>().trace();
  const double turn_a = placed_a.covariance.bottomRightCorner<3, 3>().trace();
  const double shift_b = placed_b.covariance.topLeftCorner<3, 3>().trace();
  const double turn_b = placed_b.covariance.bottomRightCorner<3, 3>().trace();
  const double r = (ca - p).norm();
  auto both = [](double shift_sigma, double turn_sigma) {
    return (shift_sigma + turn_sigma) * (shift_sigma + turn_sigma);
  };
  const double direction_variance = dir_a + dir_b + turn_a + turn_b;
  const double offset_variance = off_a + both(std::sqrt(off_b), 2.0 * r * std::sqrt(dir_b)) +
                                 both(std::sqrt(shift_a), (p.norm() + 2.0 * r) * std::sqrt(turn_a)) +
                                 both(std::sqrt(shift_b), (b.middle.norm() + 2.0 * r) * std::sqrt(turn_b));
  const double bound = std::max(direction_variance > 0.0 ? direction_error2 / direction_variance : 0.0,
                                offset_variance > 0.0 ? offset_error2 / offset_variance : 0.0);
  // Slack for Distance's Jacobians being central differences rather than exact.
  return std::isfinite(bound) ? 0.999 * bound : 0.0;
}

double LineAssociator::Distance(const SubmapLine& la, const Prepared& a, const SubmapPlacement& placed_a,
                                const SubmapLine& lb, const Prepared& b, const SubmapPlacement& placed_b,
                                const Eigen::Isometry3d& T_a_b) const {
  const Eigen::Vector3d &va = a.direction, &ca = a.middle;
  const Eigen::Vector3d &vb = b.direction, &cb = b.middle;
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
  return PairingChi2<4>(error, a.covariance, b.covariance, placed_a, placed_b);
}

std::vector<LineAssociation> LineAssociator::Associate(const std::vector<SubmapLine>& a,
                                                       const SubmapPlacement& placed_a,
                                                       const std::vector<SubmapLine>& b,
                                                       const SubmapPlacement& placed_b) const {
  auto prepare = [&](const std::vector<SubmapLine>& lines) {
    std::vector<Prepared> out;
    for (size_t i = 0; i < lines.size(); ++i) {
      if (Eligible(lines[i])) out.push_back(Prepare(lines[i], static_cast<int>(i)));
    }
    return out;
  };
  const std::vector<Prepared> pa = prepare(a), pb = prepare(b);
  const Eigen::Isometry3d T_a_b = placed_a.T_world_submap.inverse() * placed_b.T_world_submap;
  // A pairing beyond this is neither taken nor a rival of one that is (UnambiguousPairs).
  const double reach = options_.gate_chi2 + options_.ambiguity_chi2;
  std::vector<LineAssociation> candidates;
  for (const Prepared& x : pa) {
    for (const Prepared& y : pb) {
      if (LowerBound(x, placed_a, y, placed_b, T_a_b) > reach) continue;
      candidates.push_back(LineAssociation{x.index, y.index,
                                           Distance(a[static_cast<size_t>(x.index)], x, placed_a,
                                                    b[static_cast<size_t>(y.index)], y, placed_b, T_a_b)});
    }
  }
  return UnambiguousPairs(candidates, options_.gate_chi2, options_.ambiguity_chi2);
}

}  // namespace cairn
