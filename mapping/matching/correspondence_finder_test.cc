#include "mapping/matching/correspondence_finder.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace cairn {
namespace {

GravityShot Normalized(GravityShot d) {
  double s = 0.0;
  for (float v : d) s += static_cast<double>(v) * v;
  for (float& v : d) v = static_cast<float>(v / std::sqrt(s));
  return d;
}

// Random sparse non-negative unit descriptors, and noisy copies of them in shuffled order.
struct Sets {
  std::vector<GravityShot> a, b;
  std::vector<uint32_t> b_of_a;  // the true partner in b of each a
};

Sets MakeSets(int n, float noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Sets s;
  for (int i = 0; i < n; ++i) {
    GravityShot d{};
    for (float& v : d) v = u(rng) < 0.1f ? u(rng) : 0.0f;
    s.a.push_back(Normalized(d));
  }
  s.b_of_a.resize(static_cast<size_t>(n));
  std::iota(s.b_of_a.begin(), s.b_of_a.end(), 0u);
  std::shuffle(s.b_of_a.begin(), s.b_of_a.end(), rng);
  s.b.resize(static_cast<size_t>(n));
  for (size_t i = 0; i < s.a.size(); ++i) {
    GravityShot d = s.a[i];
    for (float& v : d) v = std::max(0.0f, v + noise * (u(rng) - 0.5f));
    s.b[s.b_of_a[i]] = Normalized(d);
  }
  return s;
}

TEST(CorrespondenceFinderTest, FindsTheTruePartnersAmongTheBestThree) {
  const Sets s = MakeSets(300, 0.02f, 3);
  const std::vector<KeypointCorrespondence> c = CorrespondenceFinder().Find(s.a, s.b);
  ASSERT_FALSE(c.empty());
  std::vector<int> per_a(s.a.size(), 0);
  int true_pairs = 0;
  for (size_t i = 0; i < c.size(); ++i) {
    ASSERT_LT(c[i].a, s.a.size());
    ASSERT_LT(c[i].b, s.b.size());
    EXPECT_LE(c[i].distance, 0.5f);
    EXPECT_NEAR(c[i].distance, GravityShotDescriptor::Distance(s.a[c[i].a], s.b[c[i].b]), 1e-3f);
    EXPECT_FLOAT_EQ(c[i].score, 1.0f - c[i].distance);
    if (i > 0) {
      EXPECT_TRUE(c[i - 1].a < c[i].a || (c[i - 1].a == c[i].a && c[i - 1].b < c[i].b))
          << "sorted, no duplicates";
    }
    ++per_a[c[i].a];
    if (s.b_of_a[c[i].a] == c[i].b) ++true_pairs;
  }
  EXPECT_EQ(true_pairs, 300);
  // At most three from each side: an a appears for its own three and for b's that chose it.
  EXPECT_LE(c.size(), 2u * 3u * 300u);
}

TEST(CorrespondenceFinderTest, ThresholdAndMutualChoice) {
  const Sets s = MakeSets(200, 0.02f, 5);
  CorrespondenceFinderOptions o;
  o.max_distance = 0.05;
  const std::vector<KeypointCorrespondence> tight = CorrespondenceFinder(o).Find(s.a, s.b);
  for (const KeypointCorrespondence& c : tight) EXPECT_LE(c.distance, 0.05f);
  o.max_distance = 0.5;
  const std::vector<KeypointCorrespondence> any = CorrespondenceFinder(o).Find(s.a, s.b);
  o.mutual_only = true;
  const std::vector<KeypointCorrespondence> mutual = CorrespondenceFinder(o).Find(s.a, s.b);
  EXPECT_LE(mutual.size(), any.size());
  int true_mutual = 0;
  for (const KeypointCorrespondence& c : mutual) {
    EXPECT_TRUE(std::any_of(any.begin(), any.end(),
                            [&](const KeypointCorrespondence& x) { return x.a == c.a && x.b == c.b; }));
    if (s.b_of_a[c.a] == c.b) ++true_mutual;
  }
  EXPECT_EQ(true_mutual, 200);
  o.matches_per_keypoint = 1;
  const std::vector<KeypointCorrespondence> one = CorrespondenceFinder(o).Find(s.a, s.b);
  EXPECT_EQ(one.size(), 200u);

  // Descriptors with disjoint bins are at distance 1: nothing passes 0.5.
  GravityShot x{}, y{};
  x[0] = 1.0f;
  y[1] = 1.0f;
  EXPECT_TRUE(CorrespondenceFinder().Find({x}, {y}).empty());
  EXPECT_TRUE(CorrespondenceFinder().Find({}, {y}).empty());
  EXPECT_TRUE(CorrespondenceFinder().Find({x}, {}).empty());
}

}  // namespace
}  // namespace cairn
