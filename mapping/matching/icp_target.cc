#include "mapping/matching/icp_target.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <nanoflann.hpp>

#include "estimation/math/symmetric_eigen.h"

namespace cairn {
namespace {

// The finite target points as nanoflann reads them.
struct IcpCloudAdaptor {
  const std::vector<Eigen::Vector3d>* points;

  size_t kdtree_get_point_count() const { return points->size(); }
  double kdtree_get_pt(size_t i, size_t dim) const { return (*points)[i][static_cast<Eigen::Index>(dim)]; }
  template <class BoundingBox>
  bool kdtree_get_bbox(BoundingBox& /*bb*/) const {
    return false;  // let the tree compute it
  }
};

using IcpKdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, IcpCloudAdaptor>,
                                                   IcpCloudAdaptor, 3, uint32_t>;

}  // namespace

struct IcpTarget::Tree {
  IcpCloudAdaptor adaptor;
  IcpKdTree index;
  explicit Tree(const std::vector<Eigen::Vector3d>* points)
      : adaptor{points}, index(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {}
};

std::vector<Eigen::Vector3d> IcpTarget::FinitePoints(std::span<const Eigen::Vector3d> in, size_t* skipped) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(in.size());
  for (const Eigen::Vector3d& p : in) {
    if (p.allFinite()) out.push_back(p);
  }
  *skipped = in.size() - out.size();
  return out;
}

IcpTarget::IcpTarget(std::span<const Eigen::Vector3d> target, const IcpOptions& o) {
  points_ = FinitePoints(target, &skipped_);
  normals_.assign(points_.size(), Eigen::Vector3d::UnitZ());
  good_.assign(points_.size(), 0);
  if (points_.empty()) return;
  tree_ = std::make_unique<Tree>(&points_);
  const size_t k = std::min(static_cast<size_t>(std::max<int64_t>(o.normal_neighbours, 1)), points_.size());
  std::vector<uint32_t> idx(k);
  std::vector<double> d2(k);
  const double r2 = o.normal_radius * o.normal_radius;
  for (size_t i = 0; i < points_.size(); ++i) {
    const size_t found = tree_->index.knnSearch(points_[i].data(), k, idx.data(), d2.data());
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    size_t m = 0;
    for (size_t j = 0; j < found; ++j) {
      if (d2[j] > r2) continue;
      mean += points_[idx[j]];
      ++m;
    }
    if (m < static_cast<size_t>(o.min_normal_neighbours)) continue;
    mean /= static_cast<double>(m);
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (size_t j = 0; j < found; ++j) {
      if (d2[j] > r2) continue;
      const Eigen::Vector3d d = points_[idx[j]] - mean;
      cov.noalias() += d * d.transpose();
    }
    Eigen::Vector3d values;
    Eigen::Matrix3d vectors;
    if (!SymmetricEigen(cov, &values, &vectors)) continue;
    const double sum = values.sum();
    if (!(sum > 0.0) || !(values(2) > 0.0)) continue;
    if (values(0) > o.max_surface_variation * sum) continue;   // not flat: an edge, a corner, noise
    if (values(1) < o.min_planar_ratio * values(2)) continue;  // a line: the normal is undefined
    normals_[i] = vectors.col(0).normalized();
    good_[i] = 1;
    ++good_normals_;
  }
}

IcpTarget::~IcpTarget() = default;

bool IcpTarget::Nearest(const Eigen::Vector3d& q, double max_distance_sq, uint32_t* index,
                        double* distance_sq) const {
  if (tree_ == nullptr) return false;
  nanoflann::KNNResultSet<double, uint32_t> result(1);
  result.init(index, distance_sq);
  // The search visits only what lies closer than the result's worst distance: start it at the
  // bound (just above, so that a point exactly at it is still found).
  *distance_sq = std::nextafter(max_distance_sq, std::numeric_limits<double>::infinity());
  tree_->index.findNeighbors(result, q.data(), nanoflann::SearchParams());
  return result.size() == 1;
}

}  // namespace cairn
