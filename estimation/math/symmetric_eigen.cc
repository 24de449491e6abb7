#include "estimation/math/symmetric_eigen.h"

#include <Eigen/Eigenvalues>

namespace cairn {

bool SymmetricEigen(const Eigen::Matrix<double, 6, 6>& A, Eigen::Matrix<double, 6, 1>* values,
                    Eigen::Matrix<double, 6, 6>* vectors) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(A);
  if (es.info() != Eigen::Success) return false;
  *values = es.eigenvalues();
  *vectors = es.eigenvectors();
  return true;
}

bool SymmetricEigen(const Eigen::Matrix3d& A, Eigen::Vector3d* values, Eigen::Matrix3d* vectors) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(A);
  if (es.info() != Eigen::Success) return false;
  *values = es.eigenvalues();
  *vectors = es.eigenvectors();
  return true;
}

Eigen::Vector3d SymmetricEigenvalues(const Eigen::Matrix3d& A) {
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(A, Eigen::EigenvaluesOnly).eigenvalues();
}

}  // namespace cairn
