#include "mapping/matching/line_associator.h"

#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "estimation/math/ordered_draws.h"
#include "estimation/math/tangent_axes.h"
#include "mapping/matching/testing/every_line_pairing.h"
#include "mapping/matching/testing/placements.h"
#include "mapping/testing/submap_edges.h"

namespace cairn {
namespace {

LineAssociationOptions LineAssocNoFloors() {
  LineAssociationOptions o;
  o.min_direction_sigma = o.min_offset_sigma = 0.0;
  return o;
}

struct LineAssocWorld {
  Eigen::Isometry3d a = testing::YawedPose(0.0, 0.0, 0.0), b = testing::YawedPose(4.0, 1.0, 0.6);
  // A crate's vertical and top edges, a wall's top, a sloped ridge.
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> edges = {
      {Eigen::Vector3d(6, 2, 0), Eigen::Vector3d(6, 2, 1.2)},
      {Eigen::Vector3d(6, 2, 1.2), Eigen::Vector3d(6, 4, 1.2)},
      {Eigen::Vector3d(-2, 8, 2), Eigen::Vector3d(5, 9, 2)},
      {Eigen::Vector3d(1, -4, 0.5), Eigen::Vector3d(4, -5, 2)}};
  // B sees every other edge the other way round.
  std::vector<SubmapLine> Seen(const Eigen::Isometry3d& T, bool reversed) const {
    std::vector<SubmapLine> out;
    for (size_t k = 0; k < edges.size(); ++k) {
      const bool flip = reversed && k % 2 == 1;
      out.push_back(testing::EdgeSeenFrom(T, flip ? edges[k].second : edges[k].first,
                                          flip ? edges[k].first : edges[k].second));
    }
    return out;
  }
};

TEST(LineAssociatorTest, PairsTheSameEdgesSeenFromTwoSubmaps) {
  const LineAssocWorld w;
  const LineAssociator associator{LineAssociationOptions{}};
  // B's origin off by 0.2 m and 1 deg in the graph, with a covariance that covers it.
  const Eigen::Isometry3d b_estimate = testing::YawedPose(4.2, 0.9, 0.6 + 0.017);
  const auto pairs = associator.Associate(w.Seen(w.a, false), testing::PlacedWithSigma(w.a, 0.01, 0.001),
                                          w.Seen(w.b, true), testing::PlacedWithSigma(b_estimate, 0.3, 0.03));
  ASSERT_EQ(pairs.size(), w.edges.size());
  for (size_t k = 0; k < pairs.size(); ++k) {
    EXPECT_EQ(pairs[k].a, static_cast<int>(k));
    EXPECT_EQ(pairs[k].b, static_cast<int>(k));
    EXPECT_LT(pairs[k].chi2, 4.0);
  }
  // With the exact origins, the distance of an edge to itself (either way round) is nil.
  const SubmapLine la = testing::EdgeSeenFrom(w.a, w.edges[2].first, w.edges[2].second);
  const SubmapLine lb = testing::EdgeSeenFrom(w.b, w.edges[2].second, w.edges[2].first);
  EXPECT_LT(associator.Distance(la, testing::PlacedWithSigma(w.a, 0.01, 0.001), lb,
                                testing::PlacedWithSigma(w.b, 0.01, 0.001)),
            1e-6);
}

TEST(LineAssociatorTest, RefusesAParallelEdgeNearby) {
  const Eigen::Isometry3d a = testing::YawedPose(0, 0, 0), b = testing::YawedPose(2, -1, 0.3);
  const Eigen::Vector3d p(5, 0, 1), q(5, 3, 1), shift(0.3, 0, 0);
  const LineAssociator associator{LineAssociationOptions{}};
  const std::vector<SubmapLine> la = {testing::EdgeSeenFrom(a, p, q)};
  const std::vector<SubmapLine> lb = {testing::EdgeSeenFrom(b, p + shift, q + shift)};
  const SubmapPlacement pa = testing::PlacedWithSigma(a, 0.01, 0.001),
                        pb = testing::PlacedWithSigma(b, 0.01, 0.001);
  EXPECT_GT(associator.Distance(la[0], pa, lb[0], pb), 50.0);
  EXPECT_TRUE(associator.Associate(la, pa, lb, pb).empty());
}

TEST(LineAssociatorTest, LeavesParallelNeighboursOutWhenTheEstimateCannotTellThem) {
  // Two edges 0.3 m apart (a step's two nosings); B's origin is known to 0.5 m only.
  const Eigen::Isometry3d a = testing::YawedPose(0, 0, 0), b = testing::YawedPose(2, 0, 0);
  const Eigen::Vector3d p(5, -1, 1), q(5, 2, 1), step(0.3, 0, 0.2);
  const std::vector<SubmapLine> la = {testing::EdgeSeenFrom(a, p, q),
                                      testing::EdgeSeenFrom(a, p + step, q + step)};
  const std::vector<SubmapLine> lb = {testing::EdgeSeenFrom(b, p, q),
                                      testing::EdgeSeenFrom(b, p + step, q + step)};
  const LineAssociator associator{LineAssociationOptions{}};
  EXPECT_TRUE(
      associator
          .Associate(la, testing::PlacedWithSigma(a, 0.01, 0.001), lb, testing::PlacedWithSigma(b, 0.5, 0.01))
          .empty());
  // Known to 2 cm, each finds its own.
  const auto pairs = associator.Associate(la, testing::PlacedWithSigma(a, 0.01, 0.001), lb,
                                          testing::PlacedWithSigma(b, 0.02, 0.001));
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0].a, 0);
  EXPECT_EQ(pairs[0].b, 0);
  EXPECT_EQ(pairs[1].a, 1);
  EXPECT_EQ(pairs[1].b, 1);
}

TEST(LineAssociatorTest, RefusesStretchesOfALineFarApart) {
  const Eigen::Isometry3d a = testing::YawedPose(0, 0, 0), b = testing::YawedPose(3, 8, 0.2);
  const Eigen::Vector3d along(0, 1, 0), p(5, 0, 1);
  const LineAssociator associator{LineAssociationOptions{}};
  const SubmapPlacement pa = testing::PlacedWithSigma(a, 0.01, 0.001),
                        pb = testing::PlacedWithSigma(b, 0.01, 0.001);
  const SubmapLine la = testing::EdgeSeenFrom(a, p, p + 3.0 * along);
  // 1 m of gap: beyond the 0.5 m margin; 0.3 m: within it.
  EXPECT_LT(associator.Distance(la, pa, testing::EdgeSeenFrom(b, p + 4.0 * along, p + 7.0 * along), pb), 0.0);
  EXPECT_LT(associator.Distance(la, pa, testing::EdgeSeenFrom(b, p - 1.0 * along, p - 4.0 * along), pb), 0.0);
  const double near =
      associator.Distance(la, pa, testing::EdgeSeenFrom(b, p + 3.3 * along, p + 6.0 * along), pb);
  EXPECT_GE(near, 0.0);
  EXPECT_LT(near, 1.0);
}

TEST(LineAssociatorTest, OnlyLongAndRepeatedlySeenEdgesAreEligible) {
  const Eigen::Isometry3d a = testing::YawedPose(0, 0, 0);
  const LineAssociator associator{LineAssociationOptions{}};
  const SubmapLine good = testing::EdgeSeenFrom(a, Eigen::Vector3d(4, 0, 0), Eigen::Vector3d(4, 1.5, 0));
  EXPECT_TRUE(associator.Eligible(good));
  EXPECT_FALSE(
      associator.Eligible(testing::EdgeSeenFrom(a, Eigen::Vector3d(4, 0, 0), Eigen::Vector3d(4, 0.8, 0))));
  SubmapLine rare = good;
  rare.sightings = 2;
  EXPECT_FALSE(associator.Eligible(rare));
  SubmapLine broken = good;
  broken.covariance(2, 2) = std::nanf("");
  EXPECT_FALSE(associator.Eligible(broken));
  broken = good;
  broken.moment.x() = INFINITY;
  EXPECT_FALSE(associator.Eligible(broken));
  // Never paired, however well they agree.
  const std::vector<SubmapLine> rares = {rare};
  EXPECT_TRUE(associator
                  .Associate(rares, testing::PlacedWithSigma(a, 0.01, 0.001), rares,
                             testing::PlacedWithSigma(a, 0.01, 0.001))
                  .empty());
}

TEST(LineAssociatorTest, CovarianceIsTheErrorsOfThePerturbedLine) {
  const LineAssociator associator(LineAssocNoFloors());
  // The helper's (n, v) covariance gives e exactly its stated sigmas at the middle.
  const Eigen::Isometry3d T = testing::YawedPose(1.0, -2.0, 0.7);
  const Eigen::Vector3d a_w(4, 3, 0.5), b_w(6, 5.5, 1.7);
  const SubmapLine l = testing::EdgeSeenFrom(T, a_w, b_w, 0.004, 0.03);
  const Eigen::Vector4d stated(0.004 * 0.004, 0.004 * 0.004, 0.03 * 0.03, 0.03 * 0.03);
  EXPECT_LT((associator.Covariance(l) - Eigen::Matrix4d(stated.asDiagonal())).norm(), 1e-8);

  // The closed-form Jacobian against central differences of the actual line through moved ends:
  // a rank-one (n, v) covariance dx dx^T must give de de^T.
  const Eigen::Vector3d anchor = l.anchor.cast<double>(), c = LineAssociator::Middle(l);
  const Eigen::Vector3d a = T.inverse() * a_w, b = T.inverse() * b_w;
  Eigen::Vector3d u, w;
  TangentAxes(Eigen::Vector3d(l.direction.cast<double>()), &u, &w);
  auto line = [&](const Eigen::Vector3d& pa, const Eigen::Vector3d& pb, Eigen::Matrix<double, 6, 1>* x) {
    const Eigen::Vector3d v = (pb - pa).normalized(), n = (pa - anchor).cross(v);
    *x << n, v;
    const Eigen::Vector3d p0 = anchor + v.cross(n);
    const Eigen::Vector3d off = p0 + (c - p0).dot(v) * v - c;
    return Eigen::Vector4d(u.dot(v), w.dot(v), u.dot(off), w.dot(off));
  };
  std::mt19937 rng(3);
  std::normal_distribution<double> n01(0.0, 1.0);
  constexpr double h = 1e-5;
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Vector3d da = DrawVector3(n01, rng), db = DrawVector3(n01, rng);
    Eigen::Matrix<double, 6, 1> xp, xm;
    const Eigen::Vector4d ep = line(a + h * da, b + h * db, &xp), em = line(a - h * da, b - h * db, &xm);
    const Eigen::Matrix<double, 6, 1> dx = (xp - xm) / (2 * h);
    const Eigen::Vector4d de = (ep - em) / (2 * h);
    SubmapLine moved = l;
    moved.covariance = (dx * dx.transpose()).cast<float>();
    const Eigen::Matrix4d expected = de * de.transpose();
    EXPECT_LT((associator.Covariance(moved) - expected).norm(), 1e-5 * expected.norm()) << "trial " << trial;
  }
}

// Monte Carlo: both submaps see the same edge (different stretches of it) with errors drawn from
// their stated covariances, and both origins are off by draws from theirs; the distance of the true
// pairing is then a chi2(4) draw.
TEST(LineAssociatorTest, DistanceOfTruePairsFollowsTheStatedNoise) {
  const LineAssociator associator(LineAssocNoFloors());
  const Eigen::Isometry3d a = testing::YawedPose(0, 0, 0), b = testing::YawedPose(3, 2, 0.8);
  const Eigen::Vector3d p(6, -1, 0.5), along = Eigen::Vector3d(0.2, 1.0, 0.3).normalized();
  const double sigma_r = 0.005, sigma_t = 0.01;
  const Eigen::Matrix<double, 6, 1> origin_sigma =
      (Eigen::Matrix<double, 6, 1>() << 0.01, 0.01, 0.01, 0.001, 0.001, 0.001).finished();
  std::mt19937 rng(5);
  std::normal_distribution<double> n01(0.0, 1.0);
  auto draw4 = [&](double r, double t) {
    Eigen::Vector4d e;
    e.head<2>() = r * DrawVector2(n01, rng);
    e.tail<2>() = t * DrawVector2(n01, rng);
    return e;
  };
  auto placed = [&](const Eigen::Isometry3d& T) {
    Eigen::Matrix<double, 6, 1> d;
    d.head<3>() = DrawVector3(n01, rng);
    d.tail<3>() = DrawVector3(n01, rng);
    d = d.cwiseProduct(origin_sigma);
    SubmapPlacement s = testing::PlacedWithSigma(T, origin_sigma[0], origin_sigma[3]);
    s.T_world_submap = PerturbedOrigin(T, d);
    return s;
  };
  const int draws = 200;
  double mean = 0.0;
  for (int k = 0; k < draws; ++k) {
    const SubmapLine la =
        testing::EdgeSeenFrom(a, p, p + 3.0 * along, sigma_r, sigma_t, draw4(sigma_r, sigma_t));
    const SubmapLine lb =
        testing::EdgeSeenFrom(b, p + 4.5 * along, p + 1.0 * along, sigma_r, sigma_t, draw4(sigma_r, sigma_t));
    const SubmapPlacement pa = placed(a);
    const SubmapPlacement pb = placed(b);
    const double chi2 = associator.Distance(la, pa, lb, pb);
    ASSERT_GE(chi2, 0.0);
    mean += chi2 / draws;
  }
  std::printf("[ lines] mean chi2 of true pairings over %d draws: %.2f (4 degrees of freedom)\n", draws,
              mean);
  EXPECT_GT(mean, 3.3);
  EXPECT_LT(mean, 4.7);
}

// Random edges of a random world seen from two random origins, with correlated origin covariances
// from millimetres to half a metre: both the pairings of the same edge and those of unrelated ones.
struct LineBoundDraws {
  std::mt19937 rng{11};
  std::normal_distribution<double> n01{0.0, 1.0};
  std::uniform_real_distribution<double> u01{0.0, 1.0};

  double LogUniform(double lo, double hi) { return lo * std::pow(hi / lo, u01(rng)); }
  Eigen::Isometry3d Pose() {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = so3::Exp(Eigen::Vector3d(0.05 * n01(rng), 0.05 * n01(rng), 3.0 * n01(rng)));
    T.translation() = Eigen::Vector3d(15.0 * n01(rng), 15.0 * n01(rng), n01(rng));
    return T;
  }
  SubmapPlacement Placed(const Eigen::Isometry3d& T) {
    Eigen::Matrix<double, 6, 6> L;
    for (int i = 0; i < 36; ++i) L(i / 6, i % 6) = n01(rng);
    Eigen::Matrix<double, 6, 1> sigma;
    sigma.head<3>().setConstant(LogUniform(0.001, 0.5));
    sigma.tail<3>().setConstant(LogUniform(0.0005, 0.05));
    SubmapPlacement s;
    s.T_world_submap = T;
    s.covariance = sigma.asDiagonal() * (L * L.transpose() / 6.0) * sigma.asDiagonal();
    return s;
  }
  std::pair<Eigen::Vector3d, Eigen::Vector3d> Edge() {
    const Eigen::Vector3d p(20.0 * n01(rng), 20.0 * n01(rng), 2.0 * n01(rng));
    // Half the edges along the world's axes, as a structured world's are: many parallel ones.
    Eigen::Vector3d d = u01(rng) < 0.5 ? Eigen::Vector3d::Unit(static_cast<int>(3.0 * u01(rng)) % 3)
                                       : Eigen::Vector3d(n01(rng), n01(rng), n01(rng)).normalized();
    return {p, p + (1.0 + 5.0 * u01(rng)) * d};
  }
  Eigen::Vector4d Error(double sigma_r, double sigma_t) {
    return Eigen::Vector4d(sigma_r * n01(rng), sigma_r * n01(rng), sigma_t * n01(rng), sigma_t * n01(rng));
  }
};

TEST(LineAssociatorTest, LowerBoundNeverExceedsTheDistance) {
  const LineAssociator associator{LineAssociationOptions{}};
  const double reach = LineAssociationOptions{}.gate_chi2 + LineAssociationOptions{}.ambiguity_chi2;
  LineBoundDraws d;
  int compared = 0, beyond = 0, near = 0;
  for (int k = 0; k < 4000; ++k) {
    const Eigen::Isometry3d a = d.Pose(), b = d.Pose();
    const auto ea = d.Edge();
    // Every other draw pairs an edge with itself, seen with errors and a stretch of its own.
    const bool same = k % 2 == 0;
    const auto eb = same ? std::make_pair(ea.first + 0.3 * (ea.second - ea.first), ea.second) : d.Edge();
    const double ra = d.LogUniform(0.001, 0.05), ta = d.LogUniform(0.005, 0.2);
    const double rb = d.LogUniform(0.001, 0.05), tb = d.LogUniform(0.005, 0.2);
    const SubmapLine la = testing::EdgeSeenFrom(a, ea.first, ea.second, ra, ta, d.Error(ra, ta));
    const SubmapLine lb = testing::EdgeSeenFrom(b, eb.second, eb.first, rb, tb, d.Error(rb, tb));
    // Every third draw the graph places B far from where it is.
    const SubmapPlacement pa = d.Placed(a), pb = d.Placed(k % 3 == 0 ? d.Pose() : b);
    const double chi2 = associator.Distance(la, pa, lb, pb);
    if (chi2 < 0.0) continue;
    ++compared;
    const double bound = associator.LowerBound(la, pa, lb, pb);
    ASSERT_LE(bound, chi2) << "draw " << k;
    beyond += bound > reach;
    near += chi2 <= reach;
  }
  std::printf("[ lines] %d pairings compared: %d within reach, %d put beyond it by the bound alone\n",
              compared, near, beyond);
  // The bound must also be of use: most of the pairings out of reach are found by it.
  EXPECT_GT(compared, 1000);
  EXPECT_GT(beyond, (compared - near) / 2);
}

TEST(LineAssociatorTest, DecidesAsTheSearchOfEveryPairing) {
  const LineAssociationOptions options;
  const LineAssociator associator(options);
  LineBoundDraws d;
  int paired = 0;
  for (int k = 0; k < 20; ++k) {
    const Eigen::Isometry3d a = d.Pose();
    const Eigen::Isometry3d b = a * testing::YawedPose(3.0 * d.n01(d.rng), 3.0 * d.n01(d.rng), d.n01(d.rng));
    std::vector<SubmapLine> la, lb;
    for (int e = 0; e < 40; ++e) {
      const auto edge = d.Edge();
      const double r = d.LogUniform(0.001, 0.02), t = d.LogUniform(0.005, 0.05);
      la.push_back(testing::EdgeSeenFrom(a, edge.first, edge.second, r, t, d.Error(r, t)));
      if (e % 2 == 0) lb.push_back(testing::EdgeSeenFrom(b, edge.second, edge.first, r, t, d.Error(r, t)));
    }
    const SubmapPlacement pa = testing::PlacedWithSigma(a, 0.05, 0.005);
    const SubmapPlacement pb =
        testing::PlacedWithSigma(b, d.LogUniform(0.01, 0.5), d.LogUniform(0.001, 0.05));
    const auto expected = testing::EveryLinePairing(associator, options, la, pa, lb, pb);
    const auto pairs = associator.Associate(la, pa, lb, pb);
    ASSERT_EQ(pairs.size(), expected.size()) << "world " << k;
    for (size_t i = 0; i < pairs.size(); ++i) {
      EXPECT_EQ(pairs[i].a, expected[i].a);
      EXPECT_EQ(pairs[i].b, expected[i].b);
      EXPECT_DOUBLE_EQ(pairs[i].chi2, expected[i].chi2);
    }
    paired += static_cast<int>(pairs.size());
  }
  EXPECT_GT(paired, 100);
}

}  // namespace
}  // namespace cairn
