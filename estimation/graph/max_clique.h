#pragma once
// Maximum clique of an undirected graph given as bit rows (row v has bit w set when v and w are
// adjacent; symmetric, no self loops). Used by pairwise-consistency outlier rejection, where the
// vertices are loop closures and the edges mean "these two agree with the odometry".

#include <cstddef>
#include <cstdint>
#include <vector>

namespace cairn {

// One row of 64-bit words per vertex.
using BitRows = std::vector<std::vector<uint64_t>>;

// n vertices without edges.
BitRows MakeBitRows(size_t n);
inline void SetEdge(BitRows& rows, size_t a, size_t b) {
  rows[a][b / 64] |= uint64_t{1} << (b % 64);
  rows[b][a / 64] |= uint64_t{1} << (a % 64);
}

struct CliqueResult {
  std::vector<int> members;  // ascending vertex indices
  bool exact = false;        // the branch and bound ran to completion: no larger clique exists
};

struct CliqueOptions {
  // Graphs up to this many vertices get the exact branch and bound after the greedy search.
  int exact_limit = 400;
  // Branch-and-bound nodes before giving up on exactness (the greedy clique then stands).
  int64_t node_budget = 200000;
  // Greedy starts, from the vertices of highest degree.
  int greedy_starts = 256;
};

// Greedy multi-start search (each start grows a clique from one vertex through its neighbours in
// decreasing degree order), then, for small graphs, a branch and bound with greedy-colouring bounds
// seeded with the greedy clique.
CliqueResult MaximumClique(const BitRows& adjacency, const CliqueOptions& options = {});

}  // namespace cairn
