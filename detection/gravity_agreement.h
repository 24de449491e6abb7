#pragma once
// Whether a sighting of one robot by another agrees with gravity. Each robot's filter knows its own
// roll and pitch (gravity is observable from its IMU), so the relative rotation of a sighting must
// turn the observed body's "up" onto the observer's. IPPE's flipped minimum tilts the tag by tens
// of degrees and fails this test, while its reprojection error and sigmas may look fine.

#include <Eigen/Core>

namespace cairn {

struct GravityAgreement {
  double angle = 0.0;         // rad, between the observer's up and the observed up turned into it
  double mahalanobis2 = 0.0;  // squared, of that tilt error (2 degrees of freedom)
};

// R_frame_a, R_frame_b: the observer's and the observed body's attitude in gravity-aligned frames
// (z up); R_a_b: the sighting's rotation, whose right-perturbation covariance (rotation vector, in
// the observed body's axes) is `rotation_covariance`; `attitude_sigma` (rad): each robot's own
// roll and pitch uncertainty.
GravityAgreement GravityAgreementOf(const Eigen::Matrix3d& R_frame_a, const Eigen::Matrix3d& R_frame_b,
                                    const Eigen::Matrix3d& R_a_b, const Eigen::Matrix3d& rotation_covariance,
                                    double attitude_sigma);

}  // namespace cairn
