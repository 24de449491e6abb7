#include "tests/support/test_data.h"

#include <unistd.h>

#include <atomic>

namespace cairn::testing {

namespace fs = std::filesystem;

std::string FreshTempDir(const std::string& tag) {
  static std::atomic<int> counter{0};
  const fs::path p = fs::temp_directory_path() /
                     ("cairn_" + tag + "_" + std::to_string(getpid()) + "_" + std::to_string(counter++));
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

void CopyEurocDataset(const std::string& from, const std::string& to) {
  for (const auto& e : fs::recursive_directory_iterator(from)) {
    const fs::path rel = fs::relative(e.path(), from);
    const fs::path dst = fs::path(to) / rel;
    if (e.is_directory()) {
      fs::create_directories(dst);
    } else if (e.path().extension() == ".png") {
      fs::create_symlink(fs::absolute(e.path()), dst);
    } else {
      fs::copy_file(e.path(), dst, fs::copy_options::overwrite_existing);
    }
  }
}

}  // namespace cairn::testing
