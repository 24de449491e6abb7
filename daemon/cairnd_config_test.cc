#include "daemon/cairnd_config.h"

#include <filesystem>

#include <gtest/gtest.h>

#include "tests/support/test_data.h"

namespace cairn {
namespace {

// Every configuration the project ships must load without error.
TEST(ShippedConfigsTest, EveryConfigUnderConfigsLoads) {
  int loaded = 0;
  for (const auto& e : std::filesystem::directory_iterator(testing::SourceDir() + "/configs")) {
    if (e.path().extension() != ".yaml") continue;
    auto o = LoadCairndOptions(e.path().string(), {});
    EXPECT_TRUE(o.ok()) << e.path() << ": " << o.status().message();
    ++loaded;
  }
  EXPECT_GE(loaded, 3);
}

}  // namespace
}  // namespace cairn
