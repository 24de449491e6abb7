#pragma once
// Eigen decompositions of small symmetric matrices, compiled once here: Eigen's
// SelfAdjointEigenSolver costs several seconds of compile time in every file that instantiates it.

#include <Eigen/Core>

namespace cairn {

// Eigenvalues in increasing order and the matching orthonormal eigenvectors (columns) of the
// symmetric A (its lower triangle is read). False when the iteration did not converge.
bool SymmetricEigen(const Eigen::Matrix<double, 6, 6>& A, Eigen::Matrix<double, 6, 1>* values,
                    Eigen::Matrix<double, 6, 6>* vectors);
bool SymmetricEigen(const Eigen::Matrix3d& A, Eigen::Vector3d* values, Eigen::Matrix3d* vectors);
// Eigenvalues only, increasing.
Eigen::Vector3d SymmetricEigenvalues(const Eigen::Matrix3d& A);

}  // namespace cairn
