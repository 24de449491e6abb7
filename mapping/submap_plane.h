#pragma once
// A planar face of a submap (paper 003's plane landmark), in the submap's gravity-aligned frame:
// normal . p + offset = 0, with the normal towards the cameras that saw it.
//
// Paper 003 uses (rho, phi, psi) with phi the normal's azimuth; phi is undefined for level planes,
// and the ground is the largest plane of nearly every submap. So the uncertainty is kept in the
// plane's tangent space instead: the normal moves as normalize(normal + a u + b v) and the offset
// by d, with (u, v) from Axes(); `covariance` is that of (a, b, d).

#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimation/math/tangent_axes.h"

namespace cairn {

struct SubmapPlane {
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();
  float offset = 0.0f;                                   // m
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();    // of the points it was fitted to
  Eigen::Matrix3f covariance = Eigen::Matrix3f::Zero();  // of (a, b, d): rad, rad, m
  Eigen::Vector2f min = Eigen::Vector2f::Zero();         // extent along (u, v) from the centroid, m
  Eigen::Vector2f max = Eigen::Vector2f::Zero();
  float area = 0.0f;  // m^2 the plane's faces cover
  uint32_t points = 0;

  // In-plane axes: u level (along the plane's intersection with the horizontal, as paper 003's
  // x axis) unless the plane is within about 6 deg of level, where u follows x instead.
  static void Axes(const Eigen::Vector3f& n, Eigen::Vector3f* u, Eigen::Vector3f* v) { TangentAxes(n, u, v); }
};

}  // namespace cairn
