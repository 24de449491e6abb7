#pragma once
// Which planar faces of two submaps are the same plane (paper 003's data association of plane
// landmarks), for the graph's plane landmarks: B's plane is brought into A's frame with the
// graph's estimates of both origins, and the difference of the two planes (two normal components
// and the offset, in A's plane's tangent axes) is gated on its Mahalanobis distance, with both
// planes' covariances and both origins' marginal covariances (their correlation is not known
// here: the sum overstates the relative uncertainty, so the gate errs wide and the checks after
// it carry the weight). Then geometry: both faces steep (the ground is level, and a level plane
// of uneven terrain is no landmark), large enough, facing the same way, their extents within a
// margin of each other; and no ambiguity: a pairing stands only when no other pairing of either
// plane comes within a margin of its distance. Each plane is paired at most once.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/options_visitor.h"
#include "mapping/matching/submap_placement.h"
#include "mapping/submap_plane.h"

namespace cairn {

struct PlaneAssociationOptions {
  double gate_chi2 = 11.34;         // chi2(3) at 99 %
  double ambiguity_chi2 = 9.0;      // a rival pairing within this of the best leaves both out
  double max_nz = 0.9;              // |normal z|: at least 26 deg from level
  double min_area = 1.0;            // m^2 of each face
  double extent_margin = 1.0;       // m the faces' extents may lie apart in the plane
  double min_normal_sigma = 0.005;  // rad added to each plane's normal (model error, e.g. bent panels)
  double min_offset_sigma = 0.02;   // m added to each plane's offset

  void Visit(OptionsVisitor& v) {
    v.Number("gate_chi2", gate_chi2, 0.1, 1000.0, "chi2(3)");
    v.Number("ambiguity_chi2", ambiguity_chi2, 0.0, 1000.0, "chi2(3)");
    v.Number("max_nz", max_nz, 0.0, 1.0, "");
    v.Number("min_area", min_area, 0.0, 1e6, "m^2");
    v.Number("extent_margin", extent_margin, 0.0, 100.0, "m");
    v.Number("min_normal_sigma", min_normal_sigma, 0.0, 1.0, "rad");
    v.Number("min_offset_sigma", min_offset_sigma, 0.0, 10.0, "m");
  }
};

struct PlaneAssociation {
  int a = -1, b = -1;  // plane indices
  double chi2 = 0.0;
};

class PlaneAssociator {
 public:
  explicit PlaneAssociator(const PlaneAssociationOptions& options) : options_(options) {}

  // Whether a face can be a landmark at all (steep and large enough).
  bool Eligible(const SubmapPlane& p) const;
  // The plane's covariance of (a, b, d) with the model error added.
  Eigen::Matrix3d Covariance(const SubmapPlane& p) const;

  std::vector<PlaneAssociation> Associate(const std::vector<SubmapPlane>& a, const SubmapPlacement& placed_a,
                                          const std::vector<SubmapPlane>& b,
                                          const SubmapPlacement& placed_b) const;

  // Mahalanobis distance of pairing plane `pa` of A with `pb` of B; negative when they face
  // opposite ways or their extents lie apart.
  double Distance(const SubmapPlane& pa, const SubmapPlacement& placed_a, const SubmapPlane& pb,
                  const SubmapPlacement& placed_b) const;

 private:
  PlaneAssociationOptions options_;
};

}  // namespace cairn
