#include "estimation/filter/filter_update.h"

#include <cmath>

#include "estimation/filter/filter_kernels.h"
#include "estimation/math/small_cholesky.h"
#include "estimation/math/so3.h"

namespace cairn {
namespace {

using CoreMatrix = Eigen::Matrix<double, kCoreDim, kCoreDim>;

bool Active(const FilterState& s, int slot) { return s.clones[static_cast<size_t>(slot)].id != kNoClone; }

// C <- C - V V^T on the current part (on and below the block diagonal) of the clone-clone
// covariance, V the clone rows of an update's W = P H^T L^-T. Column block by column block: each
// is one contiguous run of rows from its diagonal block down. Free slots' columns are left alone
// (the rows of V for free slots are zero).
template <int M>
void SubtractCloneOuter(FilterState& s, const Eigen::Matrix<double, kCloneDims, M>& V) {
  const Eigen::Matrix<double, M, kCloneDims> Vt = V.transpose();
  for (int j = 0; j < kMaxClones; ++j) {
    if (!Active(s, j)) continue;
    const int row0 = 6 * j;
    kernels::MulRows<M, 6, kernels::kSub>(&s.P(kCoreDim + row0, kCoreDim + row0), kStateDim, V.data() + row0,
                                          kCloneDims, kCloneDims - row0, Vt.data() + M * row0, M);
  }
}

// The EKF update for a measurement of the core state only (H zero on the clone columns), in the
// deferred form of FilterState: with L L^T = S, W = P H^T L^-T and P <- P - W W^T, the
// core-clone cross block changes as X <- (I - W_core L^-1 H) X (a left-multiplication, folded
// into phi or applied to the current cross blocks) and the clone block by a rank-M downdate.
template <int M>
UpdateOutcome CoreUpdate(FilterState& s, const Eigen::Matrix<double, M, kCoreDim>& H,
                         const Eigen::Matrix<double, M, 1>& r, const Eigen::Matrix<double, M, M>& R,
                         double gate) {
  FlushTransition(s);
  const CoreMatrix Pc = s.P.topLeftCorner<kCoreDim, kCoreDim>();
  Eigen::Matrix<double, kCoreDim, M> W = Pc.lazyProduct(H.transpose());  // P H^T, then W_core
  Eigen::Matrix<double, M, M> S = H.lazyProduct(W) + R;
  S = 0.5 * (S + S.transpose()).eval();
  Eigen::Matrix<double, M, M> L;
  if (!small_cholesky::Factor<M>(S, &L)) return UpdateOutcome::kBadCovariance;
  Eigen::Matrix<double, M, 1> z = r;
  small_cholesky::SolveLower<M>(L, z);
  if (gate > 0.0 && z.squaredNorm() > gate) return UpdateOutcome::kGated;  // r^T S^-1 r
  small_cholesky::SolveLowerTransposedRight<kCoreDim, M>(L, W);
  Eigen::Matrix<double, kCoreDim, M> Gt = H.transpose();  // becomes (L^-1 H)^T
  small_cholesky::SolveLowerTransposedRight<kCoreDim, M>(L, Gt);
  const Eigen::Matrix<double, kCoreDim, M> Gphi_t = s.phi.transpose().lazyProduct(Gt);  // (G phi)^T

  // Clone rows of W: the true clone-core cross blocks times H^T L^-T.
  Eigen::Matrix<double, kCloneDims, M> V;
  kernels::MulRows<kCoreDim, M, kernels::kSet>(V.data(), kCloneDims, &s.P(kCoreDim, 0), kStateDim, kCloneDims,
                                               Gphi_t.data(), kCoreDim);
  for (int j = 0; j < kMaxClones; ++j) {
    if (!Active(s, j) || !s.cross_current[static_cast<size_t>(j)]) continue;
    kernels::MulRows<kCoreDim, M, kernels::kSet>(V.data() + 6 * j, kCloneDims, &s.P(CloneIndex(j), 0), kStateDim,
                                                 6, Gt.data(), kCoreDim);
  }
  Eigen::Matrix<double, kStateDim, 1> dx;
  dx.head<kCoreDim>() = W.lazyProduct(z);
  dx.tail<kCloneDims>() = V.lazyProduct(z);

  CoreMatrix core = Pc;
  core -= W.lazyProduct(W.transpose());
  s.P.topLeftCorner<kCoreDim, kCoreDim>() = 0.5 * (core + core.transpose());
  s.phi -= W.lazyProduct(Gphi_t.transpose());
  const Eigen::Matrix<double, M, kCoreDim> W_t = W.transpose();
  for (int j = 0; j < kMaxClones; ++j) {
    if (!Active(s, j) || !s.cross_current[static_cast<size_t>(j)]) continue;
    kernels::MulRowsWide<M, kCoreDim, kernels::kSub>(&s.P(CloneIndex(j), 0), kStateDim, V.data() + 6 * j,
                                                     kCloneDims, 6, W_t.data(), M);
  }
  SubtractCloneOuter<M>(s, V);
  MarkDeferred(s);
  InjectError(s, dx);
  return UpdateOutcome::kApplied;
}

// Prediction of a relative pose between two clones and the non-zero 6x6 blocks of its Jacobian
// (columns of the keyframe clone and of the current clone).
void RelativePoseModel(const FilterState& s, const RelativePoseMeasurement& m, Eigen::Vector3d* t_hat,
                       Eigen::Quaterniond* q_hat, Matrix6d* Hk, Matrix6d* Hc) {
  const CloneSlot& k = s.clones[static_cast<size_t>(m.keyframe_slot)];
  const CloneSlot& c = s.clones[static_cast<size_t>(m.current_slot)];
  const Eigen::Matrix3d Rk = k.q_frame_imu.toRotationMatrix();
  *t_hat = Rk.transpose() * (c.p_frame_imu - k.p_frame_imu);
  *q_hat = k.q_frame_imu.conjugate() * c.q_frame_imu;
  const Eigen::Matrix3d R_rel = q_hat->toRotationMatrix();
  Hk->setZero();
  Hc->setZero();
  Hk->block<3, 3>(0, 0) = -Rk.transpose();
  Hk->block<3, 3>(0, 3) = so3::Skew(*t_hat);
  Hk->block<3, 3>(3, 3) = -R_rel.transpose();
  Hc->block<3, 3>(0, 0) = Rk.transpose();
  Hc->block<3, 3>(3, 3).setIdentity();
}

// Column block of the true P at a clone slot (87x6).
Eigen::Matrix<double, kStateDim, 6> CloneColumns(const FilterState& s, int slot) {
  Eigen::Matrix<double, kStateDim, 6> out;
  out.topRows<kCoreDim>() = CrossRows(s, slot).transpose();
  for (int i = 0; i < kMaxClones; ++i) out.middleRows<6>(CloneIndex(i)) = CloneBlock(s, i, slot);
  return out;
}

}  // namespace

void InjectError(FilterState& s, const Eigen::Matrix<double, kStateDim, 1>& dx) {
  s.p += dx.segment<3>(kP);
  s.v += dx.segment<3>(kV);
  s.q = so3::RetractSmall(s.q, dx.segment<3>(kTheta));
  s.ba += dx.segment<3>(kBa);
  s.bg += dx.segment<3>(kBg);
  for (int i = 0; i < kMaxClones; ++i) {
    CloneSlot& c = s.clones[static_cast<size_t>(i)];
    if (c.id == kNoClone) continue;
    c.p_frame_imu += dx.segment<3>(CloneIndex(i));
    c.q_frame_imu = so3::RetractSmall(c.q_frame_imu, dx.segment<3>(CloneIndex(i) + 3));
  }
}

Matrix6d RelativePoseCovariance(const FilterState& s, const RelativePoseMeasurement& m) {
  Eigen::Vector3d t_hat;
  Eigen::Quaterniond q_hat;
  Matrix6d Hk, Hc;
  RelativePoseModel(s, m, &t_hat, &q_hat, &Hk, &Hc);
  const Matrix6d Pkk = CloneBlock(s, m.keyframe_slot, m.keyframe_slot);
  const Matrix6d Pkc = CloneBlock(s, m.keyframe_slot, m.current_slot);
  const Matrix6d Pcc = CloneBlock(s, m.current_slot, m.current_slot);
  return Hk * Pkk * Hk.transpose() + Hk * Pkc * Hc.transpose() + Hc * Pkc.transpose() * Hk.transpose() +
         Hc * Pcc * Hc.transpose();
}

UpdateOutcome ApplyRelativePoseUpdate(FilterState& s, const RelativePoseMeasurement& m, double gate) {
  Eigen::Vector3d t_hat;
  Eigen::Quaterniond q_hat;
  Matrix6d Hk, Hc;
  RelativePoseModel(s, m, &t_hat, &q_hat, &Hk, &Hc);
  Eigen::Matrix<double, 6, 1> r;
  r.head<3>() = m.t_k_c - t_hat;
  r.tail<3>() = so3::Log(q_hat.conjugate() * m.q_k_c);

  // H is zero outside the two clone blocks: P H^T from their column blocks.
  MaterializeCross(s);
  const int ik = CloneIndex(m.keyframe_slot), ic = CloneIndex(m.current_slot);
  Eigen::Matrix<double, kStateDim, 6> U;
  {
    const Eigen::Matrix<double, kStateDim, 6> Ck = CloneColumns(s, m.keyframe_slot);
    const Eigen::Matrix<double, kStateDim, 6> Cc = CloneColumns(s, m.current_slot);
    const Matrix6d Hk_t = Hk.transpose(), Hc_t = Hc.transpose();
    kernels::MulRows<6, 6, kernels::kSet>(U.data(), kStateDim, Ck.data(), kStateDim, kStateDim, Hk_t.data(), 6);
    kernels::MulRows<6, 6, kernels::kAdd>(U.data(), kStateDim, Cc.data(), kStateDim, kStateDim, Hc_t.data(), 6);
  }
  Matrix6d S = m.covariance;
  S += Hk.lazyProduct(U.middleRows<6>(ik)) + Hc.lazyProduct(U.middleRows<6>(ic));
  S = 0.5 * (S + S.transpose()).eval();
  Matrix6d L;
  if (!small_cholesky::Factor<6>(S, &L)) return UpdateOutcome::kBadCovariance;
  Eigen::Matrix<double, 6, 1> z = r;
  small_cholesky::SolveLower<6>(L, z);
  if (gate > 0.0 && z.squaredNorm() > gate) return UpdateOutcome::kGated;  // r^T S^-1 r

  // W = P H^T L^-T; P <- P - W W^T on the core block, the (bottom-left) cross block and the
  // current part of the clone block; dx = W L^-1 r.
  small_cholesky::SolveLowerTransposedRight<kStateDim, 6>(L, U);
  const Eigen::Matrix<double, kStateDim, 6>& W = U;
  const Eigen::Matrix<double, kStateDim, 1> dx = W.lazyProduct(z);
  const Eigen::Matrix<double, 6, kCoreDim> Wc_t = W.topRows<kCoreDim>().transpose();
  const Eigen::Matrix<double, kCloneDims, 6> Wx = W.bottomRows<kCloneDims>();
  CoreMatrix core = s.P.topLeftCorner<kCoreDim, kCoreDim>();
  core -= Wc_t.transpose().lazyProduct(Wc_t);
  s.P.topLeftCorner<kCoreDim, kCoreDim>() = 0.5 * (core + core.transpose());
  kernels::MulRowsWide<6, kCoreDim, kernels::kSub>(&s.P(kCoreDim, 0), kStateDim, Wx.data(), kCloneDims, kCloneDims,
                                                   Wc_t.data(), 6);
  SubtractCloneOuter<6>(s, Wx);
  MarkDeferred(s);
  InjectError(s, dx);
  return UpdateOutcome::kApplied;
}

UpdateOutcome ApplyBodyVelocityUpdate(FilterState& s, const Eigen::Matrix3d& R_imu_meas,
                                      const Eigen::Vector3d& p_imu_point,
                                      const Eigen::Vector3d& velocity, const Eigen::Matrix3d& cov,
                                      int rows) {
  // v_meas = R_meas_imu (R^T v + w x p_imu_point), w = gyro - bg.
  const Eigen::Matrix3d R = s.q.toRotationMatrix();
  const Eigen::Matrix3d A = R_imu_meas.transpose();
  const Eigen::Vector3d w = s.gyro - s.bg;
  const Eigen::Vector3d v_imu = R.transpose() * s.v;
  const Eigen::Vector3d predicted = A * (v_imu + w.cross(p_imu_point));
  Eigen::Matrix<double, 3, kCoreDim> H3 = Eigen::Matrix<double, 3, kCoreDim>::Zero();
  H3.block<3, 3>(0, kV) = A * R.transpose();
  H3.block<3, 3>(0, kTheta) = A * so3::Skew(v_imu);
  H3.block<3, 3>(0, kBg) = A * so3::Skew(p_imu_point);
  const Eigen::Vector3d r3 = velocity - predicted;
  if (rows == 2) {
    return CoreUpdate<2>(s, H3.topRows<2>(), r3.head<2>(), cov.topLeftCorner<2, 2>(), 0.0);
  }
  if (rows == 1) {
    return CoreUpdate<1>(s, H3.topRows<1>(), r3.head<1>(), cov.topLeftCorner<1, 1>(), 0.0);
  }
  return CoreUpdate<3>(s, H3, r3, cov, 0.0);
}

UpdateOutcome ApplyPositionUpdate(FilterState& s, const Eigen::Vector3d& p,
                                  const Eigen::Matrix3d& cov) {
  Eigen::Matrix<double, 3, kCoreDim> H = Eigen::Matrix<double, 3, kCoreDim>::Zero();
  H.block<3, 3>(0, kP).setIdentity();
  return CoreUpdate<3>(s, H, Eigen::Vector3d(p - s.p), cov, 0.0);
}

}  // namespace cairn
