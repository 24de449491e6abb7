#include "common/bounded_errors.h"

#include <gtest/gtest.h>

namespace cairn {
namespace {

TEST(BoundedErrorsTest, KeepsTheFirstErrorsOnly) {
  std::vector<std::string> errors;
  for (size_t i = 0; i < kMaxReportedErrors; ++i) {
    EXPECT_TRUE(AppendBoundedError(errors, "error " + std::to_string(i)));
  }
  EXPECT_FALSE(AppendBoundedError(errors, "one too many"));
  ASSERT_EQ(errors.size(), kMaxReportedErrors);
  EXPECT_EQ(errors.front(), "error 0");
  EXPECT_EQ(errors.back(), "error " + std::to_string(kMaxReportedErrors - 1));
}

}  // namespace
}  // namespace cairn
