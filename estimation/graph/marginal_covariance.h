#pragma once
// Marginal covariances of a block-sparse information matrix H (6x6 blocks, one a pose in its
// tangent space): H is ordered to reduce fill (AMD on the block graph), factored by block
// Cholesky H = L L^T, and the blocks of Sigma = H^-1 on the pattern of L are computed by the
// Takahashi recursion from the last column back. That costs about one factorization, where one
// solve per requested variable would cost a factorization-sized solve each.
//
// FromProblem() builds H = J^T J from a ceres::Problem at its current values (tangent space,
// robust losses applied as Problem::Evaluate applies them), without the constant blocks: the
// same information ceres::Covariance uses, so constant blocks have zero covariance and the rest
// is relative to them.

#include <unordered_map>
#include <vector>

#include "common/status.h"
#include "estimation/graph/pose_graph.h"

namespace ceres {
class Problem;
}  // namespace ceres

namespace cairn {

class MarginalCovariance {
 public:
  explicit MarginalCovariance(int num_blocks);

  // Information of all non-constant parameter blocks of `problem`, whose tangent spaces have at most
  // 6 dimensions; a smaller block's marginal is the top-left corner of its 6x6 block.
  static Expected<MarginalCovariance> FromProblem(ceres::Problem& problem);

  int num_blocks() const { return static_cast<int>(diagonal_.size()); }
  // Block index of a parameter block of FromProblem(), -1 for constant or unknown blocks.
  int IndexOf(const double* parameter_block) const;

  // H_ij += info (and H_ji += info^T).
  void Add(int i, int j, const Matrix6d& info);

  // Factorization and selected inversion; FailedPrecondition when H is (numerically) singular.
  Status Compute();
  // Marginal covariance of block i; valid after a successful Compute().
  const Matrix6d& Marginal(int i) const { return sigma_diagonal_[static_cast<size_t>(i)]; }

 private:
  // Fill-reducing elimination order and the row pattern of each column of L (new indices).
  void Analyze();
  Status Factorize();
  void SelectedInversion();

  std::vector<Matrix6d> diagonal_;                          // H_ii, original order
  std::unordered_map<uint64_t, Matrix6d> off_diagonal_;     // H_ij for i > j, key i * n + j
  std::unordered_map<const double*, int> index_;            // FromProblem() blocks
  std::vector<int> old_of_new_;                             // elimination order
  std::vector<int> new_of_old_;
  // Column k of L (new order): diagonal block and the blocks at rows pattern_[k] (sorted, > k).
  std::vector<std::vector<int>> pattern_;
  std::vector<Matrix6d> L_diagonal_;
  std::vector<std::vector<Matrix6d>> L_below_;
  std::vector<Matrix6d> sigma_diagonal_;                    // original order
};

}  // namespace cairn
