#include "mapping/matching/plane_associator.h"

#include <algorithm>
#include <cmath>

#include "estimation/math/so3.h"
#include "mapping/matching/unambiguous_pairs.h"

namespace cairn {
namespace {

// A plane (n, d) of a submap at T_world_submap, in world axes.
struct WorldPlane {
  Eigen::Vector3d n;
  double d = 0.0;
};

WorldPlane ToWorld(const Eigen::Vector3d& n, double d, const Eigen::Isometry3d& T) {
  WorldPlane w;
  w.n = T.linear() * n;
  w.d = d - w.n.dot(T.translation());
  return w;
}

// A plane's (a, b, d) perturbation applied: normalize(n + a u + b v), d + dd.
void PerturbedPlane(const SubmapPlane& p, const Eigen::Vector3d& e, Eigen::Vector3d* n, double* d) {
  Eigen::Vector3f u, v;
  SubmapPlane::Axes(p.normal, &u, &v);
  *n = (p.normal.cast<double>() + e.x() * u.cast<double>() + e.y() * v.cast<double>()).normalized();
  *d = static_cast<double>(p.offset) + e.z();
}

// Corners of a face's extent in the submap's frame.
std::vector<Eigen::Vector3d> Corners(const SubmapPlane& p) {
  Eigen::Vector3f u, v;
  SubmapPlane::Axes(p.normal, &u, &v);
  std::vector<Eigen::Vector3d> out;
  for (float su : {p.min.x(), p.max.x()}) {
    for (float sv : {p.min.y(), p.max.y()}) out.push_back((p.centroid + su * u + sv * v).cast<double>());
  }
  return out;
}

}  // namespace

bool PlaneAssociator::Eligible(const SubmapPlane& p) const {
  return std::abs(p.normal.z()) <= options_.max_nz && p.area >= options_.min_area && p.normal.allFinite() &&
         std::isfinite(p.offset) && p.covariance.allFinite();
}

Eigen::Matrix3d PlaneAssociator::Covariance(const SubmapPlane& p) const {
  Eigen::Matrix3d c = p.covariance.cast<double>();
  c = 0.5 * (c + c.transpose());
  c(0, 0) += options_.min_normal_sigma * options_.min_normal_sigma;
  c(1, 1) += options_.min_normal_sigma * options_.min_normal_sigma;
  c(2, 2) += options_.min_offset_sigma * options_.min_offset_sigma;
  return c;
}

double PlaneAssociator::Distance(const SubmapPlane& pa, const SubmapPlacement& placed_a,
                                 const SubmapPlane& pb, const SubmapPlacement& placed_b) const {
  const Eigen::Isometry3d T_a_b = placed_a.T_world_submap.inverse() * placed_b.T_world_submap;
  const Eigen::Vector3d na = pa.normal.cast<double>();
  if ((T_a_b.linear() * pb.normal.cast<double>()).dot(na) <= 0.0) return -1.0;
  // Extents: B's corners in A's plane axes, against A's extent widened by the margin.
  Eigen::Vector3f uf, vf;
  SubmapPlane::Axes(pa.normal, &uf, &vf);
  const Eigen::Vector3d u = uf.cast<double>(), v = vf.cast<double>(), ca = pa.centroid.cast<double>();
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (const Eigen::Vector3d& c : Corners(pb)) {
    const Eigen::Vector3d q = T_a_b * c - ca;
    const Eigen::Vector2d s(q.dot(u), q.dot(v));
    lo = lo.cwiseMin(s);
    hi = hi.cwiseMax(s);
  }
  const double m = options_.extent_margin;
  if (lo.x() > pa.max.x() + m || hi.x() < pa.min.x() - m || lo.y() > pa.max.y() + m ||
      hi.y() < pa.min.y() - m)
    return -1.0;

  // The error of B's plane (with perturbations of B's plane and of both origins) in A's axes.
  auto error = [&](const Eigen::Vector3d& eb, const Eigen::Matrix<double, 6, 1>& da,
                   const Eigen::Matrix<double, 6, 1>& db) {
    Eigen::Vector3d nb;
    double d_b = 0.0;
    PerturbedPlane(pb, eb, &nb, &d_b);
    const WorldPlane w = ToWorld(nb, d_b, PerturbedOrigin(placed_b.T_world_submap, db));
    const Eigen::Isometry3d T_w_a = PerturbedOrigin(placed_a.T_world_submap, da);
    const Eigen::Vector3d n = T_w_a.linear().transpose() * w.n;
    const double d = w.d + w.n.dot(T_w_a.translation());
    return Eigen::Vector3d(u.dot(n), v.dot(n), d - static_cast<double>(pa.offset));
  };
  return PairingChi2<3>(error, Covariance(pa), Covariance(pb), placed_a, placed_b);
}

std::vector<PlaneAssociation> PlaneAssociator::Associate(const std::vector<SubmapPlane>& a,
                                                         const SubmapPlacement& placed_a,
                                                         const std::vector<SubmapPlane>& b,
                                                         const SubmapPlacement& placed_b) const {
  std::vector<PlaneAssociation> candidates;
  for (size_t i = 0; i < a.size(); ++i) {
    if (!Eligible(a[i])) continue;
    for (size_t j = 0; j < b.size(); ++j) {
      if (!Eligible(b[j])) continue;
      candidates.push_back(PlaneAssociation{static_cast<int>(i), static_cast<int>(j),
                                            Distance(a[i], placed_a, b[j], placed_b)});
    }
  }
  return UnambiguousPairs(candidates, options_.gate_chi2, options_.ambiguity_chi2);
}

}  // namespace cairn
