#pragma once
// The target cloud of a point-to-plane ICP (four_dof_icp.h, six_dof_icp.h): its finite points in a
// k-d tree (nanoflann) with the normal of every point whose neighbourhood is a well-sampled plane,
// and IcpPairs, the nearest-neighbour pairing of the moved source points with those points.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "mapping/matching/icp_options.h"

namespace cairn {

class IcpTarget {
 public:
  // Indexes the finite points of `target` and computes their normals (local PCA over the
  // normal_neighbours nearest within normal_radius; flat and not a line, see four_dof_icp.h).
  IcpTarget(std::span<const Eigen::Vector3d> target, const IcpOptions& options);
  ~IcpTarget();
  IcpTarget(const IcpTarget&) = delete;
  IcpTarget& operator=(const IcpTarget&) = delete;

  // The finite points of `in`; the count of the others goes to `skipped`.
  static std::vector<Eigen::Vector3d> FinitePoints(std::span<const Eigen::Vector3d> in, size_t* skipped);

  size_t size() const { return points_.size(); }
  size_t skipped() const { return skipped_; }
  size_t good_normals() const { return good_normals_; }
  const Eigen::Vector3d& point(uint32_t i) const { return points_[i]; }
  const Eigen::Vector3d& normal(uint32_t i) const { return normals_[i]; }
  bool has_normal(uint32_t i) const { return good_[i] != 0; }

  // The nearest target point to `q` within sqrt(max_distance_sq); false when there is none. The
  // bound prunes the tree's search: points outside the overlap end it early.
  bool Nearest(const Eigen::Vector3d& q, double max_distance_sq, uint32_t* index, double* distance_sq) const;

 private:
  struct Tree;
  std::vector<Eigen::Vector3d> points_;
  size_t skipped_ = 0;
  std::unique_ptr<Tree> tree_;
  std::vector<Eigen::Vector3d> normals_;
  std::vector<uint8_t> good_;
  size_t good_normals_ = 0;
};

// Pairs each moved source point with its nearest target point within the gate that has a normal.
// With unique_targets a target point keeps only its closest source point (the first on a tie).
// Scratch arrays are allocated once, not per pass.
class IcpPairs {
 public:
  IcpPairs(const IcpTarget& target, size_t source_points, bool unique_targets)
      : target_(target),
        unique_(unique_targets),
        nn_(source_points, kNone),
        claim_d2_(unique_targets ? target.size() : 0, kFree),
        claim_(unique_targets ? target.size() : 0, kNone) {
    pairs_.reserve(source_points);
  }

  // (source, target) pairs, in increasing source order, of `move(source[s])` within `gate` m.
  template <class Move>
  void Pair(const Move& move, const std::vector<Eigen::Vector3d>& source, double gate) {
    const double gate2 = gate * gate;
    for (size_t s = 0; s < source.size(); ++s) {
      const Eigen::Vector3d q = move(source[s]);
      uint32_t idx = 0;
      double d2 = 0.0;
      nn_[s] = kNone;
      if (!target_.Nearest(q, gate2, &idx, &d2) || !target_.has_normal(idx)) continue;
      nn_[s] = idx;
      if (unique_ && d2 < claim_d2_[idx]) {
        claim_d2_[idx] = d2;
        claim_[idx] = static_cast<uint32_t>(s);
      }
    }
    pairs_.clear();
    for (size_t s = 0; s < source.size(); ++s) {
      const uint32_t idx = nn_[s];
      if (idx == kNone) continue;
      if (unique_) {
        const bool mine = claim_[idx] == s;
        claim_d2_[idx] = kFree;  // reset for the next pass; only the touched entries
        if (!mine) continue;
      }
      pairs_.emplace_back(static_cast<uint32_t>(s), idx);
    }
  }

  // The pairs of the last Pair(), kept as they are when the ICP freezes them.
  std::span<const std::pair<uint32_t, uint32_t>> pairs() const { return pairs_; }

 private:
  static constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
  static constexpr double kFree = std::numeric_limits<double>::infinity();

  const IcpTarget& target_;
  bool unique_;
  std::vector<uint32_t> nn_;      // per source point: its paired target point or kNone
  std::vector<double> claim_d2_;  // per target point: distance of its closest source point
  std::vector<uint32_t> claim_;   // per target point: that source point
  std::vector<std::pair<uint32_t, uint32_t>> pairs_;
};

}  // namespace cairn
