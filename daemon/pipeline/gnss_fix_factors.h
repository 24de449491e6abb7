#pragma once
// GNSS fixes as graph factors (paper 000's GPS events): each usable fix becomes a factor between
// the team's datum variable e = T_world_enu and the robot's pose x at the fix's time. The graph's
// world stays the robot's first submap origin; the datum is estimated like any variable, so the
// fixes correct the drift of the trajectory and the map comes out geo-referenced, and robots that
// share the datum are tied through it.
//
// The datum's yaw is unobservable until the robot has moved, and an optimizer started far from it
// (with the robust loss every fix has) may not find it. So fixes are held until the robot's
// positions at them determine the yaw to `start_yaw_sigma` (from the fixes' accuracy and the
// positions' spread, not the fixes' own scatter, which noise alone would grow); then a
// closed-form yaw-and-translation fit of the held fixes to the graph's poses starts the datum,
// with a prior that only knows it is level (both frames are gravity aligned) and is otherwise
// nearly flat, and the held fixes enter as factors.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/options_visitor.h"
#include "common/status.h"
#include "estimation/graph/slam_graph_types.h"
#include "estimation/math/local_tangent_plane.h"
#include "hal/gnss_fix.h"

namespace cairn {

struct GnssFixOptions {
  bool enabled = false;
  // The team's datum: every robot of a team must use the same one.
  double datum_latitude = 0.0;                               // deg
  double datum_longitude = 0.0;                              // deg
  double datum_height = 0.0;                                 // m above the WGS84 ellipsoid
  double antenna_x = 0.0, antenna_y = 0.0, antenna_z = 0.0;  // m, in the body frame
  double start_yaw_sigma = 0.05;  // rad: the held fixes must fix the datum's yaw this well to start it
  double max_sigma = 10.0;        // m: fixes reporting worse accuracy (largest axis) are refused
  double min_sigma = 0.01;        // m: floor added to the reported accuracy (antenna phase centre, timing)
  double tilt_sigma = 0.02;       // rad: how level the graph's world is (the filter's initial attitude)

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Number("datum_latitude", datum_latitude, -90.0, 90.0, "deg");
    v.Number("datum_longitude", datum_longitude, -180.0, 180.0, "deg");
    v.Number("datum_height", datum_height, -1000.0, 100000.0, "m");
    v.Number("antenna_x", antenna_x, -10.0, 10.0, "m");
    v.Number("antenna_y", antenna_y, -10.0, 10.0, "m");
    v.Number("antenna_z", antenna_z, -10.0, 10.0, "m");
    v.Number("start_yaw_sigma", start_yaw_sigma, 1e-4, 1.0, "rad");
    v.Number("max_sigma", max_sigma, 0.001, 1000.0, "m");
    v.Number("min_sigma", min_sigma, 0.0, 100.0, "m");
    v.Number("tilt_sigma", tilt_sigma, 1e-4, 1.0, "rad");
  }
};

struct GnssFixCounts {
  uint64_t fixes = 0;    // given
  uint64_t factors = 0;  // entered the graph
  uint64_t held = 0;     // waiting for the datum to start
  bool datum_started = false;
};

class GnssFixFactors {
 public:
  explicit GnssFixFactors(const GnssFixOptions& options);

  // The datum variable's key (one per graph).
  static uint64_t DatumKey();
  // Checks `fix` and converts it to the datum's ENU; an error says why it cannot be used.
  Status Check(const GnssFix& fix) const;
  // A checked fix of an antenna at `antenna` in the body of graph pose `pose_key` (this robot's or a
  // teammate's tied to it), whose current estimate is `T_world_body`. Returns the factors to add
  // now: none while the datum waits; the datum's prior and every held fix when it starts;
  // afterwards this fix's factor.
  std::vector<SlamFactor> Add(const GnssFix& fix, uint64_t pose_key, const Pose3& T_world_body,
                              const Eigen::Vector3d& antenna);
  // This robot's antenna, in its body frame.
  const Eigen::Vector3d& antenna() const { return antenna_; }
  const GnssFixCounts& counts() const { return counts_; }

  // The sigma of a yaw fitted to weighted points (infinite while they coincide): the robot's
  // positions at its fixes, not the fixes' own scatter, which noise alone would grow.
  static double YawSigma(const std::vector<Eigen::Vector3d>& points, const std::vector<double>& weights);
  // The rigid (yaw and translation) move that puts a floating subgraph onto the datum at
  // T_world_enu: `fixes` of antennas at `antenna_floating` in the subgraph's frame. An error while
  // they do not fix its yaw to start_yaw_sigma.
  Expected<Pose3> PlaceFloating(const std::vector<GnssFix>& fixes,
                                const std::vector<Eigen::Vector3d>& antenna_floating,
                                const Pose3& T_world_enu) const;
  // Weighted fit of T_world_enu (yaw and translation; level) to antenna positions in the world and
  // the same positions in ENU with their horizontal weights. Needs two distinct points.
  static Expected<Pose3> FitDatum(const std::vector<Eigen::Vector3d>& p_world,
                                  const std::vector<Eigen::Vector3d>& z_enu,
                                  const std::vector<double>& weights);

 private:
  struct Held {
    uint64_t pose_key = 0;
    Eigen::Vector3d z_enu;
    Eigen::Matrix3d covariance;
    Eigen::Vector3d antenna;
    Eigen::Vector3d antenna_world;
  };
  SlamFactor FactorOf(const Held& h) const;
  // The fix's stated accuracy in the datum's axes, floored by min_sigma.
  Eigen::Matrix3d CovarianceInDatum(const GnssFix& fix) const;
  // The horizontal weight of a fix of covariance `covariance` (m^2, ENU).
  static double Weight(const Eigen::Matrix3d& covariance);

  GnssFixOptions options_;
  LocalTangentPlane plane_;
  Eigen::Vector3d antenna_;
  std::vector<Held> held_;
  GnssFixCounts counts_;
};

}  // namespace cairn
