#pragma once
// Distance from a point to the true surfaces of a simulated world, for scoring maps against
// ground truth: the terrain's height field, the static boxes (lander) with their markers, and
// optionally every robot's body and markers wherever it was during the mission (a teammate seen
// at some instant left voxels there; which instant is not known to the map).

#include <limits>
#include <vector>

#include <Eigen/Geometry>

#include "sim/mission_simulator.h"
#include "sim/terrain.h"

namespace cairn::sim {

class SurfaceDistance {
 public:
  // The terrain alone (it must outlive this object).
  explicit SurfaceDistance(const Terrain& terrain);
  // The terrain, the static boxes and the robots' bodies sampled every `robot_period` s of the
  // mission (the simulator must outlive this object).
  SurfaceDistance(const MissionSimulator& mission, double robot_period);

  // Distance from p to the nearest true surface when one lies within `radius`; otherwise some
  // value above `radius`. The terrain is searched on a grid of radius / 10 around p, so the result
  // overestimates by at most about that step on sloped ground.
  double Distance(const Eigen::Vector3d& p, double radius) const;

  size_t solid_count() const { return solids_.size(); }

 private:
  struct Solid {
    Eigen::Isometry3d T_solid_world;
    Eigen::Vector3d half_extent;
    Eigen::Vector3d centre_world;
    double bounding_radius;
  };
  void AddBox(const Eigen::Isometry3d& T_world_box, const Eigen::Vector3d& half_extent);
  void AddScene(const RenderScene& scene);
  double TerrainDistance(const Eigen::Vector3d& p, double radius) const;

  const Terrain* terrain_;
  std::vector<Solid> solids_;
};

}  // namespace cairn::sim
