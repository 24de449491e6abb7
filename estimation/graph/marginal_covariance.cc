#include "estimation/graph/marginal_covariance.h"

#include <algorithm>
#include <string>

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCore>
#include <ceres/ceres.h>

namespace cairn {

namespace {

// A Cholesky pivot (squared) below this fraction of its diagonal entry of H means that direction
// is determined by the others only up to rounding: H is singular, the covariance meaningless.
constexpr double kMinPivotRatio = 1e-12;

// Position of `row` in the sorted pattern `rows` (present by construction).
size_t PositionOf(const std::vector<int>& rows, int row) {
  return static_cast<size_t>(std::lower_bound(rows.begin(), rows.end(), row) - rows.begin());
}

Matrix6d LowerInverse(const Matrix6d& L) {
  return L.triangularView<Eigen::Lower>().solve(Matrix6d::Identity());
}

}  // namespace

MarginalCovariance::MarginalCovariance(int num_blocks)
    : diagonal_(static_cast<size_t>(num_blocks), Matrix6d::Zero()) {}

Expected<MarginalCovariance> MarginalCovariance::FromProblem(ceres::Problem& problem) {
  std::vector<double*> all, variable;
  problem.GetParameterBlocks(&all);
  std::unordered_map<const double*, int> index;
  // Columns of the Jacobian: block and position within it (a block's tangent may be smaller).
  std::vector<int> col_block, col_local;
  std::vector<int> tangent;
  for (double* block : all) {
    if (problem.IsParameterBlockConstant(block)) continue;  // no column: as ceres::Covariance
    const int size = problem.ParameterBlockTangentSize(block);
    if (size < 1 || size > 6) {
      return InvalidArgumentError("marginal covariance: a parameter block with a tangent space of " +
                                  std::to_string(size) + " dimensions (1 to 6 supported)");
    }
    for (int d = 0; d < size; ++d) {
      col_block.push_back(static_cast<int>(variable.size()));
      col_local.push_back(d);
    }
    tangent.push_back(size);
    index[block] = static_cast<int>(variable.size());
    variable.push_back(block);
  }
  MarginalCovariance mc(static_cast<int>(variable.size()));
  mc.index_ = std::move(index);
  if (variable.empty()) return mc;
  // The unused dimensions of smaller blocks: unit information, coupled to nothing, so they change
  // no other marginal (and their own rows of it are to be ignored).
  for (size_t b = 0; b < tangent.size(); ++b) {
    for (int d = tangent[b]; d < 6; ++d) mc.diagonal_[b](d, d) = 1.0;
  }

  // Listing only the variable blocks fixes the column order (6 per block) and holds the constant
  // ones fixed; the Jacobian is in the tangent space with the losses' corrections applied.
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = variable;
  ceres::CRSMatrix J;
  if (!problem.Evaluate(eo, nullptr, nullptr, nullptr, &J)) {
    return InternalError("marginal covariance: evaluating the Jacobian failed");
  }
  // H = sum over rows of j j^T, gathered per row into its (few) blocks.
  std::vector<std::pair<int, Vector6d>> row_blocks;
  for (int r = 0; r < J.num_rows; ++r) {
    row_blocks.clear();
    for (int e = J.rows[static_cast<size_t>(r)]; e < J.rows[static_cast<size_t>(r) + 1]; ++e) {
      const auto col = static_cast<size_t>(J.cols[static_cast<size_t>(e)]);
      const int block = col_block[col];
      auto it = std::find_if(row_blocks.begin(), row_blocks.end(), [&](const auto& b) { return b.first == block; });
      if (it == row_blocks.end()) it = row_blocks.insert(row_blocks.end(), {block, Vector6d::Zero()});
      it->second[col_local[col]] += J.values[static_cast<size_t>(e)];
    }
    for (size_t a = 0; a < row_blocks.size(); ++a) {
      for (size_t b = a; b < row_blocks.size(); ++b) {
        mc.Add(row_blocks[a].first, row_blocks[b].first, row_blocks[a].second * row_blocks[b].second.transpose());
      }
    }
  }
  return mc;
}

int MarginalCovariance::IndexOf(const double* parameter_block) const {
  const auto it = index_.find(parameter_block);
  return it == index_.end() ? -1 : it->second;
}

void MarginalCovariance::Add(int i, int j, const Matrix6d& info) {
  if (i == j) {
    diagonal_[static_cast<size_t>(i)] += info;
    return;
  }
  const uint64_t n = diagonal_.size();
  if (i > j) {
    off_diagonal_.try_emplace(static_cast<uint64_t>(i) * n + static_cast<uint64_t>(j), Matrix6d::Zero())
        .first->second += info;
  } else {
    off_diagonal_.try_emplace(static_cast<uint64_t>(j) * n + static_cast<uint64_t>(i), Matrix6d::Zero())
        .first->second += info.transpose();
  }
}

Status MarginalCovariance::Compute() {
  if (diagonal_.empty()) return Status::Ok();  // only constant blocks: nothing to invert
  Analyze();
  CAIRN_RETURN_IF_ERROR(Factorize());
  SelectedInversion();
  return Status::Ok();
}

void MarginalCovariance::Analyze() {
  const int n = num_blocks();
  const uint64_t un = diagonal_.size();
  // AMD on the block graph: one scalar per block.
  std::vector<Eigen::Triplet<double, int>> triplets;
  triplets.reserve(2 * off_diagonal_.size() + un);
  for (int i = 0; i < n; ++i) triplets.emplace_back(i, i, 1.0);
  for (const auto& [key, block] : off_diagonal_) {
    const int i = static_cast<int>(key / un), j = static_cast<int>(key % un);
    triplets.emplace_back(i, j, 1.0);
    triplets.emplace_back(j, i, 1.0);
  }
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> graph(n, n);
  graph.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::AMDOrdering<int>::PermutationType perm;
  Eigen::AMDOrdering<int>()(graph, perm);
  old_of_new_.assign(perm.indices().data(), perm.indices().data() + n);
  new_of_old_.assign(static_cast<size_t>(n), 0);
  for (int k = 0; k < n; ++k) new_of_old_[static_cast<size_t>(old_of_new_[static_cast<size_t>(k)])] = k;

  // Symbolic factorization: column k's rows are H's rows below k and its elimination-tree
  // children's rows (without k itself).
  std::vector<std::vector<int>> rows_of_h(un), children(un);
  for (const auto& [key, block] : off_diagonal_) {
    const int a = new_of_old_[key / un], b = new_of_old_[key % un];
    rows_of_h[static_cast<size_t>(std::min(a, b))].push_back(std::max(a, b));
  }
  pattern_.assign(un, {});
  for (size_t k = 0; k < un; ++k) {
    std::vector<int>& rows = pattern_[k];
    rows = std::move(rows_of_h[k]);
    for (int c : children[k]) {
      for (int r : pattern_[static_cast<size_t>(c)]) {
        if (r != static_cast<int>(k)) rows.push_back(r);
      }
    }
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    if (!rows.empty()) children[static_cast<size_t>(rows.front())].push_back(static_cast<int>(k));
  }
}

Status MarginalCovariance::Factorize() {
  const size_t n = diagonal_.size();
  const uint64_t un = n;
  L_diagonal_.resize(n);
  L_below_.assign(n, {});
  for (size_t k = 0; k < n; ++k) {
    L_diagonal_[k] = diagonal_[static_cast<size_t>(old_of_new_[k])];
    L_below_[k].assign(pattern_[k].size(), Matrix6d::Zero());
  }
  for (const auto& [key, block] : off_diagonal_) {
    const int a = new_of_old_[key / un], b = new_of_old_[key % un];  // block is H(a, b), new order
    if (a > b) {
      L_below_[static_cast<size_t>(b)][PositionOf(pattern_[static_cast<size_t>(b)], a)] = block;
    } else {
      L_below_[static_cast<size_t>(a)][PositionOf(pattern_[static_cast<size_t>(a)], b)] = block.transpose();
    }
  }
  // Right-looking: column k, once final, updates the columns of its rows (a clique in L).
  for (size_t k = 0; k < n; ++k) {
    const Matrix6d& H_kk = diagonal_[static_cast<size_t>(old_of_new_[k])];
    Eigen::LLT<Matrix6d> llt(L_diagonal_[k]);
    if (llt.info() != Eigen::Success) {
      return FailedPreconditionError("marginal covariance: the information matrix is not positive definite");
    }
    L_diagonal_[k] = llt.matrixL();
    for (int d = 0; d < 6; ++d) {
      const double pivot = L_diagonal_[k](d, d) * L_diagonal_[k](d, d);
      if (!std::isfinite(pivot) || pivot <= kMinPivotRatio * H_kk(d, d)) {
        return FailedPreconditionError("marginal covariance: the information matrix is rank deficient");
      }
    }
    const Matrix6d L_inv_T = LowerInverse(L_diagonal_[k]).transpose();
    const std::vector<int>& rows = pattern_[k];
    std::vector<Matrix6d>& L = L_below_[k];
    for (Matrix6d& block : L) block = block * L_inv_T;
    for (size_t a = 0; a < rows.size(); ++a) {
      const size_t i = static_cast<size_t>(rows[a]);
      L_diagonal_[i].noalias() -= L[a] * L[a].transpose();
      const std::vector<int>& rows_i = pattern_[i];
      size_t q = 0;
      for (size_t b = a + 1; b < rows.size(); ++b) {
        while (rows_i[q] != rows[b]) ++q;
        L_below_[i][q].noalias() -= L[b] * L[a].transpose();
      }
    }
  }
  return Status::Ok();
}

void MarginalCovariance::SelectedInversion() {
  // With U_k = L_Sk L_kk^-1 (S: rows of column k) and D_k^-1 = L_kk^-T L_kk^-1, Sigma = H^-1 obeys
  //   Sigma_Sk = -Sigma_SS U_k,   Sigma_kk = D_k^-1 - U_k^T Sigma_Sk,
  // and Sigma_SS lies on the pattern of the later columns, so the last column goes first.
  const size_t n = diagonal_.size();
  std::vector<Matrix6d> sigma_kk(n);
  std::vector<std::vector<Matrix6d>> sigma_below(n);
  std::vector<Matrix6d> U;
  for (size_t k = n; k-- > 0;) {
    const Matrix6d L_inv = LowerInverse(L_diagonal_[k]);
    const std::vector<int>& rows = pattern_[k];
    U.resize(rows.size());
    for (size_t a = 0; a < rows.size(); ++a) U[a].noalias() = L_below_[k][a] * L_inv;
    std::vector<Matrix6d>& sigma = sigma_below[k];
    sigma.assign(rows.size(), Matrix6d::Zero());
    for (size_t a = 0; a < rows.size(); ++a) {
      const size_t i = static_cast<size_t>(rows[a]);
      sigma[a].noalias() -= sigma_kk[i] * U[a];
      const std::vector<int>& rows_i = pattern_[i];
      size_t q = 0;
      for (size_t b = a + 1; b < rows.size(); ++b) {
        while (rows_i[q] != rows[b]) ++q;
        const Matrix6d& sigma_ji = sigma_below[i][q];  // j = rows[b] > i
        sigma[b].noalias() -= sigma_ji * U[a];
        sigma[a].noalias() -= sigma_ji.transpose() * U[b];
      }
    }
    Matrix6d S = L_inv.transpose() * L_inv;
    for (size_t a = 0; a < rows.size(); ++a) S.noalias() -= U[a].transpose() * sigma[a];
    sigma_kk[k] = 0.5 * (S + S.transpose());
  }
  sigma_diagonal_.resize(n);
  for (size_t k = 0; k < n; ++k) sigma_diagonal_[static_cast<size_t>(old_of_new_[k])] = sigma_kk[k];
}

}  // namespace cairn
