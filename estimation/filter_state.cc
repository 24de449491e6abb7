#include "estimation/filter_state.h"

#include <algorithm>
#include <cstddef>

#include "estimation/filter_kernels.h"

namespace cairn {
namespace {

constexpr int kCloneDims = kStateDim - kCoreDim;

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

}  // namespace

void MarkDeferred(FilterState& s) {
  if (s.cross_pending) return;
  ZeroUpper(s.P);
  s.cross_pending = true;
}

void MaterializeCross(FilterState& s) {
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
  if (!s.cross_pending || s.cross_current[static_cast<size_t>(slot)]) return B;
  return B.lazyProduct(s.phi.transpose());
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
