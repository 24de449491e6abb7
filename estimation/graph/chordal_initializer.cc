#include "estimation/graph/chordal_initializer.h"

#include <Eigen/SVD>
#include <Eigen/SparseCholesky>

namespace cairn {
namespace {

Eigen::Matrix3d ProjectToSo3(const Eigen::Matrix3d& M) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  S(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * S * svd.matrixV().transpose();
}

// Solves min sum_e w_e ||x_j - A_e x_i - b_e||^2 over blocks x (dimension D per vertex, K right-hand
// sides) with the anchors fixed. `unknown[v]` is the column block of v or -1 for an anchor.
template <int D, int K>
struct BlockLeastSquares {
  using Block = Eigen::Matrix<double, D, D>;
  using Rhs = Eigen::Matrix<double, D, K>;
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::MatrixXd rhs;

  explicit BlockLeastSquares(int unknowns) : rhs(Eigen::MatrixXd::Zero(D * unknowns, K)) {}

  void AddBlock(int r, int c, const Block& B) {
    for (int i = 0; i < D; ++i) {
      for (int j = 0; j < D; ++j) triplets.emplace_back(D * r + i, D * c + j, B(i, j));
    }
  }
  // Residual x_j - A x_i - b with x of anchors given.
  void AddTerm(int i, int j, const Block& A, const Rhs& b, double w, const Rhs& xi_fixed,
               const Rhs& xj_fixed) {
    // Jacobians: d/dx_j = I, d/dx_i = -A. Normal equations J^T W J x = J^T W (-r0).
    const Block I = Block::Identity();
    Rhs r0 = -b;
    if (i < 0) r0 -= A * xi_fixed;
    if (j < 0) r0 += xj_fixed;
    if (j >= 0) {
      AddBlock(j, j, w * I);
      rhs.template middleRows<D>(D * j) -= w * r0;
    }
    if (i >= 0) {
      AddBlock(i, i, w * A.transpose() * A);
      rhs.template middleRows<D>(D * i) += w * A.transpose() * r0;
    }
    if (i >= 0 && j >= 0) {
      AddBlock(j, i, -w * A);
      AddBlock(i, j, -w * A.transpose());
    }
  }

  Expected<Eigen::MatrixXd> Solve(int unknowns) {
    Eigen::SparseMatrix<double> H(D * unknowns, D * unknowns);
    H.setFromTriplets(triplets.begin(), triplets.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(H);
    if (ldlt.info() != Eigen::Success) return InternalError("chordal system is singular");
    Eigen::MatrixXd x = ldlt.solve(rhs);
    if (ldlt.info() != Eigen::Success) return InternalError("chordal solve failed");
    return x;
  }
};

}  // namespace

Status InitializeChordal(PoseGraph& graph) {
  const size_t n = graph.num_vertices();
  int count = 0;
  const std::vector<int> component = graph.Components(&count);
  std::vector<int> unknown(n, -1);
  std::vector<bool> anchored(static_cast<size_t>(count), false);
  int unknowns = 0;
  for (size_t v = 0; v < n; ++v) {
    if (!anchored[static_cast<size_t>(component[v])]) {
      anchored[static_cast<size_t>(component[v])] = true;  // first vertex of its component
    } else {
      unknown[v] = unknowns++;
    }
  }
  if (unknowns == 0) return Status::Ok();
  auto& poses = graph.poses();

  // Rotations: with x_v = R_v^T (columns = the rows of R_v), R_j - R_i R_ij = 0 reads
  // x_j = R_ij^T x_i for all three rows at once.
  BlockLeastSquares<3, 3> rot(unknowns);
  for (const auto& e : graph.edges()) {
    const size_t i = graph.Find(e.from), j = graph.Find(e.to);
    rot.AddTerm(unknown[i], unknown[j], e.T_from_to.R().transpose(), Eigen::Matrix3d::Zero(),
                e.kappa, poses[i].R().transpose(), poses[j].R().transpose());
  }
  auto x = rot.Solve(unknowns);
  if (!x.ok()) return x.status();
  for (size_t v = 0; v < n; ++v) {
    if (unknown[v] < 0) continue;
    const Eigen::Matrix3d Rt = x->middleRows<3>(3 * unknown[v]);
    poses[v].q = Eigen::Quaterniond(ProjectToSo3(Rt.transpose())).normalized();
  }

  // Translations: t_j = t_i + R_i t_ij, one scalar Laplacian, xyz as three right-hand sides.
  BlockLeastSquares<1, 3> tra(unknowns);
  for (const auto& e : graph.edges()) {
    const size_t i = graph.Find(e.from), j = graph.Find(e.to);
    const Eigen::RowVector3d b = (poses[i].R() * e.T_from_to.t).transpose();
    tra.AddTerm(unknown[i], unknown[j], Eigen::Matrix<double, 1, 1>::Identity(), b, e.tau,
                poses[i].t.transpose(), poses[j].t.transpose());
  }
  auto y = tra.Solve(unknowns);
  if (!y.ok()) return y.status();
  for (size_t v = 0; v < n; ++v) {
    if (unknown[v] >= 0) poses[v].t = y->row(unknown[v]).transpose();
  }
  return Status::Ok();
}

}  // namespace cairn
