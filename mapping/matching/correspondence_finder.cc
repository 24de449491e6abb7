#include "mapping/matching/correspondence_finder.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Core>

namespace cairn {
namespace {

// Dynamic rows: with a fixed row count GCC 12 reports a false -Waggressive-loop-optimizations in
// Eigen's matrix-vector kernel.
using DescriptorMatrix = Eigen::MatrixXf;

DescriptorMatrix ToMatrix(const std::vector<GravityShot>& d) {
  DescriptorMatrix m(kGravityShotSize, static_cast<Eigen::Index>(d.size()));
  for (size_t i = 0; i < d.size(); ++i) {
    m.col(static_cast<Eigen::Index>(i)) =
        Eigen::Map<const Eigen::Matrix<float, kGravityShotSize, 1>>(d[i].data());
  }
  return m;
}

// The k smallest squared distances seen, with their indices, ascending.
class BestK {
 public:
  explicit BestK(int k) : k_(k) {}
  void Offer(float d2, uint32_t index, std::pair<float, uint32_t>* slots, int* count) const {
    if (*count == k_ && d2 >= slots[k_ - 1].first) return;
    int i = *count < k_ ? (*count)++ : k_ - 1;
    while (i > 0 && slots[i - 1].first > d2) {
      slots[i] = slots[i - 1];
      --i;
    }
    slots[i] = {d2, index};
  }

 private:
  int k_;
};

}  // namespace

std::vector<KeypointCorrespondence> CorrespondenceFinder::Find(const std::vector<GravityShot>& a,
                                                               const std::vector<GravityShot>& b) const {
  std::vector<KeypointCorrespondence> out;
  if (a.empty() || b.empty()) return out;
  const int k = static_cast<int>(std::max<int64_t>(1, options_.matches_per_keypoint));
  const size_t na = a.size(), nb = b.size();
  const DescriptorMatrix ma = ToMatrix(a), mb = ToMatrix(b);
  const Eigen::VectorXf norm_a = ma.colwise().squaredNorm().transpose();
  const Eigen::RowVectorXf norm_b = mb.colwise().squaredNorm();
  // Distance in [0, 1] is |a - b| / sqrt(2): compare squared distances against 2 max^2.
  const float max_d2 = static_cast<float>(2.0 * options_.max_distance * options_.max_distance);

  const BestK best(k);
  using Slot = std::pair<float, uint32_t>;
  std::vector<Slot> row_best(na * static_cast<size_t>(k)), col_best(nb * static_cast<size_t>(k));
  std::vector<int> row_count(na, 0), col_count(nb, 0);
  constexpr Eigen::Index kBlock = 256;
  Eigen::MatrixXf d2;
  for (Eigen::Index begin = 0; begin < static_cast<Eigen::Index>(na); begin += kBlock) {
    const Eigen::Index rows = std::min<Eigen::Index>(kBlock, static_cast<Eigen::Index>(na) - begin);
    d2.noalias() = -2.0f * (ma.middleCols(begin, rows).transpose() * mb);
    d2.colwise() += norm_a.segment(begin, rows);
    d2.rowwise() += norm_b;
    for (Eigen::Index c = 0; c < d2.cols(); ++c) {
      const size_t j = static_cast<size_t>(c);
      for (Eigen::Index r = 0; r < rows; ++r) {
        const float v = std::max(0.0f, d2(r, c));
        if (!(v <= max_d2)) continue;
        const size_t i = static_cast<size_t>(begin + r);
        best.Offer(v, static_cast<uint32_t>(j), &row_best[i * static_cast<size_t>(k)], &row_count[i]);
        best.Offer(v, static_cast<uint32_t>(i), &col_best[j * static_cast<size_t>(k)], &col_count[j]);
      }
    }
  }

  struct Pair {
    uint32_t a, b;
    float d2;
    uint8_t from;  // bit 0: among a's best, bit 1: among b's best
  };
  std::vector<Pair> pairs;
  for (size_t i = 0; i < na; ++i) {
    for (int s = 0; s < row_count[i]; ++s) {
      const Slot& slot = row_best[i * static_cast<size_t>(k) + static_cast<size_t>(s)];
      pairs.push_back({static_cast<uint32_t>(i), slot.second, slot.first, 1});
    }
  }
  for (size_t j = 0; j < nb; ++j) {
    for (int s = 0; s < col_count[j]; ++s) {
      const Slot& slot = col_best[j * static_cast<size_t>(k) + static_cast<size_t>(s)];
      pairs.push_back({slot.second, static_cast<uint32_t>(j), slot.first, 2});
    }
  }
  std::sort(pairs.begin(), pairs.end(),
            [](const Pair& x, const Pair& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
  for (size_t i = 0; i < pairs.size();) {
    size_t e = i;
    uint8_t from = 0;
    while (e < pairs.size() && pairs[e].a == pairs[i].a && pairs[e].b == pairs[i].b) from |= pairs[e++].from;
    if (!options_.mutual_only || from == 3) {
      KeypointCorrespondence c;
      c.a = pairs[i].a;
      c.b = pairs[i].b;
      c.distance = std::sqrt(pairs[i].d2 * 0.5f);
      c.score = 1.0f - c.distance;
      out.push_back(c);
    }
    i = e;
  }
  return out;
}

}  // namespace cairn
