#include "estimation/filter/filter_state.h"

#include <algorithm>
#include <cstddef>

#include "estimation/filter/filter_kernels.h"

namespace cairn {
namespace {

// The parts of P above the block diagonal: the top-right core-clone block and the clone-clone
// blocks above the diagonal.
void ZeroUpper(StateCovariance& P) {
  P.topRightCorner<kCoreDim, kCloneDims>().setZero();
  for (int j = 1; j < kMaxClones; ++j) P.block(kCoreDim, CloneIndex(j), 6 * j, 6).setZero();
}

void FillUpperFromLower(StateCovariance& P) {
  P.topRightCorner<kCoreDim, kCloneDims>() = P.bottomLeftCorner<kCloneDims, kCoreDim>().transpose();
  for (int j = 1; j < kMaxClones; ++j) {
    for (int i = 0; i < j; ++i) {
      P.block<6, 6>(CloneIndex(i), CloneIndex(j)) = P.block<6, 6>(CloneIndex(j), CloneIndex(i)).transpose();
    }
  }
}

// r <- Pi r for `Lanes` error vectors stored as rows (from row i) of a column-major matrix with 15
// columns, in place (the structured counterpart of the IMU step's transition kernel).
template <int Lanes>
[[gnu::always_inline]] inline void ProductRow(const CoreTransitionProduct& f, double* m, int ld, int i) {
  using T = typename kernels::Unaligned<Lanes>::type;
  T* col[kCoreDim];
  for (int c = 0; c < kCoreDim; ++c) col[c] = reinterpret_cast<T*>(m + static_cast<ptrdiff_t>(c) * ld + i);
  T x[kCoreDim];
  for (int c = 0; c < kCoreDim; ++c) x[c] = *col[c];
  for (int r = 0; r < 3; ++r) {
    T th = f.Tt(r, 0) * x[6] + f.Tt(r, 1) * x[7] + f.Tt(r, 2) * x[8];
    th += f.Tg(r, 0) * x[12] + f.Tg(r, 1) * x[13] + f.Tg(r, 2) * x[14];
    T v = x[3 + r] + f.Vt(r, 0) * x[6] + f.Vt(r, 1) * x[7] + f.Vt(r, 2) * x[8];
    v += f.Va(r, 0) * x[9] + f.Va(r, 1) * x[10] + f.Va(r, 2) * x[11];
    v += f.Vg(r, 0) * x[12] + f.Vg(r, 1) * x[13] + f.Vg(r, 2) * x[14];
    T p = x[r] + f.T * x[3 + r] + f.Pt(r, 0) * x[6] + f.Pt(r, 1) * x[7] + f.Pt(r, 2) * x[8];
    p += f.Pa(r, 0) * x[9] + f.Pa(r, 1) * x[10] + f.Pa(r, 2) * x[11];
    p += f.Pg(r, 0) * x[12] + f.Pg(r, 1) * x[13] + f.Pg(r, 2) * x[14];
    *col[6 + r] = th;
    *col[3 + r] = v;
    *col[r] = p;
  }
}

CAIRN_WIDE_KERNEL void ApplyProductRows(const CoreTransitionProduct& f, double* m, int ld, int rows) {
  int i = 0;
  for (; i + 4 <= rows; i += 4) ProductRow<4>(f, m, ld, i);
  for (; i + 2 <= rows; i += 2) ProductRow<2>(f, m, ld, i);
  for (; i < rows; ++i) ProductRow<1>(f, m, ld, i);
}

}  // namespace

void FlushTransition(FilterState& s) {
  if (s.pending_transition.identity) return;
  // phi is row-major: its storage is phi^T, whose rows are the error vectors (phi <- Pi phi).
  ApplyProductRows(s.pending_transition, s.phi.data(), kCoreDim, kCoreDim);
  // Current cross blocks (stored transposed, B_j <- B_j Pi^T); adjacent slots are adjacent rows.
  auto current = [&s](int j) {
    const size_t u = static_cast<size_t>(j);
    return s.clones[u].id != kNoClone && s.cross_current[u];
  };
  for (int j = 0; j < kMaxClones;) {
    if (!current(j)) {
      ++j;
      continue;
    }
    int end = j + 1;
    while (end < kMaxClones && current(end)) ++end;
    ApplyProductRows(s.pending_transition, &s.P(CloneIndex(j), 0), kStateDim, 6 * (end - j));
    j = end;
  }
  s.pending_transition = CoreTransitionProduct{};
}

void MarkDeferred(FilterState& s) {
  if (s.cross_pending) return;
  ZeroUpper(s.P);
  s.cross_pending = true;
}

void MaterializeCross(FilterState& s) {
  FlushTransition(s);
  if (!s.phi.isIdentity(0.0)) {
    // The clone-core cross blocks are stored transposed (bottom-left): B <- B phi^T.
    const Eigen::Matrix<double, kCoreDim, kCoreDim> phi_t = s.phi.transpose();
    Eigen::Matrix<double, kCloneDims, kCoreDim> t;
    kernels::MulRowsWide<kCoreDim, kCoreDim, kernels::kSet>(t.data(), kCloneDims, &s.P(kCoreDim, 0), kStateDim,
                                                            kCloneDims, phi_t.data(), kCoreDim);
    for (int j = 0; j < kMaxClones; ++j) {
      const size_t u = static_cast<size_t>(j);
      if (s.clones[u].id == kNoClone || s.cross_current[u]) continue;
      s.P.block<6, kCoreDim>(CloneIndex(j), 0) = t.middleRows<6>(6 * j);
    }
    s.phi.setIdentity();
  }
  s.cross_current.fill(false);
}

void MaterializeCovariance(FilterState& s) {
  if (!s.cross_pending) return;
  MaterializeCross(s);
  FillUpperFromLower(s.P);
  s.cross_pending = false;
}

Eigen::Matrix<double, 6, kCoreDim> CrossRows(const FilterState& s, int slot) {
  const auto B = s.P.block<6, kCoreDim>(CloneIndex(slot), 0);
  if (!s.cross_pending) return B;
  Eigen::Matrix<double, 6, kCoreDim> X = B;
  if (!s.cross_current[static_cast<size_t>(slot)]) X = B.lazyProduct(s.phi.transpose());
  if (!s.pending_transition.identity) ApplyProductRows(s.pending_transition, X.data(), 6, 6);
  return X;
}

Matrix6d CloneBlock(const FilterState& s, int i, int j) {
  if (i >= j) return s.P.block<6, 6>(CloneIndex(i), CloneIndex(j));
  return s.P.block<6, 6>(CloneIndex(j), CloneIndex(i)).transpose();
}

void PackCovariance(const StateCovariance& P, PackedCovariance& out) {
  double* o = out.data();
  o = std::copy_n(P.data(), kCoreDim * kStateDim, o);
  for (int c = kCoreDim; c < kStateDim; ++c) {
    const int row0 = kCoreDim + (c - kCoreDim) / 6 * 6;
    o = std::copy_n(P.data() + static_cast<ptrdiff_t>(c) * kStateDim + row0, kStateDim - row0, o);
  }
}

void UnpackCovariance(const PackedCovariance& in, bool packed_pending, FilterState& s) {
  const double* i = in.data();
  std::copy_n(i, kCoreDim * kStateDim, s.P.data());
  i += kCoreDim * kStateDim;
  for (int c = kCoreDim; c < kStateDim; ++c) {
    const int row0 = kCoreDim + (c - kCoreDim) / 6 * 6;
    std::copy_n(i, kStateDim - row0, s.P.data() + static_cast<ptrdiff_t>(c) * kStateDim + row0);
    i += kStateDim - row0;
  }
  if (!packed_pending) {
    FillUpperFromLower(s.P);  // a complete P is exactly symmetric
  } else if (!s.cross_pending) {
    ZeroUpper(s.P);
  }
}

}  // namespace cairn
