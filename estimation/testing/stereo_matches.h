#pragma once
// Synthetic stereo matches between a keyframe and a current rectified pair with known motion:
// random points in the keyframe's view, seen by both pairs with Gaussian pixel noise and
// triangulated, for the pose estimator's and the bundle adjustment's tests.

#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "estimation/vo/vo_types.h"

namespace cairn::testing {

struct StereoMatches {
  std::vector<StereoObservation> kf_seen, cur_seen;
  std::vector<StereoPoint> kf, cur;  // triangulated from them
};

// The pixel (in the keyframe's left image) of the projection of the point p.
StereoObservation ObserveStereo(const RectifiedStereoCamera& camera, const Eigen::Vector3d& p);

// n points at depths [z_min, z_max] in the keyframe, in front of the current camera by at least
// `min_current_depth`. Columns get `noise_px` of noise, the row (the mean of two) noise_px / sqrt 2;
// triangulation states `sigma_px`.
StereoMatches MakeStereoMatches(const RectifiedStereoCamera& camera, const Eigen::Isometry3d& T_kf_cur, int n,
                                double noise_px, double sigma_px, std::mt19937_64& rng, double z_min = 1.5,
                                double z_max = 6.0, double min_current_depth = 0.5);

}  // namespace cairn::testing
