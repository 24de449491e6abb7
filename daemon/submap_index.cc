#include "daemon/submap_index.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace cairn {
namespace {

double YawOf(const Eigen::Isometry3d& T) { return std::atan2(T.linear()(1, 0), T.linear()(0, 0)); }

// Body position and yaw at `t`, interpolated between the two nearest poses; false outside.
bool TruthAt(const Trajectory& truth, Timestamp t, Eigen::Vector4d* out) {
  const auto& poses = truth.poses;
  const auto after = std::lower_bound(poses.begin(), poses.end(), t,
                                      [](const StampedPose& p, Timestamp time) { return p.time < time; });
  if (after == poses.end()) return false;
  if (after->time == t || after == poses.begin()) {
    if (after->time != t) return false;
    const Eigen::Vector3d p = after->T_frame_body.translation();
    *out = {p.x(), p.y(), p.z(), YawOf(after->T_frame_body)};
    return true;
  }
  const auto before = std::prev(after);
  const double w = (t - before->time).seconds() / (after->time - before->time).seconds();
  const Eigen::Vector3d p =
      (1.0 - w) * before->T_frame_body.translation() + w * after->T_frame_body.translation();
  const double y0 = YawOf(before->T_frame_body), y1 = YawOf(after->T_frame_body);
  const double yaw = y0 + w * std::remainder(y1 - y0, 2.0 * M_PI);
  *out = {p.x(), p.y(), p.z(), std::remainder(yaw, 2.0 * M_PI)};
  return true;
}

}  // namespace

std::string FormatSubmapIndex(const std::string& robot, const std::map<uint64_t, Timestamp>& origin_times,
                              const Trajectory* truth) {
  std::string out = "robot,submap,origin_time,true_x,true_y,true_z,true_yaw\n";
  char buffer[256];
  for (const auto& [id, time] : origin_times) {
    std::snprintf(buffer, sizeof(buffer), "%s,%llu,%.9f", robot.c_str(), static_cast<unsigned long long>(id),
                  time.seconds());
    out += buffer;
    Eigen::Vector4d p;
    if (truth != nullptr && TruthAt(*truth, time, &p)) {
      std::snprintf(buffer, sizeof(buffer), ",%.6f,%.6f,%.6f,%.8f\n", p[0], p[1], p[2], p[3]);
      out += buffer;
    } else {
      out += ",,,,\n";
    }
  }
  return out;
}

}  // namespace cairn
