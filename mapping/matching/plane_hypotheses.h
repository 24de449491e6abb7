#pragma once
// 4-DoF hypotheses T_a_b from the submaps' planar faces (paper 003's plane landmarks as a matching
// cue), for places where the dense descriptors find little: walls, crates, habitats. Two steep
// planes of B that are not parallel, paired with two of A at the same angle between them, fix the
// yaw (their normals) and x, y (their offsets); the largest level plane of each, z. A plane may be
// paired with the other side of a face (a wall one robot saw from the front and another from the
// back). A pairing survives when each plane of B lands on its partner's extent. The matcher then
// checks the grey levels and runs the ICP as for any other hypothesis.

#include <cstdint>
#include <vector>

#include "common/options_visitor.h"
#include "mapping/matching/four_dof_transform.h"
#include "mapping/submap_plane.h"

namespace cairn {

struct PlaneHypothesisOptions {
  bool enabled = true;
  double max_steep_nz = 0.5;        // |normal z| of a steep plane (sin 30 deg: at least 60 deg from level)
  double min_level_nz = 0.95;       // |normal z| of a level plane
  double min_pair_angle = 30.0;     // deg between the two steep planes of a pair (and at most 180 minus it)
  double max_angle_mismatch = 5.0;  // deg between the pairs' angles, and between the yaws they give
  double extent_margin = 1.0;       // m a plane's centroid may land beyond its partner's extent
  int64_t max_hypotheses = 8;       // best first (the smaller face of a pairing largest)

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Number("max_steep_nz", max_steep_nz, 0.0, 1.0, "");
    v.Number("min_level_nz", min_level_nz, 0.0, 1.0, "");
    v.Number("min_pair_angle", min_pair_angle, 1.0, 89.0, "deg");
    v.Number("max_angle_mismatch", max_angle_mismatch, 0.1, 45.0, "deg");
    v.Number("extent_margin", extent_margin, 0.0, 100.0, "m");
    v.Integer("max_hypotheses", max_hypotheses, 1, 1000, "");
  }
};

struct PlaneHypothesis {
  FourDofTransform T_a_b;
  double area = 0.0;                     // m^2, the smallest of the four faces paired
  int a[2] = {-1, -1}, b[2] = {-1, -1};  // the planes paired
};

class PlaneHypotheses {
 public:
  explicit PlaneHypotheses(const PlaneHypothesisOptions& options) : options_(options) {}

  std::vector<PlaneHypothesis> Find(const std::vector<SubmapPlane>& a,
                                    const std::vector<SubmapPlane>& b) const;

 private:
  // Whether `p` (A's frame) lies on plane `q`'s extent, within the margin.
  bool OnExtent(const SubmapPlane& q, const Eigen::Vector3d& p) const;

  PlaneHypothesisOptions options_;
};

}  // namespace cairn
