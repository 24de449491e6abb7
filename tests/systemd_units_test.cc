// The shipped systemd units pass `systemd-analyze verify` (where systemd-analyze exists), with
// ExecStart pointed at the binary of this build.

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/support/process_runner.h"
#include "tests/support/scoped_temp_dir.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

namespace fs = std::filesystem;

std::string Read(const std::string& p) {
  std::stringstream s;
  s << std::ifstream(p).rdbuf();
  return s.str();
}

const char kAnalyze[] = "/usr/bin/systemd-analyze";

// Writes both units to `dir` with ExecStart pointed at this build's cairnd; returns their paths
// (the template as the instance cairnd@rover.service).
std::vector<std::string> WriteUnits(const std::string& dir) {
  const std::string cairnd = testing::BinaryDir() + "/daemon/cairnd";
  std::vector<std::string> paths;
  for (const std::string unit : {"cairnd.service", "cairnd@.service"}) {
    std::string text = Read(testing::BinaryDir() + "/systemd/" + unit);
    EXPECT_FALSE(text.empty()) << unit;
    // Units must not be left with unexpanded configure variables.
    EXPECT_EQ(text.find('@' + std::string("CMAKE")), std::string::npos) << unit;
    const size_t exec = text.find("ExecStart=");
    EXPECT_NE(exec, std::string::npos) << unit;
    if (exec == std::string::npos) continue;
    const size_t binary_end = text.find(' ', exec);
    text.replace(exec, binary_end - exec, "ExecStart=" + cairnd);
    const std::string name = unit == "cairnd@.service" ? "cairnd@rover.service" : unit;
    std::ofstream(dir + "/" + name) << text;
    for (const char* key : {"Type=notify", "WatchdogSec=", "Restart=on-failure", "LimitRTPRIO=",
                            "LimitMEMLOCK=", "ProtectSystem=strict", "PrivateTmp=yes",
                            "NoNewPrivileges=yes", "CapabilityBoundingSet=", "ReadWritePaths=/var/lib/cairn",
                            "User=cairn", "SystemCallFilter=@system-service", "DevicePolicy=closed"}) {
      EXPECT_NE(text.find(key), std::string::npos) << unit << " lacks " << key;
    }
    paths.push_back(dir + "/" + name);
  }
  return paths;
}

TEST(SystemdUnitsTest, UnitsVerify) {
  if (!fs::exists(kAnalyze)) GTEST_SKIP() << "missing " << kAnalyze;
  const testing::ScopedTempDir temp("units");
  const std::vector<std::string> units = WriteUnits(temp.path());
  ASSERT_EQ(units.size(), 2u);
  const auto r = testing::RunProcess({kAnalyze, "verify", "--man=no", units[0], units[1]});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  // Warnings about our units (not about unrelated system units) count as failures too.
  EXPECT_EQ(r.output.find("cairnd"), std::string::npos) << r.output;
}

// systemd's own exposure score (0 = locked down, 10 = unprotected) of each unit is at most 2.0,
// systemd's "OK", while the daemon keeps what the real-time thread and the devices need.
TEST(SystemdUnitsTest, SecurityExposureIsAtMostTwo) {
  if (!fs::exists(kAnalyze)) GTEST_SKIP() << "missing " << kAnalyze;
  const testing::ScopedTempDir temp("units");
  for (const std::string& unit : WriteUnits(temp.path())) {
    SCOPED_TRACE(unit);
    const auto r = testing::RunProcess({kAnalyze, "security", "--offline=true", "--no-pager", unit});
    const std::string marker = "Overall exposure level for ";
    const size_t at = r.output.find(marker);
    ASSERT_NE(at, std::string::npos) << r.output;
    const size_t colon = r.output.find(": ", at);
    ASSERT_NE(colon, std::string::npos) << r.output;
    const double exposure = std::stod(r.output.substr(colon + 2));
    EXPECT_LE(exposure, 2.0) << r.output;
  }
}

TEST(SystemdUnitsTest, SysusersAndTmpfilesDeclareTheStateFolder) {
  const std::string src = testing::SourceDir() + "/systemd/";
  EXPECT_NE(Read(src + "cairn.sysusers.conf").find("u cairn "), std::string::npos);
  EXPECT_NE(Read(src + "cairn.tmpfiles.conf").find("d /var/lib/cairn 0750 cairn cairn"), std::string::npos);
}

// `systemctl stop` waits TimeoutStopSec before it kills: a stopped team robot's linger
// (team.stop_linger of every shipped profile) must leave it time to write its outputs.
TEST(SystemdUnitsTest, TheStopTimeoutOutlastsTheTeamsLingerAfterAStop) {
  const double kWriteSeconds = 15.0;
  const std::regex timeout_line(R"(\nTimeoutStopSec=([0-9]+)s\n)");
  const std::regex linger_line(R"(\n  stop_linger: ([0-9.e+]+))");
  for (const std::string unit : {"cairnd.service.in", "cairnd@.service.in"}) {
    const std::string text = Read(testing::SourceDir() + "/systemd/" + unit);
    std::smatch timeout;
    ASSERT_TRUE(std::regex_search(text, timeout, timeout_line)) << unit;
    for (const std::string profile : {"rover", "hexacopter", "euroc"}) {
      const std::string config = Read(testing::SourceDir() + "/configs/" + profile + ".yaml");
      std::smatch linger;
      ASSERT_TRUE(std::regex_search(config, linger, linger_line)) << profile;
      EXPECT_GE(std::stod(timeout[1].str()) - std::stod(linger[1].str()), kWriteSeconds)
          << unit << ", " << profile;
    }
  }
}

}  // namespace
}  // namespace cairn
