#pragma once
// Locating the shared real data sets from tests, and making writable, damageable copies of them
// (into a ScopedTempDir, tests/support/scoped_temp_dir.h).

#include <cstdlib>
#include <filesystem>
#include <string>

namespace cairn::testing {

// Root of ../shared/data: CAIRN_DATA_DIR from the environment (ctest sets it), else the path the
// build was configured with.
inline std::string DataDir() {
  const char* d = std::getenv("CAIRN_DATA_DIR");
#ifdef CAIRN_TEST_DATA_DIR
  if (d == nullptr) return CAIRN_TEST_DATA_DIR;
#endif
  return d != nullptr ? d : "";
}

#ifdef CAIRN_TEST_SOURCE_DIR
inline std::string SourceDir() { return CAIRN_TEST_SOURCE_DIR; }
inline std::string BinaryDir() { return CAIRN_TEST_BINARY_DIR; }
#endif

inline std::string EurocMicro() { return DataDir() + "/euroc-v1_01-micro"; }

// Copies an EuRoC folder's text files (CSV, YAML) and links its images, so a test can break one
// file without copying 200 images or touching the shared data.
void CopyEurocDataset(const std::string& from, const std::string& to);

}  // namespace cairn::testing

// Skips the current test when a data set is absent, naming the missing path.
#define CAIRN_REQUIRE_PATH(path)                                              \
  do {                                                                        \
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << (path); \
  } while (0)
