#include "drivers/replay/euroc_dataset.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "tests/support/scoped_temp_dir.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

namespace fs = std::filesystem;
using testing::CopyEurocDataset;
using testing::EurocMicro;

TEST(EurocDatasetTest, IndexesTheMicroExcerpt) {
  CAIRN_REQUIRE_PATH(EurocMicro());
  auto ds = EurocDataset::Open(EurocMicro());
  ASSERT_TRUE(ds.ok()) << ds.status().ToString();
  EXPECT_EQ(ds->imu().size(), 29120u);
  EXPECT_EQ(ds->stereo().size(), 95u);
  // cam1/data.csv lists four frames past the end of cam0 whose images are not in the excerpt.
  EXPECT_EQ(ds->unpaired_left(), 0);
  EXPECT_EQ(ds->unpaired_right(), 4);
  for (size_t i = 1; i < ds->imu().size(); ++i) ASSERT_LT(ds->imu()[i - 1].time, ds->imu()[i].time);
  for (size_t i = 1; i < ds->stereo().size(); ++i) ASSERT_LT(ds->stereo()[i - 1].time, ds->stereo()[i].time);
  EXPECT_EQ(ds->stereo().front().time.nanoseconds(), 1403715273262142976);
  // First IMU row: gyro then accel.
  EXPECT_NEAR(ds->imu().front().accel.x(), 9.0874956666666655, 1e-12);
  EXPECT_NEAR(ds->imu().front().gyro.z(), 0.07749261878854824, 1e-15);
  EXPECT_DOUBLE_EQ(ds->imu_calibration().gyro_noise_density, 1.6968e-04);
  EXPECT_DOUBLE_EQ(ds->imu_calibration().rate_hz, 200.0);
  const StereoCalibration& sc = ds->stereo_calibration();
  EXPECT_EQ(sc.left.intrinsics.width, 752);
  EXPECT_DOUBLE_EQ(sc.left.intrinsics.fx, 458.654);
  EXPECT_NEAR(sc.baseline(), 0.110, 0.002);  // the VI-Sensor's 11 cm baseline
  EXPECT_FALSE(ds->groundtruth_path().empty());
}

class BrokenEurocTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(EurocMicro())) GTEST_SKIP() << "missing " << EurocMicro();
    CopyEurocDataset(EurocMicro(), root_);
  }
  const testing::ScopedTempDir temp_{"euroc"};
  const std::string root_ = temp_.path();
};

TEST_F(BrokenEurocTest, MissingImageNamesTheFile) {
  const std::string img = root_ + "/mav0/cam1/data/1403715273912143104.png";
  ASSERT_TRUE(fs::remove(img));
  auto ds = EurocDataset::Open(root_);
  ASSERT_FALSE(ds.ok());
  EXPECT_EQ(ds.status().code(), StatusCode::kNotFound);
  EXPECT_NE(ds.status().message().find(img), std::string::npos) << ds.status().message();
}

TEST_F(BrokenEurocTest, TruncatedImuCsvNamesFileAndLine) {
  const std::string csv = root_ + "/mav0/imu0/data.csv";
  fs::resize_file(csv, fs::file_size(csv) / 2);
  auto ds = EurocDataset::Open(root_);
  ASSERT_FALSE(ds.ok());
  EXPECT_EQ(ds.status().code(), StatusCode::kDataLoss);
  EXPECT_NE(ds.status().message().find(csv + ":"), std::string::npos) << ds.status().message();
}

TEST_F(BrokenEurocTest, BadSensorYamlIsReported) {
  const std::string yaml = root_ + "/mav0/cam0/sensor.yaml";
  std::ofstream(yaml) << "T_BS: [unclosed\n";
  auto ds = EurocDataset::Open(root_);
  ASSERT_FALSE(ds.ok());
  EXPECT_NE(ds.status().message().find(yaml), std::string::npos) << ds.status().message();
}

TEST_F(BrokenEurocTest, NonOrthonormalExtrinsicsAreRejected) {
  const std::string yaml = root_ + "/mav0/imu0/sensor.yaml";
  std::ofstream(yaml) << "T_BS:\n  rows: 4\n  cols: 4\n  data: [2,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]\n"
                         "rate_hz: 200\ngyroscope_noise_density: 1\ngyroscope_random_walk: 1\n"
                         "accelerometer_noise_density: 1\naccelerometer_random_walk: 1\n";
  auto ds = EurocDataset::Open(root_);
  ASSERT_FALSE(ds.ok());
  EXPECT_NE(ds.status().message().find("orthonormal"), std::string::npos) << ds.status().message();
}

TEST(EurocDatasetOpenTest, FolderWithoutMav0IsNotADataset) {
  const testing::ScopedTempDir temp("euroc_empty");
  const std::string dir = temp.path();
  auto ds = EurocDataset::Open(dir);
  ASSERT_FALSE(ds.ok());
  EXPECT_NE(ds.status().message().find("no mav0/"), std::string::npos);
}

}  // namespace
}  // namespace cairn
