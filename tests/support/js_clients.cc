#include "tests/support/js_clients.h"

#include <filesystem>

#include "tests/support/process_runner.h"
#include "tests/support/test_data.h"

namespace cairn::testing {

namespace fs = std::filesystem;

std::string InstallJsClients(std::string* why_not) {
  if (!fs::exists("/usr/bin/node") || !fs::exists("/usr/bin/npm")) {
    *why_not = "missing /usr/bin/node or /usr/bin/npm";
    return "";
  }
  const std::string dir = BinaryDir() + "/js-clients";
  const std::string src = SourceDir() + "/tests/js";
  fs::create_directories(dir);
  // Reinstall when package.json changed.
  const bool fresh = fs::exists(dir + "/package.json") && fs::exists(dir + "/node_modules") &&
                     fs::last_write_time(dir + "/package.json") >= fs::last_write_time(src + "/package.json");
  if (!fresh) {
    fs::copy_file(src + "/package.json", dir + "/package.json", fs::copy_options::overwrite_existing);
    const auto r = RunProcess({"/usr/bin/npm", "install", "--prefix", dir, "--no-audit", "--no-fund", "--silent"});
    if (r.exit_code != 0) {
      *why_not = "npm install of tests/js failed (no registry access?): " + r.output.substr(0, 300);
      return "";
    }
  }
  for (const auto& e : fs::directory_iterator(src)) {
    if (e.path().extension() == ".mjs") {
      fs::copy_file(e.path(), dir + "/" + e.path().filename().string(), fs::copy_options::overwrite_existing);
    }
  }
  return dir;
}

}  // namespace cairn::testing
