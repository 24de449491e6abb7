#include "estimation/graph/max_clique.h"

#include <algorithm>
#include <bit>
#include <numeric>

namespace cairn {
namespace {

using Bits = std::vector<uint64_t>;

bool Test(const Bits& b, size_t v) { return (b[v / 64] >> (v % 64)) & 1u; }
void Clear(Bits& b, size_t v) { b[v / 64] &= ~(uint64_t{1} << (v % 64)); }
bool Empty(const Bits& b) {
  return std::all_of(b.begin(), b.end(), [](uint64_t w) { return w == 0; });
}
size_t First(const Bits& b) {
  for (size_t k = 0; k < b.size(); ++k) {
    if (b[k] != 0) return 64 * k + static_cast<size_t>(std::countr_zero(b[k]));
  }
  return b.size() * 64;
}
void And(Bits& a, const Bits& b) {
  for (size_t k = 0; k < a.size(); ++k) a[k] &= b[k];
}

std::vector<int> Greedy(const BitRows& adj, const std::vector<size_t>& order, size_t start) {
  Bits candidates = adj[start];
  std::vector<int> clique{static_cast<int>(start)};
  for (size_t w : order) {
    if (!Test(candidates, w)) continue;
    clique.push_back(static_cast<int>(w));  // adjacent to every member so far
    And(candidates, adj[w]);
  }
  return clique;
}

// Branch and bound in the manner of Tomita's MCQ: colour the candidates greedily, a colour class
// being an independent set, so that |R| + colours bounds any clique grown from R.
struct Search {
  Search(const BitRows& rows, int64_t node_budget) : adj(rows), budget(node_budget) {}
  const BitRows& adj;
  int64_t budget;
  int64_t nodes = 0;
  bool aborted = false;
  std::vector<int> best;
  std::vector<int> current;

  void Expand(Bits candidates) {
    if (++nodes > budget) {
      aborted = true;
      return;
    }
    std::vector<std::pair<size_t, int>> coloured;  // vertex, colour bound, in colouring order
    Bits uncoloured = candidates;
    for (int colour = 1; !Empty(uncoloured); ++colour) {
      Bits independent = uncoloured;
      while (!Empty(independent)) {
        const size_t v = First(independent);
        Clear(independent, v);
        Clear(uncoloured, v);
        for (size_t k = 0; k < independent.size(); ++k) independent[k] &= ~adj[v][k];
        coloured.emplace_back(v, colour);
      }
    }
    for (size_t i = coloured.size(); i-- > 0;) {
      const auto [v, bound] = coloured[i];
      if (current.size() + static_cast<size_t>(bound) <= best.size()) return;
      current.push_back(static_cast<int>(v));
      Bits next = candidates;
      And(next, adj[v]);
      if (Empty(next)) {
        if (current.size() > best.size()) best = current;
      } else {
        Expand(std::move(next));
      }
      current.pop_back();
      Clear(candidates, v);
      if (aborted) return;
    }
  }
};

}  // namespace

BitRows MakeBitRows(size_t n) { return BitRows(n, Bits((n + 63) / 64, 0)); }

CliqueResult MaximumClique(const BitRows& adjacency, const CliqueOptions& options) {
  CliqueResult result;
  const size_t n = adjacency.size();
  if (n == 0) {
    result.exact = true;
    return result;
  }
  std::vector<int> degree(n);
  for (size_t v = 0; v < n; ++v) {
    int d = 0;
    for (uint64_t w : adjacency[v]) d += std::popcount(w);
    degree[v] = d;
  }
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return degree[a] > degree[b]; });
  std::vector<int> best;
  for (size_t s = 0; s < order.size() && s < static_cast<size_t>(options.greedy_starts); ++s) {
    // No clique through a vertex exceeds its degree + 1; the order is by decreasing degree.
    if (static_cast<size_t>(degree[order[s]]) + 1 <= best.size()) break;
    std::vector<int> clique = Greedy(adjacency, order, order[s]);
    if (clique.size() > best.size()) best = std::move(clique);
  }
  if (n <= static_cast<size_t>(options.exact_limit)) {
    Search search(adjacency, options.node_budget);
    search.best = best;
    Bits all((n + 63) / 64, ~uint64_t{0});
    if (n % 64 != 0) all.back() = (uint64_t{1} << (n % 64)) - 1;
    search.Expand(std::move(all));
    result.exact = !search.aborted;
    best = std::move(search.best);
  }
  std::sort(best.begin(), best.end());
  result.members = std::move(best);
  return result;
}

}  // namespace cairn
