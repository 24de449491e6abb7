// The shipped systemd units pass `systemd-analyze verify` (where systemd-analyze exists), with
// ExecStart pointed at the binary of this build.

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "tests/support/process_runner.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

namespace fs = std::filesystem;

std::string Read(const std::string& p) {
  std::stringstream s;
  s << std::ifstream(p).rdbuf();
  return s.str();
}

TEST(SystemdUnitsTest, UnitsVerify) {
  const std::string analyze = "/usr/bin/systemd-analyze";
  if (!fs::exists(analyze)) GTEST_SKIP() << "missing " << analyze;
  const std::string dir = testing::FreshTempDir("units");
  const std::string cairnd = testing::BinaryDir() + "/daemon/cairnd";
  for (const std::string unit : {"cairnd.service", "cairnd@.service"}) {
    std::string text = Read(testing::BinaryDir() + "/systemd/" + unit);
    ASSERT_FALSE(text.empty()) << unit;
    // Units must not be left with unexpanded configure variables.
    EXPECT_EQ(text.find('@' + std::string("CMAKE")), std::string::npos) << unit;
    const size_t exec = text.find("ExecStart=");
    ASSERT_NE(exec, std::string::npos) << unit;
    const size_t binary_end = text.find(' ', exec);
    text.replace(exec, binary_end - exec, "ExecStart=" + cairnd);
    const std::string name = unit == "cairnd@.service" ? "cairnd@rover.service" : unit;
    std::ofstream(dir + "/" + name) << text;
    for (const char* key : {"Type=notify", "WatchdogSec=", "Restart=on-failure", "LimitRTPRIO=",
                            "LimitMEMLOCK=", "ProtectSystem=strict", "PrivateTmp=yes",
                            "NoNewPrivileges=yes", "CapabilityBoundingSet=", "ReadWritePaths=/var/lib/cairn",
                            "User=cairn"}) {
      EXPECT_NE(text.find(key), std::string::npos) << unit << " lacks " << key;
    }
  }
  const auto r = testing::RunProcess({analyze, "verify", "--man=no", dir + "/cairnd.service",
                                      dir + "/cairnd@rover.service"});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  // Warnings about our units (not about unrelated system units) count as failures too.
  EXPECT_EQ(r.output.find("cairnd"), std::string::npos) << r.output;
}

TEST(SystemdUnitsTest, SysusersAndTmpfilesDeclareTheStateFolder) {
  const std::string src = testing::SourceDir() + "/systemd/";
  EXPECT_NE(Read(src + "cairn.sysusers.conf").find("u cairn "), std::string::npos);
  EXPECT_NE(Read(src + "cairn.tmpfiles.conf").find("d /var/lib/cairn 0750 cairn cairn"), std::string::npos);
}

}  // namespace
}  // namespace cairn
