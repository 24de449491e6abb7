#pragma once
// Pairwise-consistency outlier rejection of loop closures (the idea of PCM, Mangelson et al.,
// ICRA 2018): two closures are consistent when the cycle they close through the odometry is
// the identity within its uncertainty; the largest set of mutually consistent closures is kept.
//
// Odometry chains are maximal runs of consecutive keys of one robot joined by odometry edges;
// each is dead-reckoned in a frame of its own, so no closure (true or false) enters the poses
// the test composes. Closures are grouped by the pair of chains they join (intra-robot closures
// of one chain, inter-robot closures of two robots' chains, ...): only closures of one group
// close a cycle with each other, and each group gets its own maximum clique.
//
// Cycle covariance (first order, documented approximation): every odometry edge and closure
// noise is a right perturbation in its own frame; it is moved to the chain's dead-reckoning frame
// by the adjoint of the pose it acts at, so that the covariance of any odometry segment is a
// difference of prefix sums. The cycle's covariance is the two closures' plus the two segments'
// (the second chain's carried into the first chain's frame through the first closure). The
// squared Mahalanobis length of the cycle error is tested against a chi-square quantile with 6
// degrees of freedom (3 for planar graphs, whose lifted z, roll and pitch carry no information).
//
// Threshold: the maximum clique keeps a true closure only if its cycle with every other true
// closure passes, so each pair is tested at probability confidence^(1/(n - 1)), n the closures of
// the largest group: each true closure passes all its tests with `confidence` under the fitted
// model (a per-pair 99 % fails one of every hundred pairs of true closures, and every failed pair
// takes a true closure out of the clique). The estimated noise scale (noise_scale 0) is the
// robust fit of noise_scale.h to every closure's shortest cycle (fewest odometry edges), not to
// all cycles: the random-walk covariance of the odometry can misstate long segments by another
// factor than short ones, and where long cycles are many they set the median. On the ARGoS
// 2-robot sets (every edge stating 0.1 m and 0.01 rad) cycles of 2-20 odometry edges have a
// median squared length of 104, cycles of about 730 edges 23: the fit to all cycles (half of them
// long there) gave a threshold that 19 of the 34 true closures of `clean` failed. Assumption:
// longer cycles of true closures stay within the fit's tail at that probability, i.e. their
// squared length per stated variance is at most a few times that of the shortest. On `clean` it
// grows 3.5 times from 2 to 24 edges and the threshold, 12 times the shortest cycles' median,
// passes its largest pair (560) by 1.5 %: a thin margin, set by the data, not tuned. On intel and
// sphere2500 with 20 % false closures (one robot, closures of every length) the threshold is 250
// and 5 times the all-cycle fit's: PCM lets more false closures through to the residual screen
// after it (pose_graph_solver.h), which takes them out.

#include <vector>

#include "common/status.h"
#include "estimation/graph/max_clique.h"
#include "estimation/graph/pose_graph.h"

namespace cairn {

struct PairwiseConsistencyOptions {
  double confidence = 0.99;  // probability that every pair of true closures passes its test
  // Factor by which the true noise variance exceeds the one the information matrices state (see
  // noise_scale.h): every covariance of a cycle scales by it, so the threshold does. 0 = estimated
  // from the closures' shortest cycles' squared Mahalanobis lengths (the robust log-normal fit of
  // noise_scale.h, its quantile at the per-pair probability the threshold): the cycle test's own
  // statistic, so that it also absorbs odometry and closures misstated by different factors.
  double noise_scale = 1.0;
  CliqueOptions clique;
};

struct PairwiseConsistencyResult {
  std::vector<bool> keep;      // per edge: false for a rejected loop closure
  int loop_closures = 0;
  int rejected = 0;
  int groups = 0;
  bool exact = true;           // every group's clique is provably maximum
  double threshold = 0.0;      // on the squared Mahalanobis length of a cycle
  double noise_scale = 1.0;    // given or estimated
  int64_t pairs_tested = 0;
};

// Cumulative distribution of the chi-square distribution (integer dof >= 1) at x >= 0.
double ChiSquareCdf(double x, int dof);
// Quantile of the chi-square distribution (integer dof >= 1), by bisection on its CDF.
double ChiSquareQuantile(double probability, int dof);

Expected<PairwiseConsistencyResult> FindConsistentLoopClosures(const PoseGraph& graph,
                                                               const PairwiseConsistencyOptions& options);

}  // namespace cairn
