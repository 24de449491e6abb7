#include "sim/surface_distance.h"

#include <algorithm>
#include <cmath>

namespace cairn::sim {

SurfaceDistance::SurfaceDistance(const Terrain& terrain) : terrain_(&terrain) {}

SurfaceDistance::SurfaceDistance(const MissionSimulator& mission, double robot_period) : terrain_(&mission.terrain()) {
  RenderScene fixed;
  fixed.boxes = mission.static_boxes();
  fixed.markers = mission.landmarks();
  AddScene(fixed);
  const double step = std::max(robot_period, 1e-3);
  for (double t = 0.0; t <= mission.duration() + 1e-9; t += step) {
    RenderScene scene;
    for (const SimRobot& robot : mission.robots()) scene.AddRobot(robot, robot.trajectory.Evaluate(t).T_world_body);
    AddScene(scene);
  }
}

void SurfaceDistance::AddBox(const Eigen::Isometry3d& T_world_box, const Eigen::Vector3d& half_extent) {
  solids_.push_back({T_world_box.inverse(), half_extent, T_world_box.translation(), half_extent.norm()});
}

void SurfaceDistance::AddScene(const RenderScene& scene) {
  for (const SimBox& b : scene.boxes) AddBox(b.T_body_box, b.half_extent);
  // A marker is a flat square: the black border of `size` inside a white quiet ring one module
  // (size / 8) wide.
  for (const SimMarker& m : scene.markers) {
    const double half = 0.5 * m.size * 10.0 / 8.0;
    AddBox(m.T_body_marker, Eigen::Vector3d(half, half, 0.0));
  }
}

double SurfaceDistance::TerrainDistance(const Eigen::Vector3d& p, double radius) const {
  constexpr int kSteps = 10;
  const double step = radius / kSteps;
  double best = std::numeric_limits<double>::infinity();
  for (int sy = -kSteps; sy <= kSteps; ++sy) {
    for (int sx = -kSteps; sx <= kSteps; ++sx) {
      const double dx = step * sx, dy = step * sy;
      const double horizontal2 = dx * dx + dy * dy;
      if (horizontal2 > radius * radius) continue;
      const double dz = p.z() - terrain_->Height(p.x() + dx, p.y() + dy);
      best = std::min(best, horizontal2 + dz * dz);
    }
  }
  return std::sqrt(best);
}

double SurfaceDistance::Distance(const Eigen::Vector3d& p, double radius) const {
  double best = TerrainDistance(p, radius);
  for (const Solid& s : solids_) {
    if ((p - s.centre_world).norm() > s.bounding_radius + std::min(best, radius)) continue;
    // Distance to the box's surface, from outside or inside.
    const Eigen::Vector3d q = (s.T_solid_world * p).cwiseAbs() - s.half_extent;
    const double outside = q.cwiseMax(0.0).norm();
    const double inside = std::min(q.maxCoeff(), 0.0);
    best = std::min(best, outside > 0.0 ? outside : -inside);
  }
  return best;
}

}  // namespace cairn::sim
