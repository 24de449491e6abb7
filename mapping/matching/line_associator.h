#pragma once
// Which straight edges of two submaps are the same line (paper 000's data association of line
// landmarks), for the graph's line landmarks, as PlaneAssociator does for planes: B's line is
// brought into A's frame with the graph's estimates of both origins, and its error against A's
// line (line_factors.h's e: B's direction on A's tangent axes (u, w), and the offset of B's point
// closest to A's middle) is gated on its Mahalanobis distance, with both lines' covariances and both
// origins' marginal covariances (their sum, as for planes: the gate errs wide). Then geometry: both
// edges long enough and seen often enough, their extents along A's line within a margin of each
// other; and no ambiguity (unambiguous_pairs.h). An edge has no orientation: B's line is compared
// with its direction turned towards A's.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/options_visitor.h"
#include "mapping/matching/submap_placement.h"
#include "mapping/submap_line.h"

namespace cairn {

struct LineAssociationOptions {
  double gate_chi2 = 13.28;            // chi2(4) at 99 %
  double ambiguity_chi2 = 9.0;         // a rival pairing within this of the best leaves both out
  double min_length = 1.0;             // m of each edge
  int min_sightings = 3;               // images each edge was triangulated in
  double extent_margin = 0.5;          // m the edges' extents may lie apart along the line
  double min_direction_sigma = 0.005;  // rad added to each line's direction (model error, rounded edges)
  double min_offset_sigma = 0.02;      // m added to each line's offset

  void Visit(OptionsVisitor& v) {
    v.Number("gate_chi2", gate_chi2, 0.1, 1000.0, "chi2(4)");
    v.Number("ambiguity_chi2", ambiguity_chi2, 0.0, 1000.0, "chi2(4)");
    v.Number("min_length", min_length, 0.0, 1000.0, "m");
    v.Integer("min_sightings", min_sightings, 0, 1'000'000, "images");
    v.Number("extent_margin", extent_margin, 0.0, 100.0, "m");
    v.Number("min_direction_sigma", min_direction_sigma, 0.0, 1.0, "rad");
    v.Number("min_offset_sigma", min_offset_sigma, 0.0, 10.0, "m");
  }
};

struct LineAssociation {
  int a = -1, b = -1;  // line indices
  double chi2 = 0.0;
};

class LineAssociator {
 public:
  explicit LineAssociator(const LineAssociationOptions& options) : options_(options) {}

  // Whether an edge can be a landmark at all (long and seen often enough, finite).
  bool Eligible(const SubmapLine& l) const;
  // The segment's middle, where its error e is measured.
  static Eigen::Vector3d Middle(const SubmapLine& l);
  // The covariance of the line's error e at its middle in its tangent axes, with the model error
  // added.
  Eigen::Matrix4d Covariance(const SubmapLine& l) const;

  std::vector<LineAssociation> Associate(const std::vector<SubmapLine>& a, const SubmapPlacement& placed_a,
                                         const std::vector<SubmapLine>& b,
                                         const SubmapPlacement& placed_b) const;

  // Mahalanobis distance of pairing line `la` of A with `lb` of B; negative when their extents lie
  // apart along A's line or the covariance is degenerate.
  double Distance(const SubmapLine& la, const SubmapPlacement& placed_a, const SubmapLine& lb,
                  const SubmapPlacement& placed_b) const;
  // At most Distance (when that is not negative), from the errors alone: Associate skips the
  // Jacobians of pairings this already puts beyond every rival's reach.
  double LowerBound(const SubmapLine& la, const SubmapPlacement& placed_a, const SubmapLine& lb,
                    const SubmapPlacement& placed_b) const;

 private:
  // What Associate works out once per line rather than once per pairing.
  struct Prepared {
    int index = -1;
    Eigen::Vector3d middle, direction;
    Eigen::Matrix4d covariance;
  };
  Prepared Prepare(const SubmapLine& l, int index) const;
  double LowerBound(const Prepared& a, const SubmapPlacement& placed_a, const Prepared& b,
                    const SubmapPlacement& placed_b, const Eigen::Isometry3d& T_a_b) const;
  double Distance(const SubmapLine& la, const Prepared& a, const SubmapPlacement& placed_a,
                  const SubmapLine& lb, const Prepared& b, const SubmapPlacement& placed_b,
                  const Eigen::Isometry3d& T_a_b) const;

  LineAssociationOptions options_;
};

}  // namespace cairn
