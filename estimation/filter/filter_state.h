#pragma once
// The local reference filter's complete state: nominal IMU state, pose clones in fixed slots and
// the joint error-state covariance. Everything is fixed-size so that a copy (a replay snapshot)
// never allocates. Error state: [dp dv dtheta dba dbg | clone0 (dp dtheta) | clone1 ...], attitude
// errors are right perturbations R = R_hat * Exp(dtheta).

#include <array>
#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/timestamp.h"

namespace cairn {

// Five visual-odometry keyframes plus the clones of frames whose relative pose is still in
// flight (about 250 ms at 20 Hz) and the newest one.
inline constexpr int kMaxClones = 12;
inline constexpr int kCoreDim = 15;
inline constexpr int kStateDim = kCoreDim + 6 * kMaxClones;
inline constexpr int kCloneDims = kStateDim - kCoreDim;
inline constexpr int kP = 0, kV = 3, kTheta = 6, kBa = 9, kBg = 12;
constexpr int CloneIndex(int slot) { return kCoreDim + 6 * slot; }

using CloneId = uint64_t;
inline constexpr CloneId kNoClone = 0;

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using StateCovariance = Eigen::Matrix<double, kStateDim, kStateDim>;

struct CloneSlot {
  CloneId id = kNoClone;  // kNoClone = free slot (its covariance rows/columns are zero)
  Timestamp time;
  Eigen::Vector3d p_frame_imu = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_frame_imu = Eigen::Quaterniond::Identity();
  // Creation time, then the state time of the latest relative pose that used it as keyframe:
  // when the slots are full the least recently used clone is marginalized.
  Timestamp last_used;
};

// The product of the IMU-step transitions since the last event, not yet applied to phi and the
// current cross blocks (see FilterState). A product of step transitions keeps their block pattern
//   [I  T I  Pt  Pa  Pg]
//   [0  I    Vt  Va  Vg]
//   [0  0    Tt  0   Tg]
//   [0  0    0   I   0 ]
//   [0  0    0   0   I ]
// (rows and columns p, v, theta, ba, bg), so a step costs a few 3x3 products here instead of a pass
// over phi and every current cross block; those get the product once, at the next event.
struct CoreTransitionProduct {
  bool identity = true;
  double T = 0.0;
  Eigen::Matrix3d Pt = Eigen::Matrix3d::Zero(), Pa = Eigen::Matrix3d::Zero(), Pg = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d Vt = Eigen::Matrix3d::Zero(), Va = Eigen::Matrix3d::Zero(), Vg = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d Tt = Eigen::Matrix3d::Identity(), Tg = Eigen::Matrix3d::Zero();
};

// Everything but the full covariance matrix (what a replay snapshot copies as is).
struct FilterStateHead {
  Timestamp time;
  // IMU pose and velocity in the current local frame (gravity along -z).
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d ba = Eigen::Vector3d::Zero();
  Eigen::Vector3d bg = Eigen::Vector3d::Zero();
  // Raw IMU reading at `time` (interpolated when `time` lies between samples): the start point of
  // the next propagation interval.
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();
  std::array<CloneSlot, kMaxClones> clones{};
  // The deferred parts of the covariance P (see FilterState).
  Eigen::Matrix<double, kCoreDim, kCoreDim, Eigen::RowMajor> phi =
      Eigen::Matrix<double, kCoreDim, kCoreDim, Eigen::RowMajor>::Identity();
  std::array<bool, kMaxClones> cross_current{};
  bool cross_pending = false;
  // Left factor of phi and of the current cross blocks' transitions not yet applied to them.
  CoreTransitionProduct pending_transition;
};

struct FilterState : FilterStateHead {
  // Parts of P are kept deferred so that the work per IMU sample and per core-only update does
  // not grow with the number of clones. While cross_pending is set:
  //  - the core block P[0:15, 0:15] is current;
  //  - the clone-core cross block of an active slot j is kept in the bottom-left block,
  //    B_j = P[CloneIndex(j) + 0..5, 0:15]. It is current if cross_current[j], else the true block
  //    is B_j phi^T: propagation and core-only updates (wheel, position) change the core-clone
  //    cross-covariance by left-multiplication, which is accumulated in phi; the IMU steps since
  //    the last event are further held in pending_transition (Pi): the true cross block is
  //    B_j phi^T Pi^T, or B_j Pi^T where it is current (FlushTransition applies Pi);
  //  - of the clone-clone block, the 6x6 blocks on and below the block diagonal are current;
  //  - the top-right block and the clone-clone blocks above the diagonal are stale and held at
  //    zero (MarkDeferred), so that a state restored from a packed snapshot (which keeps only the
  //    current parts) is bit-identical to the one that was saved.
  // While cross_pending is clear, P is complete and exactly symmetric, phi is the identity and no
  // cross block is flagged current. Free slots have all-zero rows and columns.
  // MaterializeCovariance makes P complete.
  StateCovariance P = StateCovariance::Zero();
};

// Sets cross_pending, zeroing the stale parts of P if it was complete: every change that leaves P
// in the deferred representation ends with it.
void MarkDeferred(FilterState& s);
// Applies pending_transition to phi and the current cross blocks (it becomes the identity). Every
// reader of phi or of a current cross block calls it first.
void FlushTransition(FilterState& s);
// Makes every cross block current (applies phi, which becomes the identity).
void MaterializeCross(FilterState& s);
// Makes P complete and symmetric.
void MaterializeCovariance(FilterState& s);
// The true covariance of a clone with the core state (6x15), and the true clone-clone block (i, j).
Eigen::Matrix<double, 6, kCoreDim> CrossRows(const FilterState& s, int slot);
Matrix6d CloneBlock(const FilterState& s, int i, int j);

// The current parts of P (above): the core columns in full and, of each clone column block, the
// rows from its diagonal block down, about 55 % of P. Column-major runs, so packing is a few
// contiguous copies.
constexpr int PackedCovarianceSize() {
  int n = kCoreDim * kStateDim;
  for (int j = 0; j < kMaxClones; ++j) n += 6 * (kStateDim - CloneIndex(j));
  return n;
}
using PackedCovariance = std::array<double, PackedCovarianceSize()>;
void PackCovariance(const StateCovariance& P, PackedCovariance& out);
// Restores P from a packing of a state with the given cross_pending (s.cross_pending is the
// state's current one, s.P's stale parts are zero if it is set). The result is bit-identical to
// the packed P: stale parts become zero, a complete P is completed from its lower part.
void UnpackCovariance(const PackedCovariance& in, bool packed_pending, FilterState& s);

}  // namespace cairn
