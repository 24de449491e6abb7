// What the sanitizer build catches: UndefinedBehaviorSanitizer's checks in our code (they are left
// out of system headers, cmake/ubsan_ignorelist.txt), AddressSanitizer's everywhere, the
// standard library's and Eigen's inlined code included.

#include <string>

#include <gtest/gtest.h>

#include "common/sanitizers.h"
#include "tests/support/process_runner.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

using testing::ProcessResult;
using testing::RunProcess;

ProcessResult Probe(const std::string& fault) {
  return RunProcess({testing::BinaryDir() + "/tests/sanitizer_probe", fault});
}

class SanitizersTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!CAIRN_ADDRESS_SANITIZER) {
      GTEST_SKIP() << "not an AddressSanitizer + UBSan build (the asan-ubsan preset runs this)";
    }
  }
};

TEST_F(SanitizersTest, UndefinedBehaviourInOurCodeStopsTheProgram) {
  for (const auto& [fault, report] : {std::pair<std::string, std::string>{"signed-overflow", "signed integer overflow"},
                                      {"null-member-call", "member call on null pointer"}}) {
    const ProcessResult r = Probe(fault);
    EXPECT_NE(r.exit_code, 0) << fault << ":\n" << r.output;
    EXPECT_NE(r.output.find("runtime error: " + report), std::string::npos) << fault << ":\n" << r.output;
    EXPECT_NE(r.output.find("sanitizer_probe.cc"), std::string::npos) << fault << ":\n" << r.output;
  }
}

TEST_F(SanitizersTest, OutOfBoundsReadsInLibraryHeadersAreCaught) {
  for (const std::string fault : {"vector-overflow", "eigen-overflow"}) {
    const ProcessResult r = Probe(fault);
    EXPECT_NE(r.exit_code, 0) << fault << ":\n" << r.output;
    EXPECT_NE(r.output.find("AddressSanitizer: heap-buffer-overflow"), std::string::npos) << fault << ":\n"
                                                                                          << r.output;
  }
}

}  // namespace
}  // namespace cairn
