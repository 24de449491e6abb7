#include "mapping/matching/line_hypotheses.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/LU>

namespace cairn {
namespace {

// An edge as the pairing sees it: unit direction, middle of its segment, extent along it.
struct PairedEdge {
  Eigen::Vector3d d, mid;
  double half = 0.0;  // half length, m
  double length = 0.0;
  int index = -1;
};

std::vector<PairedEdge> LongestEdges(const std::vector<SubmapLine>& lines, const LineHypothesisOptions& o) {
  std::vector<PairedEdge> out;
  for (size_t k = 0; k < lines.size(); ++k) {
    const SubmapLine& l = lines[k];
    if (!(l.length() >= o.min_length)) continue;
    PairedEdge e;
    e.d = l.direction.cast<double>().normalized();
    e.mid = l.End(0.5f * (l.t_min + l.t_max)).cast<double>();
    e.length = l.length();
    e.half = 0.5 * e.length;
    e.index = static_cast<int>(k);
    if (e.d.allFinite() && e.mid.allFinite()) out.push_back(e);
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const PairedEdge& x, const PairedEdge& y) { return x.length > y.length; });
  if (out.size() > static_cast<size_t>(o.max_lines)) out.resize(static_cast<size_t>(o.max_lines));
  return out;
}

// What a pair of edges keeps under any rigid motion: the angle between them and the distance
// between the lines.
struct PairShape {
  int i = -1, j = -1;
  double angle = 0.0;     // rad in [0, pi/2]
  double distance = 0.0;  // m
};

std::vector<PairShape> EdgePairs(const std::vector<PairedEdge>& e, double min_angle) {
  std::vector<PairShape> out;
  for (size_t i = 0; i < e.size(); ++i) {
    for (size_t j = i + 1; j < e.size(); ++j) {
      const Eigen::Vector3d c = e[i].d.cross(e[j].d);
      const double s = c.norm();
      const double angle = std::atan2(s, std::abs(e[i].d.dot(e[j].d)));
      if (angle < min_angle) continue;
      out.push_back(
          {static_cast<int>(i), static_cast<int>(j), angle, std::abs((e[j].mid - e[i].mid).dot(c)) / s});
    }
  }
  return out;
}

double EdgeHeading(const Eigen::Vector3d& v) { return std::atan2(v.y(), v.x()); }

Eigen::Matrix3d EdgeYawRotation(double yaw) {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace

std::vector<LineHypothesis> LineHypotheses::Find(const std::vector<SubmapLine>& a,
                                                 const std::vector<SubmapLine>& b) const {
  std::vector<LineHypothesis> out;
  if (!options_.enabled) return out;
  const double deg = std::numbers::pi / 180.0;
  const double mismatch = options_.max_angle_mismatch * deg;
  const double tol = options_.max_distance_mismatch;
  const std::vector<PairedEdge> ea = LongestEdges(a, options_), eb = LongestEdges(b, options_);
  const std::vector<PairShape> pa = EdgePairs(ea, options_.min_pair_angle * deg),
                               pb = EdgePairs(eb, options_.min_pair_angle * deg);
  // An edge within this of vertical gives no heading.
  const double vertical = std::cos(mismatch);

  // Whether y (of B) moved into A is parallel to x, on it (its middle `*across` m off x) and overlaps it.
  const auto on_partner = [&](const PairedEdge& x, const PairedEdge& y, const Eigen::Matrix3d& R,
                              const Eigen::Vector3d& t, double* across = nullptr) {
    const Eigen::Vector3d d = R * y.d, m = R * y.mid + t;
    if (std::abs(d.dot(x.d)) < std::cos(mismatch)) return false;
    const Eigen::Vector3d off = m - x.mid;
    const double along = off.dot(x.d);
    const double off_line = (off - along * x.d).norm();
    if (off_line > tol) return false;
    if (across != nullptr) *across = off_line;
    return std::abs(along) <= x.half + y.half + options_.overlap_margin;
  };

  for (const PairShape& sa : pa) {
    for (const PairShape& sb : pb) {
      if (std::abs(sa.angle - sb.angle) > mismatch || std::abs(sa.distance - sb.distance) > tol) continue;
      for (int swap = 0; swap < 2; ++swap) {
        const PairedEdge& a0 = ea[static_cast<size_t>(sa.i)];
        const PairedEdge& a1 = ea[static_cast<size_t>(sa.j)];
        const PairedEdge& b0 = eb[static_cast<size_t>(swap == 0 ? sb.i : sb.j)];
        const PairedEdge& b1 = eb[static_cast<size_t>(swap == 0 ? sb.j : sb.i)];
        // Gravity keeps each edge's tilt.
        if (std::abs(std::abs(a0.d.z()) - std::abs(b0.d.z())) > std::sin(mismatch) ||
            std::abs(std::abs(a1.d.z()) - std::abs(b1.d.z())) > std::sin(mismatch))
          continue;
        std::vector<double> yaws;
        for (const auto& [x, y] : {std::pair{&a0, &b0}, std::pair{&a1, &b1}}) {
          if (std::abs(x->d.z()) >= vertical) continue;
          // Unoriented edges: the heading turns by psi or psi + pi.
          const double psi = EdgeHeading(x->d) - EdgeHeading(y->d);
          yaws.push_back(WrapAngle(psi));
          yaws.push_back(WrapAngle(psi + std::numbers::pi));
        }
        if (yaws.empty()) {
          // Two vertical edges: the heading of the line between them.
          const Eigen::Vector3d va = a1.mid - a0.mid, vb = b1.mid - b0.mid;
          if (va.head<2>().norm() < tol || vb.head<2>().norm() < tol) continue;
          yaws.push_back(WrapAngle(EdgeHeading(va) - EdgeHeading(vb)));
        }
        for (double yaw : yaws) {
          const Eigen::Matrix3d R = EdgeYawRotation(yaw);
          // Least squares across both lines, and weakly the middles' offset where the lines leave
          // the translation free.
          constexpr double kMiddleWeight = 1e-3;
          Eigen::Matrix3d M = kMiddleWeight * Eigen::Matrix3d::Identity();
          Eigen::Vector3d rhs = kMiddleWeight * 0.5 * ((a0.mid - R * b0.mid) + (a1.mid - R * b1.mid));
          for (const auto& [x, y] : {std::pair{&a0, &b0}, std::pair{&a1, &b1}}) {
            const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - x->d * x->d.transpose();
            M += P;
            rhs += P * (x->mid - R * y->mid);
          }
          const Eigen::Vector3d t = M.partialPivLu().solve(rhs);
          if (!t.allFinite() || !on_partner(a0, b0, R, t) || !on_partner(a1, b1, R, t)) continue;
          LineHypothesis h;
          h.T_a_b = FourDofTransform(t, yaw);
          h.length = std::min({a0.length, a1.length, b0.length, b1.length});
          h.a[0] = a0.index;
          h.a[1] = a1.index;
          h.b[0] = b0.index;
          h.b[1] = b1.index;
          out.push_back(h);
        }
      }
    }
  }
  // Man-made edges repeat (a crate's corners are alike): what the other edges say ranks a pairing.
  for (LineHypothesis& h : out) {
    const Eigen::Matrix3d R = h.T_a_b.rotation();
    double sum = 0.0;
    for (const PairedEdge& y : eb) {
      double best = tol;
      bool landed = false;
      for (const PairedEdge& x : ea) {
        double across = 0.0;
        if (on_partner(x, y, R, h.T_a_b.translation(), &across) && across <= best) {
          best = across;
          landed = true;
        }
      }
      if (!landed) continue;
      ++h.edges_agreeing;
      sum += best;
    }
    h.offset = h.edges_agreeing > 0 ? sum / h.edges_agreeing : tol;
  }
  std::stable_sort(out.begin(), out.end(), [](const LineHypothesis& x, const LineHypothesis& y) {
    return x.edges_agreeing != y.edges_agreeing ? x.edges_agreeing > y.edges_agreeing : x.offset < y.offset;
  });
  // One per pose: pairings of one place give nearly the same transform.
  std::vector<LineHypothesis> kept;
  for (const LineHypothesis& h : out) {
    bool near = false;
    for (const LineHypothesis& k : kept) {
      near = near || ((h.T_a_b.translation() - k.T_a_b.translation()).norm() < 2.0 * tol &&
                      std::abs(WrapAngle(h.T_a_b.yaw() - k.T_a_b.yaw())) < 2.0 * mismatch);
    }
    if (!near) kept.push_back(h);
    if (kept.size() >= static_cast<size_t>(options_.max_hypotheses)) break;
  }
  return kept;
}

}  // namespace cairn
