#pragma once
// Depth image to 3-D points with their stereo error (thesis 5.1.1, eq. 5.2): points whose depth
// error exceeds the camera's limit are dropped, rays that see nothing within range are kept as
// free-space ends for the voxel map.

#include <span>

#include "mapping/depth_image.h"
#include "mapping/mapping_options.h"
#include "stereo/stereo_error_model.h"

namespace cairn {

class DepthProjector {
 public:
  DepthProjector(const DepthPointOptions& options, const StereoCamera& camera);

  // Fills `out` (cleared first) from `image` seen at body pose T_local_body. `depth_error`, when
  // not empty, is each pixel's depth sigma (a fused image's) and replaces eq. 5.2c in the points;
  // the range limit stays eq. 5.2c's, since a pixel's first image decides alone.
  Status Project(const DepthImage& image, const Eigen::Isometry3d& T_local_body, CameraPoints* out,
                 std::span<const float> depth_error = {}) const;

  // Smaller of max_depth and the depth whose eq. 5.2c error reaches max_depth_error.
  double range() const { return range_; }
  const StereoErrorModel& error_model() const { return model_; }
  const StereoCamera& camera() const { return camera_; }
  const DepthPointOptions& options() const { return options_; }

 private:
  DepthPointOptions options_;
  StereoCamera camera_;
  StereoErrorModel model_;
  double range_;
};

}  // namespace cairn
