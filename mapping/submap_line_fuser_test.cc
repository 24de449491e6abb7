#include "mapping/submap_line_fuser.h"

#include <cmath>
#include <cstdio>
#include <random>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

namespace cairn {
namespace {

// A stereo-like endpoint error: long along the line of sight (grows with the range squared).
Eigen::Matrix3d FuserTestError(const Eigen::Vector3d& camera, const Eigen::Vector3d& p) {
  const Eigen::Vector3d z = (p - camera).normalized();
  const double range = (p - camera).norm();
  const double along = 0.02 * range * range / 25.0, across = 0.004 * range / 5.0;
  const Eigen::Vector3d x = z.unitOrthogonal(), y = z.cross(x);
  Eigen::Matrix3d R;
  R << x, y, z;
  return R * Eigen::Vector3d(across * across, across * across, along * along).asDiagonal() * R.transpose();
}

Eigen::Vector3d FuserTestDraw(const Eigen::Vector3d& mean, const Eigen::Matrix3d& cov, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Vector3d z(n(rng), n(rng), n(rng));
  return mean + cov.llt().matrixL() * z;
}

// Sightings of the segment a-b from cameras along x; each sees a random stretch of at least half.
// With `shared` > 0 both ends of a sighting also move together by an error of that sigma (m), as
// when one fit gives both.
std::vector<LineSighting> FuserTestSightings(const Eigen::Vector3d& a, const Eigen::Vector3d& b, int images,
                                             std::mt19937& rng, double shared = 0.0) {
  std::uniform_real_distribution<double> u(0.0, 0.25);
  std::vector<LineSighting> out;
  for (int k = 0; k < images; ++k) {
    LineSighting s;
    s.viewpoint = Eigen::Vector3d(0.1 * k, 0.0, 0.0);
    const Eigen::Vector3d ta = a + u(rng) * (b - a), tb = b - u(rng) * (b - a);
    s.cov_a = FuserTestError(s.viewpoint, ta);
    s.cov_b = FuserTestError(s.viewpoint, tb);
    s.a = FuserTestDraw(ta, s.cov_a, rng);
    s.b = FuserTestDraw(tb, s.cov_b, rng);
    if (shared > 0.0) {
      const Eigen::Matrix3d c = shared * shared * Eigen::Matrix3d::Identity();
      const Eigen::Vector3d common = FuserTestDraw(Eigen::Vector3d::Zero(), c, rng);
      s.a += common;
      s.b += common;
      s.cov_a += c;
      s.cov_b += c;
      s.cov_ab = c;
    }
    out.push_back(s);
  }
  return out;
}

// NEES of the estimated (n, v) against the truth (same anchor) under the rank-4 covariance.
double FuserTestNees(const SubmapLine& l, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  Eigen::Vector3d v = (b - a).normalized();
  if (v.dot(l.direction.cast<double>()) < 0.0) v = -v;
  const Eigen::Vector3d n = (a - l.anchor.cast<double>()).cross(v);
  Eigen::Matrix<double, 6, 1> e;
  e << l.moment.cast<double>() - n, l.direction.cast<double>() - v;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(l.covariance.cast<double>());
  double nees = 0.0;
  for (int i = 2; i < 6; ++i) {  // the four largest: a line has four degrees of freedom
    const double c = eig.eigenvectors().col(i).dot(e);
    nees += c * c / eig.eigenvalues()(i);
  }
  return nees;
}

class SubmapLineFuserConsistencyTest : public ::testing::TestWithParam<double> {};

TEST_P(SubmapLineFuserConsistencyTest, OneEdgeFromManyImagesIsConsistent) {
  const Eigen::Vector3d a(-1.0, 0.5, 5.0), b(1.5, 1.0, 6.0);
  std::mt19937 rng(7);
  constexpr int kRuns = 300;
  double sum = 0.0;
  int splits = 0;
  for (int run = 0; run < kRuns; ++run) {
    SubmapLineFuser fuser(LineFusionOptions{});
    for (const LineSighting& s : FuserTestSightings(a, b, 20, rng, GetParam())) ASSERT_TRUE(fuser.Add(s));
    const auto lines = fuser.Lines();
    ASSERT_FALSE(lines.empty()) << "run " << run;
    // The gate is 99.99 %: of the 19 joins per run a rare one fails and starts a second edge.
    splits += lines.size() > 1 || lines[0].sightings != 20u;
    sum += FuserTestNees(lines[0], a, b);
  }
  EXPECT_LE(splits, 3);
  // 95 % band of the mean of kRuns chi-square(4) draws (normal approximation of chi2(4 kRuns)).
  const double mean = sum / kRuns, half = 1.96 * std::sqrt(8.0 * kRuns) / kRuns;
  std::printf("mean NEES %.2f over %d runs (band %.2f to %.2f), %d split\n", mean, kRuns, 4.0 - half,
              4.0 + half, splits);
  EXPECT_GT(mean, 4.0 - half);
  EXPECT_LT(mean, 4.0 + half);
}

// Independent ends, and ends that share an error as large as their own.
INSTANTIATE_TEST_SUITE_P(Ends, SubmapLineFuserConsistencyTest, ::testing::Values(0.0, 0.01));

TEST(SubmapLineFuserTest, EndsExtendAndTheAnchorIsTheFirstViewpoint) {
  SubmapLineFuser fuser(LineFusionOptions{});
  const Eigen::Matrix3d cov = 1e-6 * Eigen::Matrix3d::Identity();
  LineSighting s;
  s.viewpoint = Eigen::Vector3d(0.0, -1.0, 0.0);
  s.a = Eigen::Vector3d(0.0, 0.0, 4.0);
  s.b = Eigen::Vector3d(1.0, 0.0, 4.0);
  s.cov_a = s.cov_b = cov;
  ASSERT_TRUE(fuser.Add(s));
  s.viewpoint = Eigen::Vector3d(0.5, -1.0, 0.0);
  s.a = Eigen::Vector3d(0.8, 0.0, 4.0);
  s.b = Eigen::Vector3d(2.5, 0.0, 4.0);
  ASSERT_TRUE(fuser.Add(s));
  const auto lines = fuser.Lines();
  ASSERT_EQ(lines.size(), 1u);
  const SubmapLine& l = lines[0];
  EXPECT_TRUE(l.anchor.isApprox(Eigen::Vector3f(0.0f, -1.0f, 0.0f)));
  EXPECT_NEAR(l.length(), 2.5f, 1e-4f);
  const Eigen::Vector3f lo = l.End(l.t_min), hi = l.End(l.t_max);
  EXPECT_NEAR(std::min(lo.x(), hi.x()), 0.0f, 1e-4f);
  EXPECT_NEAR(std::max(lo.x(), hi.x()), 2.5f, 1e-4f);
  EXPECT_NEAR(l.ClosestPoint().z(), 4.0f, 1e-4f);
  EXPECT_NEAR(l.moment.dot(l.direction), 0.0f, 1e-5f);
}

TEST(SubmapLineFuserTest, NeighbouringEdgesStayApart) {
  LineFusionOptions options;
  options.min_sightings = 1;
  SubmapLineFuser fuser(options);
  std::mt19937 rng(3);
  // Two parallel edges 0.3 m apart at 5 m (a crate's top and bottom), and one across them.
  const Eigen::Vector3d a(-1.0, 0.0, 5.0), b(1.0, 0.0, 5.0), up(0.0, 0.3, 0.0);
  for (int k = 0; k < 5; ++k) {
    for (const LineSighting& s : FuserTestSightings(a, b, 1, rng)) ASSERT_TRUE(fuser.Add(s));
    for (const LineSighting& s : FuserTestSightings(a + up, b + up, 1, rng)) ASSERT_TRUE(fuser.Add(s));
    for (const LineSighting& s : FuserTestSightings(a, a + up, 1, rng)) ASSERT_TRUE(fuser.Add(s));
  }
  EXPECT_EQ(fuser.edges(), 3u);
  // A second stretch of the first edge beyond a gap is another edge.
  LineSighting far;
  far.a = b + Eigen::Vector3d(1.0, 0.0, 0.0);
  far.b = b + Eigen::Vector3d(2.0, 0.0, 0.0);
  far.cov_a = FuserTestError(far.viewpoint, far.a);
  far.cov_b = FuserTestError(far.viewpoint, far.b);
  ASSERT_TRUE(fuser.Add(far));
  EXPECT_EQ(fuser.edges(), 4u);
}

TEST(SubmapLineFuserTest, RefusesBadSightingsAndKeepsItsBound) {
  LineFusionOptions options;
  options.max_lines = 2;
  SubmapLineFuser fuser(options);
  LineSighting s;
  s.a = Eigen::Vector3d(0.0, 0.0, 3.0);
  s.b = Eigen::Vector3d(NAN, 0.0, 3.0);
  EXPECT_FALSE(fuser.Add(s));
  s.b = s.a;
  EXPECT_FALSE(fuser.Add(s));
  for (int k = 0; k < 3; ++k) {
    s.a = Eigen::Vector3d(0.0, k, 3.0);
    s.b = Eigen::Vector3d(1.0, k, 3.0);
    s.cov_a = s.cov_b = 1e-4 * Eigen::Matrix3d::Identity();
    EXPECT_EQ(fuser.Add(s), k < 2) << k;
  }
  EXPECT_EQ(fuser.edges(), 2u);
  fuser.Reset();
  EXPECT_EQ(fuser.edges(), 0u);
  EXPECT_TRUE(fuser.Lines().empty());
}

}  // namespace
}  // namespace cairn
