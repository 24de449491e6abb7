#include "sim/imu_synthesizer.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "sim/analytic_trajectory.h"
#include "sim/sim_robot.h"

namespace cairn::sim {
namespace {

struct NavState {
  Eigen::Quaterniond q;
  Eigen::Vector3d v, p;
};

struct NavRate {
  Eigen::Quaterniond dq;
  Eigen::Vector3d dv, dp;
};

NavRate Derivative(const NavState& s, const ImuSample& m) {
  NavRate r;
  const Eigen::Quaterniond w(0, m.gyro.x(), m.gyro.y(), m.gyro.z());
  r.dq.coeffs() = 0.5 * (s.q * w).coeffs();
  r.dv = s.q.toRotationMatrix() * m.accel - Eigen::Vector3d(0, 0, kGravity);
  r.dp = s.v;
  return r;
}

NavState Step(const NavState& s, const NavRate& r, double h) {
  NavState o;
  o.q.coeffs() = s.q.coeffs() + h * r.dq.coeffs();
  o.v = s.v + h * r.dv;
  o.p = s.p + h * r.dp;
  return o;
}

// Classical RK4 over two IMU intervals (start, middle and end samples), from the true initial
// state; returns the largest position error against ground truth.
double IntegrationError(const std::vector<ImuTruth>& imu) {
  NavState s{Eigen::Quaterniond(imu[0].state.T_world_body.linear()), imu[0].state.velocity,
             imu[0].state.T_world_body.translation()};
  double worst = 0.0;
  for (size_t k = 0; k + 2 < imu.size(); k += 2) {
    const double h = (imu[k + 2].sample.time - imu[k].sample.time).seconds();
    const NavRate k1 = Derivative(s, imu[k].sample);
    const NavRate k2 = Derivative(Step(s, k1, h / 2), imu[k + 1].sample);
    const NavRate k3 = Derivative(Step(s, k2, h / 2), imu[k + 1].sample);
    const NavRate k4 = Derivative(Step(s, k3, h), imu[k + 2].sample);
    s.q.coeffs() += h / 6 * (k1.dq.coeffs() + 2 * k2.dq.coeffs() + 2 * k3.dq.coeffs() + k4.dq.coeffs());
    s.q.normalize();
    s.v += h / 6 * (k1.dv + 2 * k2.dv + 2 * k3.dv + k4.dv);
    s.p += h / 6 * (k1.dp + 2 * k2.dp + 2 * k3.dp + k4.dp);
    worst = std::max(worst, (s.p - imu[k + 2].state.T_world_body.translation()).norm());
  }
  return worst;
}

Terrain TestTerrain() {
  WorldOptions w;
  w.size = 30.0;
  w.resolution = 0.2;
  w.lander.clear();
  return Terrain::Generate(w);
}

// Integrates the noise-free IMU of a robot over 10 s; returns the sample count and the error.
std::pair<size_t, double> NoiseFreeDrift(const SimRobot& robot) {
  ImuSynthesizer imu(robot.imu, 1, /*noise=*/false);
  const auto samples = imu.Generate(robot.trajectory, Timestamp::FromSeconds(1.0), 10.0);
  return {samples.size(), IntegrationError(samples)};
}

TEST(ImuSynthesizerTest, NoiseFreeRoverImuIntegratesToGroundTruthWithin1mmOver10s) {
  const auto [count, error] = NoiseFreeDrift(MakeRover(TestTerrain(), "rover", 0, 5, 10.0, 0.1, 0.16));
  EXPECT_EQ(count, 2001u);
  EXPECT_LT(error, 1e-3);
}

TEST(ImuSynthesizerTest, NoiseFreeHexacopterImuIntegratesToGroundTruthWithin1mmOver10s) {
  const auto [count, error] = NoiseFreeDrift(MakeHexacopter(TestTerrain(), "hexacopter", 1, 5, 10.0, 0.1, 0.16));
  EXPECT_EQ(count, 4001u);
  EXPECT_LT(error, 1e-3);
}

// The filter tests' analytic trajectory, streamed through the same sensor model.
TEST(ImuSynthesizerTest, NoiseFreeAnalyticTrajectoryImuIntegratesToGroundTruthWithin1mmOver10s) {
  ImuSynthesizer imu(ImuCalibration{}, 1, /*noise=*/false);
  const AnalyticTrajectory trajectory;
  std::vector<ImuTruth> samples;
  for (int64_t k = 0; k <= 2000; ++k) {  // 200 Hz
    samples.push_back(imu.Sample(Timestamp::FromSeconds(1.0) + Duration::Nanoseconds(k * 5000000),
                                 trajectory.Evaluate(static_cast<double>(k) * 0.005)));
  }
  EXPECT_LT(IntegrationError(samples), 1e-3);
}

// Streaming gives what Generate gives, and biases set by hand are the ones the readings carry.
TEST(ImuSynthesizerTest, StreamedSamplesAreTheGeneratedOnes) {
  const Terrain terrain = TestTerrain();
  const SimRobot rover = MakeRover(terrain, "rover", 0, 5, 10.0, 0.1, 0.16);
  const Timestamp start = Timestamp::FromSeconds(1.0);
  ImuSynthesizer batch(rover.imu, 4), stream(rover.imu, 4);
  const std::vector<ImuTruth> generated = batch.Generate(rover.trajectory, start, 1.0);
  for (const ImuTruth& g : generated) {
    const double t = (g.sample.time - start).seconds();
    const ImuTruth s = stream.Sample(g.sample.time, rover.trajectory.Evaluate(t));
    ASSERT_EQ(s.sample.accel, g.sample.accel);
    ASSERT_EQ(s.sample.gyro, g.sample.gyro);
    ASSERT_EQ(s.gyro_bias, g.gyro_bias);
  }

  ImuSynthesizer exact(rover.imu, 4, /*noise=*/false);
  const Eigen::Vector3d bg(0.01, -0.02, 0.03), ba(0.1, 0.2, -0.3);
  exact.SetBiases(bg, ba);
  for (int k = 0; k < 3; ++k) {
    const TrajectoryState state = rover.trajectory.Evaluate(0.5 * k);
    const ImuTruth s = exact.Sample(start, state);
    Eigen::Vector3d a, g;
    ImuSynthesizer::Exact(state, &a, &g);
    EXPECT_EQ(s.sample.gyro, g + bg);
    EXPECT_EQ(s.sample.accel, a + ba);
    EXPECT_EQ(s.gyro_bias, bg);
  }
}

TEST(ImuSynthesizerTest, NoiseHasTheCalibratedDiscreteSigma) {
  const Terrain terrain = TestTerrain();
  const SimRobot rover = MakeRover(terrain, "rover", 0, 5, 10.0, 0.1, 0.16);
  ImuSynthesizer noisy(rover.imu, 9, true);
  const auto samples = noisy.Generate(rover.trajectory, Timestamp::FromSeconds(1.0), 10.0);
  double sg = 0.0, sa = 0.0;
  for (const ImuTruth& s : samples) {
    Eigen::Vector3d a, g;
    ImuSynthesizer::Exact(s.state, &a, &g);
    sg += (s.sample.gyro - g - s.gyro_bias).squaredNorm();
    sa += (s.sample.accel - a - s.accel_bias).squaredNorm();
  }
  const double n = 3.0 * static_cast<double>(samples.size());
  const double rate = rover.imu.rate_hz;
  EXPECT_NEAR(std::sqrt(sg / n), rover.imu.gyro_noise_density * std::sqrt(rate), 0.05 * rover.imu.gyro_noise_density * std::sqrt(rate));
  EXPECT_NEAR(std::sqrt(sa / n), rover.imu.accel_noise_density * std::sqrt(rate), 0.05 * rover.imu.accel_noise_density * std::sqrt(rate));
  EXPECT_NE(samples.back().gyro_bias, samples.front().gyro_bias);  // the bias walks
}

}  // namespace
}  // namespace cairn::sim
