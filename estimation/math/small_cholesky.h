#pragma once
// Cholesky factorization and triangular solves for the filter's small fixed-size matrices
// (1x1 to 6x6). Plain loops: Eigen::LLT instantiates its blocked solver machinery for every size
// and right-hand side, which costs about a second of compile time per use and more than the
// factorization itself at run time at these sizes.

#include <cmath>

#include <Eigen/Core>

namespace cairn::small_cholesky {

// L L^T = S from the lower triangle of S (the strict upper triangle of L is zero). False when S is
// not positive definite (or not finite).
template <int N>
bool Factor(const Eigen::Matrix<double, N, N>& S, Eigen::Matrix<double, N, N>* L) {
  L->setZero();
  for (int j = 0; j < N; ++j) {
    double d = S(j, j);
    for (int k = 0; k < j; ++k) d -= (*L)(j, k) * (*L)(j, k);
    if (!(d > 0.0) || !std::isfinite(d)) return false;
    const double ljj = std::sqrt(d);
    (*L)(j, j) = ljj;
    for (int i = j + 1; i < N; ++i) {
      double x = S(i, j);
      for (int k = 0; k < j; ++k) x -= (*L)(i, k) * (*L)(j, k);
      (*L)(i, j) = x / ljj;
    }
  }
  return true;
}

template <int N>
bool PositiveDefinite(const Eigen::Matrix<double, N, N>& S) {
  Eigen::Matrix<double, N, N> L;
  return Factor<N>(S, &L);
}

// z <- L^-1 z (forward substitution).
template <int M>
void SolveLower(const Eigen::Matrix<double, M, M>& L, Eigen::Matrix<double, M, 1>& z) {
  for (int i = 0; i < M; ++i) {
    for (int k = 0; k < i; ++k) z(i) -= L(i, k) * z(k);
    z(i) /= L(i, i);
  }
}

// z <- L^-T z (back substitution).
template <int M>
void SolveLowerTransposed(const Eigen::Matrix<double, M, M>& L, Eigen::Matrix<double, M, 1>& z) {
  for (int i = M - 1; i >= 0; --i) {
    for (int k = i + 1; k < M; ++k) z(i) -= L(k, i) * z(k);
    z(i) /= L(i, i);
  }
}

// W <- W L^-T in place, column by column.
template <int N, int M>
void SolveLowerTransposedRight(const Eigen::Matrix<double, M, M>& L, Eigen::Matrix<double, N, M>& W) {
  for (int i = 0; i < M; ++i) {
    for (int k = 0; k < i; ++k) W.col(i) -= L(i, k) * W.col(k);
    W.col(i) /= L(i, i);
  }
}

}  // namespace cairn::small_cholesky
