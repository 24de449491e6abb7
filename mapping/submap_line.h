#pragma once
// A straight edge of a submap (paper 000's line landmark) as an anchored Pluecker line in the submap's
// frame: anchor p0, moment n = (p - p0) x v of any point p on the line, and unit direction v; the
// segment's ends are abscissas along v from the line's point closest to the anchor (eq. 13), so that
// later sightings of a longer stretch only move them (extensible endpoints).
//
// The anchor is the viewpoint that first saw the edge: the stereo error of the moment then grows with
// the distance from that camera, as it should, and stays small where the line was seen from. The
// anchor itself is exact in the submap frame (it is a camera centre of that frame), so `covariance`
// is that of (n, v) only; it has rank 4 (a line has four degrees of freedom: n . v = 0 and |v| = 1
// are held).

#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cairn {

struct SubmapLine {
  Eigen::Vector3f anchor = Eigen::Vector3f::Zero();      // m, submap frame
  Eigen::Vector3f moment = Eigen::Vector3f::Zero();      // n, m
  Eigen::Vector3f direction = Eigen::Vector3f::UnitX();  // v, unit
  float t_min = 0.0f;                                    // m along v from ClosestPoint()
  float t_max = 0.0f;
  Eigen::Matrix<float, 6, 6> covariance = Eigen::Matrix<float, 6, 6>::Zero();  // of (n, v)
  uint32_t sightings = 0;  // images the edge was triangulated in

  // The line's point closest to the anchor: p0 + v x n for a unit v.
  Eigen::Vector3f ClosestPoint() const { return anchor + direction.cross(moment); }
  Eigen::Vector3f End(float t) const { return ClosestPoint() + t * direction; }
  float length() const { return t_max - t_min; }
};

}  // namespace cairn
