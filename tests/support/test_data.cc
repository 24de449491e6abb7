#include "tests/support/test_data.h"

namespace cairn::testing {

namespace fs = std::filesystem;

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
