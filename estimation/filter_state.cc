#include "estimation/filter_state.h"

#include "estimation/filter_kernels.h"

namespace cairn {

void MaterializeCross(FilterState& s) {
  if (!s.phi.isIdentity(0.0)) {
    // The clone-core cross blocks are stored transposed (bottom-left): B <- B phi^T.
    constexpr int kCloneDims = kStateDim - kCoreDim;
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
  constexpr int kCloneDims = kStateDim - kCoreDim;
  s.P.topRightCorner<kCoreDim, kCloneDims>() = s.P.bottomLeftCorner<kCloneDims, kCoreDim>().transpose();
  for (int j = 1; j < kMaxClones; ++j) {
    for (int i = 0; i < j; ++i) {
      s.P.block<6, 6>(CloneIndex(i), CloneIndex(j)) = s.P.block<6, 6>(CloneIndex(j), CloneIndex(i)).transpose();
    }
  }
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

}  // namespace cairn
