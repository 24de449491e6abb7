#include "mapping/matching/plane_hypotheses.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include <Eigen/LU>

namespace cairn {
namespace {

template <class Vector>
double Heading(const Vector& n) {
  return std::atan2(static_cast<double>(n.y()), static_cast<double>(n.x()));
}

// One plane of a pairing as A sees it: its normal and offset, turned to the side B's partner faces.
struct Sided {
  Eigen::Vector3d normal;
  double offset;
};
Sided Side(const SubmapPlane& p, int sign) {
  return {sign * p.normal.cast<double>(), sign * static_cast<double>(p.offset)};
}

}  // namespace

bool PlaneHypotheses::OnExtent(const SubmapPlane& q, const Eigen::Vector3d& p) const {
  Eigen::Vector3f u, v;
  SubmapPlane::Axes(q.normal, &u, &v);
  const Eigen::Vector3d d = p - q.centroid.cast<double>();
  const double m = options_.extent_margin;
  const double s = u.cast<double>().dot(d), t = v.cast<double>().dot(d);
  return s >= q.min.x() - m && s <= q.max.x() + m && t >= q.min.y() - m && t <= q.max.y() + m;
}

std::vector<PlaneHypothesis> PlaneHypotheses::Find(const std::vector<SubmapPlane>& a,
                                                   const std::vector<SubmapPlane>& b) const {
  std::vector<PlaneHypothesis> out;
  if (!options_.enabled) return out;
  const auto steep = [&](const std::vector<SubmapPlane>& planes) {
    std::vector<int> ids;
    for (size_t k = 0; k < planes.size(); ++k) {
      if (std::abs(planes[k].normal.z()) <= options_.max_steep_nz) ids.push_back(static_cast<int>(k));
    }
    return ids;
  };
  // The largest level plane (the planes come largest first), facing up.
  const auto level = [&](const std::vector<SubmapPlane>& planes) -> std::optional<Sided> {
    for (const SubmapPlane& p : planes) {
      if (std::abs(p.normal.z()) >= options_.min_level_nz) return Side(p, p.normal.z() > 0.0f ? 1 : -1);
    }
    return std::nullopt;
  };
  const std::vector<int> sa = steep(a), sb = steep(b);
  const std::optional<Sided> la = level(a), lb = level(b);
  const double min_pair = options_.min_pair_angle * std::numbers::pi / 180.0;
  const double mismatch = options_.max_angle_mismatch * std::numbers::pi / 180.0;
  const double max_dz = 2.0 * std::sin(mismatch);
  for (size_t i = 0; i < sb.size(); ++i) {
    for (size_t j = i + 1; j < sb.size(); ++j) {
      const SubmapPlane &bi = b[static_cast<size_t>(sb[i])], &bj = b[static_cast<size_t>(sb[j])];
      const double angle_b = WrapAngle(Heading(bj.normal) - Heading(bi.normal));
      if (std::abs(angle_b) < min_pair || std::abs(angle_b) > std::numbers::pi - min_pair) continue;
      for (const int k : sa) {
        for (const int l : sa) {
          if (k == l) continue;
          const SubmapPlane &ak = a[static_cast<size_t>(k)], &al = a[static_cast<size_t>(l)];
          for (const int sk : {1, -1}) {
            for (const int sl : {1, -1}) {
              const Sided pk = Side(ak, sk), pl = Side(al, sl);
              if (std::abs(pk.normal.z() - bi.normal.z()) > max_dz ||
                  std::abs(pl.normal.z() - bj.normal.z()) > max_dz)
                continue;
              const double hk = Heading(pk.normal), hl = Heading(pl.normal);
              if (std::abs(WrapAngle(WrapAngle(hl - hk) - angle_b)) > mismatch) continue;
              const double yaw1 = WrapAngle(hk - Heading(bi.normal)),
                           yaw2 = WrapAngle(hl - Heading(bj.normal));
              const double split = WrapAngle(yaw2 - yaw1);
              if (std::abs(split) > mismatch) continue;
              const double yaw = WrapAngle(yaw1 + split / 2);
              // (R n_b) . t = offset_b - offset_a for each plane B sees as A's.
              const Eigen::Matrix3d R = FourDofTransform(Eigen::Vector3d::Zero(), yaw).rotation();
              Eigen::Matrix3d m;
              Eigen::Vector3d r;
              m.row(0) = (R * bi.normal.cast<double>()).transpose();
              r(0) = bi.offset - pk.offset;
              m.row(1) = (R * bj.normal.cast<double>()).transpose();
              r(1) = bj.offset - pl.offset;
              if (la && lb) {
                m.row(2) = (R * lb->normal).transpose();
                r(2) = lb->offset - la->offset;
              } else {
                m.row(2) = Eigen::Vector3d::UnitZ().transpose();  // no level plane: z left to the ICP
                r(2) = 0.0;
              }
              const Eigen::FullPivLU<Eigen::Matrix3d> lu(m);
              if (!lu.isInvertible()) continue;
              const Eigen::Vector3d t = lu.solve(r);
              if (!t.allFinite()) continue;
              const FourDofTransform T(t, yaw);
              if (!OnExtent(ak, T * bi.centroid.cast<double>()) ||
                  !OnExtent(al, T * bj.centroid.cast<double>()))
                continue;
              PlaneHypothesis h;
              h.T_a_b = T;
              h.area = std::min({static_cast<double>(ak.area), static_cast<double>(al.area),
                                 static_cast<double>(bi.area), static_cast<double>(bj.area)});
              h.a[0] = k;
              h.a[1] = l;
              h.b[0] = sb[i];
              h.b[1] = sb[j];
              out.push_back(h);
            }
          }
        }
      }
    }
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const PlaneHypothesis& x, const PlaneHypothesis& y) { return x.area > y.area; });
  // The same alignment from other pairings of the same faces counts once.
  std::vector<PlaneHypothesis> kept;
  for (const PlaneHypothesis& h : out) {
    bool seen = false;
    for (const PlaneHypothesis& k : kept) {
      seen |= (h.T_a_b.translation() - k.T_a_b.translation()).norm() < 0.3 &&
              std::abs(WrapAngle(h.T_a_b.yaw() - k.T_a_b.yaw())) < mismatch;
    }
    if (!seen) kept.push_back(h);
    if (kept.size() >= static_cast<size_t>(options_.max_hypotheses)) break;
  }
  return kept;
}

}  // namespace cairn
