#include "mapping/matching/icp_options.h"

#include <cstdio>
#include <string>

#include "mapping/matching/point_to_plane_icp.h"

namespace cairn {

Status IcpOptions::Validate() const {
  if (max_iterations < 1) return InvalidArgumentError("icp: max_iterations must be >= 1");
  if (!(min_correspondence_distance > 0.0) || !(max_correspondence_distance >= min_correspondence_distance))
    return InvalidArgumentError("icp: need 0 < min_correspondence_distance <= max_correspondence_distance");
  if (!(gate_shrink > 0.0 && gate_shrink <= 1.0))
    return InvalidArgumentError("icp: gate_shrink must be in (0, 1]");
  if (normal_neighbours < 3 || min_normal_neighbours < 3 || min_normal_neighbours > normal_neighbours)
    return InvalidArgumentError("icp: need 3 <= min_normal_neighbours <= normal_neighbours");
  if (!(normal_radius > 0.0)) return InvalidArgumentError("icp: normal_radius must be > 0");
  if (!(max_surface_variation >= 0.0) || !(min_planar_ratio >= 0.0))
    return InvalidArgumentError("icp: max_surface_variation and min_planar_ratio must be >= 0");
  if (min_correspondences < 5) return InvalidArgumentError("icp: min_correspondences must be >= 5");
  if (!(min_observability >= 0.0)) return InvalidArgumentError("icp: min_observability must be >= 0");
  if (!(translation_tolerance >= 0.0) || !(yaw_tolerance >= 0.0) || !(max_step_sigmas >= 0.0))
    return InvalidArgumentError("icp: tolerances must be >= 0");
  if (freeze_after < 1) return InvalidArgumentError("icp: freeze_after must be >= 1");
  return Status::Ok();
}

std::string IcpNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.4g", v);
  return buf;
}

}  // namespace cairn
