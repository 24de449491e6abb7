#pragma once
// A 3-D straight line as an anchored Pluecker line (APL; Vidal-Calleja et al., multi-robot visual
// mapping with points and line segments, sec. IV): the 9-vector (p0, n, v) with p0 an anchor (the
// optical centre when the line was first seen), v a direction and n = (p - p0) x v for any point p
// of the line, i.e. the normal of the plane through the anchor and the line scaled by the line's
// distance to the anchor times |v|.
// Near the anchor's camera the projection is linear in n and v, and v behaves as an inverse depth,
// so one image segment initializes the line at once (undelayed) with a prior on the unseen part of
// v. The segment's extent is kept outside the state as two abscissas along the line.
//
// The 9-vector has two gauge directions: a common scale of (n, v) and the component of n along v
// (n . v = 0 holds for a line). Errors are therefore measured with MinimalError(), four numbers
// that ignore both.

#include <array>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cairn {

// Pinhole camera with square pixels (f in px, principal point in px), undistorted images.
struct LinePinhole {
  double f = 0.0;
  double cx = 0.0;
  double cy = 0.0;
};

// Prior on the two unmeasured degrees of freedom of v for a line seen in one image (eq. 15).
// With n normalized to unit length beta_1 is an inverse distance: beta = (b, 0) is a line parallel
// to the image plane at 1 / b m from the optical centre; beta_2 tilts it in depth. Defaults: the
// values of the paper's experiment (a 40 m prior for a helicopter at about 40 m elevation).
struct LineBetaPrior {
  Eigen::Vector2d beta = Eigen::Vector2d(0.025, 0.0);      // 1/m
  Eigen::Vector2d sigma = Eigen::Vector2d(0.025, 0.0375);  // 1/m
};

class AnchoredPluckerLine {
 public:
  using Vector9 = Eigen::Matrix<double, 9, 1>;
  using Matrix9 = Eigen::Matrix<double, 9, 9>;

  AnchoredPluckerLine() = default;
  explicit AnchoredPluckerLine(const Vector9& state) : x_(state) {}
  AnchoredPluckerLine(const Eigen::Vector3d& p0, const Eigen::Vector3d& n, const Eigen::Vector3d& v);
  // The line through a and b anchored at `anchor`, with the abscissas of a and b as endpoints.
  static AnchoredPluckerLine ThroughPoints(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                           const Eigen::Vector3d& anchor);

  const Vector9& state() const { return x_; }
  void set_state(const Vector9& x) { x_ = x; }
  Eigen::Vector3d anchor() const { return x_.head<3>(); }
  Eigen::Vector3d n() const { return x_.segment<3>(3); }
  Eigen::Vector3d v() const { return x_.tail<3>(); }
  Eigen::Vector3d UnitDirection() const { return v().normalized(); }
  // q = p0 + (v x n) / (v . v), the origin of the abscissas (Fig. 3a).
  Eigen::Vector3d ClosestPointToAnchor() const;
  double DistanceToAnchor() const { return n().norm() / v().norm(); }

  // This line given in frame b, expressed in frame a (eq. 8; eq. 9 is T_a_b.inverse()).
  // Abscissas are unchanged: the closest point and the direction move rigidly.
  AnchoredPluckerLine Transformed(const Eigen::Isometry3d& T_a_b) const;
  // Plain Pluecker coordinates (moment about the frame's origin, direction), eq. 10.
  Eigen::Matrix<double, 6, 1> Unanchored() const;

  // K of eq. 11: maps the moment of a camera-frame Pluecker line to its homogeneous image line.
  static Eigen::Matrix3d PluckerIntrinsic(const LinePinhole& cam);
  // Homogeneous image line l = K R^T (n - (T - p0) x v) (eq. 12) for the camera at T_w_c, and its
  // Jacobian w.r.t. the 9-vector. Points x = (u, v, 1) of the image line satisfy l . x = 0.
  Eigen::Vector3d Project(const LinePinhole& cam, const Eigen::Isometry3d& T_w_c,
                          Eigen::Matrix<double, 3, 9>* J = nullptr) const;
  // Signed pixel distances of the observed endpoints u1, u2 to the predicted image line: zero for
  // a perfect prediction. Each endpoint's isotropic pixel noise sigma passes to its distance as
  // sigma, so the measurement covariance is sigma^2 I.
  Eigen::Vector2d SegmentResidual(const LinePinhole& cam, const Eigen::Isometry3d& T_w_c,
                                  const Eigen::Vector2d& u1, const Eigen::Vector2d& u2,
                                  Eigen::Matrix<double, 2, 9>* J = nullptr) const;
  // EKF update of this line alone (camera pose known) with an observed segment; re-imposes the
  // Pluecker constraint afterwards. `nis` (optional) is the normalized innovation squared (chi-square
  // with 2 dof). False, with nothing changed, when the innovation covariance is singular.
  bool UpdateWithSegment(const LinePinhole& cam, const Eigen::Isometry3d& T_w_c, const Eigen::Vector2d& u1,
                         const Eigen::Vector2d& u2, double pixel_sigma, Matrix9* cov, double* nis = nullptr);

  // An EKF update moves (n, v) off n . v = 0. The correction keeps the direction v and the closest
  // point to the anchor (what MinimalError() sees) and drops n's component along v:
  // n <- n - (n . v / v . v) v. Returns the corrected 9-vector and its Jacobian.
  static Vector9 ConstrainedState(const Vector9& x, Matrix9* J = nullptr);
  // Applies ConstrainedState() to this line and propagates `cov` (optional) through its Jacobian.
  void EnforcePluckerConstraint(Matrix9* cov = nullptr);

  // Back-projection of an image segment seen from T_w_c (eqs. 14-19): n^c = K^-1 (x1 x x2)
  // normalized, v^c = E(n^c) beta, anchored at the optical centre. J (optional) is w.r.t.
  // (u1, u2, beta). False for a segment too short to define a line.
  static bool BackProject(const LinePinhole& cam, const Eigen::Isometry3d& T_w_c, const Eigen::Vector2d& u1,
                          const Eigen::Vector2d& u2, const Eigen::Vector2d& beta, Vector9* x,
                          Eigen::Matrix<double, 9, 6>* J = nullptr);
  // Undelayed initialization from one segment: the 9-vector with the endpoint pixel noise and
  // the beta prior propagated to first order, plus `anchor_cov` (the camera position's) on p0.
  // The abscissas are where the endpoint rays meet the line.
  static bool InitializeFromSegment(const LinePinhole& cam, const Eigen::Isometry3d& T_w_c,
                                    const Eigen::Vector2d& u1, const Eigen::Vector2d& u2, double pixel_sigma,
                                    const LineBetaPrior& prior, const Eigen::Matrix3d& anchor_cov,
                                    AnchoredPluckerLine* line, Matrix9* cov);
  // Initialization from a stereo-triangulated segment: endpoints p1_c, p2_c in the camera frame
  // with their covariances, anchored at the optical centre (n^c = p1 x p2, v^c = p2 - p1).
  // False when the endpoints coincide or are aligned with the optical centre.
  static bool InitializeFromStereo(const Eigen::Isometry3d& T_w_c, const Eigen::Vector3d& p1_c,
                                   const Eigen::Matrix3d& cov1, const Eigen::Vector3d& p2_c,
                                   const Eigen::Matrix3d& cov2, const Eigen::Matrix3d& anchor_cov,
                                   AnchoredPluckerLine* line, Matrix9* cov);

  // Endpoints p_i = q + t_i v / |v| (eq. 13).
  std::array<Eigen::Vector3d, 2> Endpoints() const;
  const Eigen::Vector2d& abscissas() const { return t_; }
  void set_abscissas(const Eigen::Vector2d& t) { t_ = t; }
  // Abscissa of the orthogonal projection of p onto the line.
  double Abscissa(const Eigen::Vector3d& p) const;
  // Abscissa of the point of the line closest to the ray origin + s dir. False when the ray is
  // parallel to the line.
  bool AbscissaOfRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double* t) const;
  // Extensible endpoints: projects p onto the line and moves the nearer endpoint out to it when it
  // falls outside the segment.
  void ExtendEndpoints(const Eigen::Vector3d& p);

  // Error of this line w.r.t. `truth` in 4 numbers, zero when both are the same line (whatever the
  // anchors, scales and orientation of v). With u the truth's unit direction, b2 the unit normal
  // of the plane through the truth's anchor and the line, b1 = u x b2 (from the anchor towards the
  // line) and r the truth's point closest to its anchor:
  //   (b1 . v, b2 . v) / (u . v)     direction tilt in and out of that plane (rad, first order),
  //   (b1, b2) . (q(r) - r)          offset (m) of this line's point q(r) closest to r.
  // J (optional) is w.r.t. this line's 9-vector; it is zero along the gauge directions.
  Eigen::Vector4d MinimalError(const AnchoredPluckerLine& truth,
                               Eigen::Matrix<double, 4, 9>* J = nullptr) const;

 private:
  Vector9 x_ = Vector9::Zero();
  Eigen::Vector2d t_ = Eigen::Vector2d::Zero();
};

}  // namespace cairn
