#pragma once
// Joins the stereo line segments of a submap's images into its edges (SubmapLine). A segment joins
// the edge it is closest to when its direction, its endpoints' distances from the edge (against
// their stereo errors) and its stretch along the edge all agree; otherwise it starts an edge. Each
// edge is the weighted least-squares line through the endpoints of all its segments, each segment's
// two endpoints weighted by their joint error across the line (eq. 5.2 is long along the line of
// sight, so an endpoint pins the line well only across it); the fit's 4 x 4 covariance, inflated by the
// reduced chi-square where the endpoints scatter more than their errors say, becomes that of the anchored
// Pluecker line. Endpoints along the line are where segments end: an edge seen whole from far and in
// part from near keeps the whole.
//
// Not thread safe; the mapping thread owns one. Memory is bounded by `max_lines` edges of at most
// `max_segments` segments each; after the first submaps, Add() allocates nothing (Reset() keeps the
// edges' capacity).

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "common/options_visitor.h"
#include "mapping/line_sighting.h"
#include "mapping/submap_line.h"

namespace cairn {

struct LineFusionOptions {
  double max_angle = 15.0;    // deg between a segment and an edge it may join (a cheap first test)
  double gate_chi2 = 23.5;    // of both endpoints' distances from the edge (4 dof, 99.99 %)
  double max_gap = 0.3;       // m along the edge between it and a segment that joins it
  int64_t min_sightings = 2;  // images an edge needs to be kept
  double min_length = 0.3;    // m, shorter edges are not kept
  int64_t max_lines = 256;    // edges per submap (new segments start no more)
  int64_t max_segments = 32;  // per edge refitted; later ones only extend its ends

  void Visit(OptionsVisitor& v) {
    v.Number("max_angle", max_angle, 0.1, 45.0, "deg");
    v.Number("gate_chi2", gate_chi2, 1.0, 1000.0, "chi2");
    v.Number("max_gap", max_gap, 0.0, 100.0, "m");
    v.Integer("min_sightings", min_sightings, 1, 1000, "images");
    v.Number("min_length", min_length, 0.0, 100.0, "m");
    v.Integer("max_lines", max_lines, 1, 100000, "lines");
    v.Integer("max_segments", max_segments, 2, 10000, "segments");
  }
};

class SubmapLineFuser {
 public:
  explicit SubmapLineFuser(const LineFusionOptions& options);

  // Starts a new submap's edges.
  void Reset();
  // Adds one image's segment (in the submap frame); false when it was not usable (not finite, degenerate) or
  // no edge could take it and the edges are at `max_lines`.
  bool Add(const LineSighting& s);
  // The kept edges (enough sightings and length), longest first.
  std::vector<SubmapLine> Lines() const;
  size_t edges() const { return used_; }

 private:
  struct Segment {
    Eigen::Vector3d a, b;
    Eigen::Matrix<double, 6, 6> cov;  // of (a, b)
  };
  struct Edge {
    Eigen::Vector3d anchor = Eigen::Vector3d::Zero();
    Eigen::Vector3d point = Eigen::Vector3d::Zero();  // on the line
    Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
    Eigen::Matrix4d covariance = Eigen::Matrix4d::Identity();  // of (shift 2, tilt 2), see Refit
    Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();  // extreme ends seen
    std::vector<Segment> segments;
    uint32_t sightings = 0;
  };
  // Chi-square of the segment's endpoints across the edge; negative when direction or stretch
  // disagree.
  double Distance(const Edge& e, const LineSighting& s) const;
  static void Refit(Edge* e);
  static void Extend(Edge* e, const Eigen::Vector3d& p);
  static SubmapLine ToLine(const Edge& e);

  LineFusionOptions options_;
  double cos_max_angle_;
  std::vector<Edge> edges_;  // a pool: the first used_ are this submap's, the rest kept for reuse
  size_t used_ = 0;
};

}  // namespace cairn
