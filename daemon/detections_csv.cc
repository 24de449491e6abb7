#include "daemon/detections_csv.h"

#include <cmath>
#include <cstdio>

namespace cairn {

std::string FormatDetectionsCsv(const std::vector<DetectionRecord>& records) {
  std::string out =
      "#time [ns],observer,observed,landmark,tag_id,x [m],y [m],z [m],qw,qx,qy,qz,sigma_x [m],sigma_y [m],"
      "sigma_z [m],sigma_rx [rad],sigma_ry [rad],sigma_rz [rad],distance [m],view_angle [deg],status\n";
  char buf[512];
  for (const DetectionRecord& r : records) {
    const TeamDetection& d = r.detection;
    const Eigen::Vector3d t = d.T_observer_observed.translation();
    const Eigen::Quaterniond q(d.T_observer_observed.linear());
    double s[6];
    for (int i = 0; i < 6; ++i) s[i] = std::sqrt(std::max(0.0, d.covariance(i, i)));
    std::snprintf(buf, sizeof buf, "%lld,%s,%s,%d,%d,%.4f,%.4f,%.4f,%.6f,%.6f,%.6f,%.6f,%.4f,%.4f,%.4f,%.5f,%.5f,%.5f,%.3f,%.2f,",
                  static_cast<long long>(d.time.nanoseconds()), d.observer.c_str(), d.observed.c_str(), d.landmark ? 1 : 0,
                  d.tag_id, t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z(), s[0], s[1], s[2], s[3], s[4], s[5],
                  d.distance, d.view_angle * 180.0 / M_PI);
    std::string status = r.status;
    for (char& c : status) {
      if (c == ',' || c == '\n') c = ';';
    }
    out += buf + status + "\n";
  }
  return out;
}

}  // namespace cairn
