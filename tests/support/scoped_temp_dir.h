#pragma once
// A fresh, empty folder under the system temp directory for one test, removed with everything in
// it when the owner goes out of scope, so that test runs on bench machines and CI boxes do not fill
// /tmp. When the test (or, for a folder a test suite shares, the suite) has failed, the folder is
// kept and its path printed, to look at what the failing test left.
//
// Header-only, like the other gtest-bound helpers here: test targets that do not link
// test_support can use it too.

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>

#include <gtest/gtest.h>

namespace cairn::testing {

class ScopedTempDir {
 public:
  // `tag` names the folder (cairn_TAG_PID_N), so a kept one shows which test made it.
  explicit ScopedTempDir(const std::string& tag) {
    // Function-local in an inline function: one counter per process, whichever file includes this.
    static std::atomic<int> counter{0};
    namespace fs = std::filesystem;
    const fs::path p = fs::temp_directory_path() /
                       ("cairn_" + tag + "_" + std::to_string(getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(p);  // a leftover of an earlier process that had the same id
    fs::create_directories(p);
    path_ = p.string();
  }

  ~ScopedTempDir() {
    if (CurrentTestFailed()) {
      std::fprintf(stderr, "kept %s\n", path_.c_str());
      return;
    }
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
    if (ec) std::fprintf(stderr, "could not remove %s: %s\n", path_.c_str(), ec.message().c_str());
  }

  ScopedTempDir(const ScopedTempDir&) = delete;
  ScopedTempDir& operator=(const ScopedTempDir&) = delete;

  const std::string& path() const { return path_; }

 private:
  // Inside a test (its body, fixture, TearDown) the test's result; in SetUpTestSuite or
  // TearDownTestSuite, where no test is current, whether any test of the suite failed.
  static bool CurrentTestFailed() {
    const ::testing::UnitTest* unit = ::testing::UnitTest::GetInstance();
    if (unit->current_test_info() == nullptr && unit->current_test_suite() != nullptr) {
      return unit->current_test_suite()->Failed();
    }
    return ::testing::Test::HasFailure();
  }

  std::string path_;
};

}  // namespace cairn::testing
