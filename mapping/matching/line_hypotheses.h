#pragma once
// 4-DoF hypotheses T_a_b from the submaps' straight edges (paper 000's line segments as a matching
// cue), for man-made places whose faces are too small or too noisy to become planes: a crate's
// edges, a wall's top, a habitat's corners. Two edges of B that are not parallel, paired with two of
// A at the same angle and the same distance between them (both invariant under any rigid motion),
// and tilted from gravity as their partners are, fix the yaw (their directions, or for two vertical
// edges the line between them) and the translation (least squares across both lines; along what they
// leave free, e.g. the height between two vertical edges, the middles of the segments are aligned).
// A pairing survives when each edge of B lands on its partner and the segments overlap along it;
// pairings are ranked by how many of B's edges land on one of A's, then by how close.
// Horizontal pairs are symmetric under a half turn: both yaws are offered, and the matcher's grey
// levels and ICP tell them apart, as for any other hypothesis.

#include <cstdint>
#include <vector>

#include "common/options_visitor.h"
#include "mapping/matching/four_dof_transform.h"
#include "mapping/submap_line.h"

namespace cairn {

struct LineHypothesisOptions {
  bool enabled = true;
  int64_t max_lines = 24;               // longest edges of each submap paired
  double min_length = 0.5;              // m, shorter edges are not paired
  double min_pair_angle = 20.0;         // deg between the two edges of a pair
  double max_angle_mismatch = 5.0;      // deg between the pairs' angles, tilts and yaws
  double max_distance_mismatch = 0.15;  // m between the pairs' distances, and off the partner edge
  double overlap_margin = 0.5;          // m the aligned segments may miss each other by along the edge
  int64_t max_hypotheses = 8;           // best first (most edges agreeing, then closest)

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Integer("max_lines", max_lines, 2, 1000, "edges");
    v.Number("min_length", min_length, 0.0, 100.0, "m");
    v.Number("min_pair_angle", min_pair_angle, 1.0, 89.0, "deg");
    v.Number("max_angle_mismatch", max_angle_mismatch, 0.1, 45.0, "deg");
    v.Number("max_distance_mismatch", max_distance_mismatch, 0.001, 10.0, "m");
    v.Number("overlap_margin", overlap_margin, 0.0, 100.0, "m");
    v.Integer("max_hypotheses", max_hypotheses, 1, 1000, "");
  }
};

struct LineHypothesis {
  FourDofTransform T_a_b;
  double length = 0.0;                   // m, the shortest of the four edges paired
  int edges_agreeing = 0;                // edges of B that land on one of A's (the pair's included)
  double offset = 0.0;                   // m, their mean distance from A's edges
  int a[2] = {-1, -1}, b[2] = {-1, -1};  // the edges paired (a[k] with b[k])
};

class LineHypotheses {
 public:
  explicit LineHypotheses(const LineHypothesisOptions& options) : options_(options) {}

  std::vector<LineHypothesis> Find(const std::vector<SubmapLine>& a, const std::vector<SubmapLine>& b) const;

 private:
  LineHypothesisOptions options_;
};

}  // namespace cairn
