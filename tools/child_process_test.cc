#include "tools/child_process.h"

#include <signal.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "tests/support/scoped_temp_dir.h"

namespace cairn::tools {
namespace {

std::string Read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(ChildProcessTest, RunsFromPathAndLogsBothStreams) {
  const cairn::testing::ScopedTempDir temp("child_process_streams");
  const std::string log = temp.path() + "/child.log";
  ChildProcess p;
  ASSERT_TRUE(p.Start({"sh", "-c", "echo out; echo err >&2; exit 3"}, log).ok());
  EXPECT_EQ(p.Wait(), 3);
  EXPECT_EQ(p.Wait(), 3);
  EXPECT_FALSE(p.Running());
  EXPECT_EQ(Read(log), "out\nerr\n");
}

TEST(ChildProcessTest, SignalEndsItWithTheSignalNumber) {
  const cairn::testing::ScopedTempDir temp("child_process_signal");
  ChildProcess p;
  ASSERT_TRUE(p.Start({"sleep", "30"}, temp.path() + "/child.log").ok());
  EXPECT_TRUE(p.Running());
  p.Signal(SIGTERM);
  EXPECT_EQ(p.Wait(), 128 + SIGTERM);
}

TEST(ChildProcessTest, MissingProgramIsAnErrorNamingIt) {
  EXPECT_FALSE(ProgramAvailable("cairn-no-such-program"));
  EXPECT_TRUE(ProgramAvailable("sh"));
  const cairn::testing::ScopedTempDir temp("child_process_missing");
  ChildProcess p;
  const Status s = p.Start({"cairn-no-such-program"}, temp.path() + "/child.log");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("cairn-no-such-program"), std::string::npos);
  EXPECT_EQ(p.Wait(), -1);
}

TEST(ChildProcessTest, DestructionKillsARunningChild) {
  const cairn::testing::ScopedTempDir temp("child_process_kill");
  pid_t pid = -1;
  {
    ChildProcess p;
    ASSERT_TRUE(p.Start({"sleep", "30"}, temp.path() + "/child.log").ok());
    pid = p.pid();
  }
  EXPECT_NE(kill(pid, 0), 0);  // reaped: the pid no longer names a process of ours
}

}  // namespace
}  // namespace cairn::tools
