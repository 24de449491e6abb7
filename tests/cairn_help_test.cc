// Every `cairn` command answers -h and --help with its usage on standard output and exit status
// 0, whatever else is on the line, rather than taking the word for a file or an unknown option.

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/support/process_runner.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

std::string Cairn() { return testing::BinaryDir() + "/tools/cairn"; }

// Every command `cairn help` lists but `config doc`, which takes no arguments.
const std::vector<std::string> kCommands = {"config check",
                                            "summary",
                                            "mcap info",
                                            "keys generate",
                                            "trajectory convert",
                                            "stereo",
                                            "stereo-eval",
                                            "bench stereo",
                                            "bench fpga",
                                            "bench filter",
                                            "bench rt",
                                            "graph solve",
                                            "graph replay",
                                            "graph inject",
                                            "graph switch-nees",
                                            "bench graph",
                                            "sim",
                                            "bench sim",
                                            "map",
                                            "bench map",
                                            "match",
                                            "bench match",
                                            "detect",
                                            "detect build-lut",
                                            "detect check-lut",
                                            "bench detect",
                                            "eval",
                                            "bench vo",
                                            "bench vo-scale",
                                            "bench lines",
                                            "bench landmarks"};

std::vector<std::string> Words(const std::string& command) {
  std::vector<std::string> out{Cairn()};
  const size_t space = command.find(' ');
  out.push_back(command.substr(0, space));
  if (space != std::string::npos) out.push_back(command.substr(space + 1));
  return out;
}

TEST(CairnHelpTest, EveryCommandListedIsCovered) {
  const auto r = testing::RunProcess({Cairn(), "help"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  size_t listed = 0;
  for (size_t at = r.output.find("\n  "); at != std::string::npos; at = r.output.find("\n  ", at + 1))
    ++listed;
  EXPECT_EQ(listed, kCommands.size() + 1) << r.output;  // and `config doc`
  for (const std::string& c : kCommands) EXPECT_NE(r.output.find("\n  " + c + " "), std::string::npos) << c;
}

TEST(CairnHelpTest, HelpPrintsTheUsageAndSucceeds) {
  for (size_t i = 0; i < kCommands.size(); ++i) {
    const std::string& c = kCommands[i];
    // Either flag (one per command keeps the test short under the sanitizers), after other words
    // too: a path, or an option that would otherwise be refused.
    const std::string flag = i % 2 == 0 ? "--help" : "-h";
    std::vector<std::string> argv = Words(c);
    argv.push_back(i % 4 < 2 ? "some/path" : "--frames");
    argv.push_back(flag);
    const auto r = testing::RunProcess(argv);
    EXPECT_EQ(r.exit_code, 0) << c << " " << flag << ": " << r.output;
    EXPECT_EQ(r.output.rfind("usage: cairn " + c, 0), 0u) << c << " " << flag << ": " << r.output;
  }
}

TEST(CairnHelpTest, AnUnknownOptionStillFails) {
  const auto r = testing::RunProcess({Cairn(), "bench", "sim", "--no-such-option"});
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("usage: cairn bench sim"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace cairn
