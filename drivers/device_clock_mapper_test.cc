#include "drivers/device_clock_mapper.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace cairn {
namespace {

// A 100 Hz device whose clock runs 50 ppm fast and 3.2 s behind the host's, its samples arriving
// after 0.5 ms plus an exponential delay of mean 2 ms (a USB serial adapter's).
TEST(DeviceClockMapperTest, RecoversOffsetAndDriftWithinAMillisecondOfTheTruth) {
  std::mt19937_64 rng(5);
  std::exponential_distribution<double> delay(1.0 / 0.002);
  DeviceClockMapper mapper;
  double worst_late = 0.0, worst_arrival_error = 0.0;
  for (int i = 0; i < 6000; ++i) {
    const double host_truth = 3.2 + i * 0.01;             // s, when the sample was taken
    const double device = (host_truth - 3.2) * (1.0 + 50e-6);  // its clock
    const double arrival = host_truth + 0.0005 + delay(rng);
    const Timestamp mapped = mapper.Map(std::llround(device * 1e9), Timestamp::FromSeconds(arrival));
    EXPECT_LE(mapped.nanoseconds(), Timestamp::FromSeconds(arrival).nanoseconds());
    if (i >= 1000) {
      worst_late = std::max(worst_late, std::abs(mapped.seconds() - (host_truth + 0.0005)));
      worst_arrival_error = std::max(worst_arrival_error, std::abs(arrival - host_truth));
    }
  }
  std::printf("mapped within %.3f ms of the truth (+ the fixed 0.5 ms); arrival times up to %.1f ms; drift %.1f ppm\n",
              worst_late * 1e3, worst_arrival_error * 1e3, mapper.drift_ppm());
  EXPECT_LT(worst_late, 0.001);
  EXPECT_GT(worst_arrival_error, 0.010);  // what taking the arrival time would have cost
  EXPECT_NEAR(mapper.drift_ppm(), -50.0, 10.0);
  EXPECT_EQ(mapper.restarts(), 0);
}

TEST(DeviceClockMapperTest, ADeviceResetStartsAgain) {
  DeviceClockMapper mapper;
  for (int i = 0; i < 300; ++i) mapper.Map(int64_t{i} * 10'000'000, Timestamp::FromSeconds(10.0 + i * 0.01));
  // The device restarts its clock at 0; the host goes on.
  const Timestamp t = mapper.Map(0, Timestamp::FromSeconds(13.5));
  EXPECT_EQ(mapper.restarts(), 1);
  EXPECT_NEAR(t.seconds(), 13.5, 1e-6);
}

}  // namespace
}  // namespace cairn
