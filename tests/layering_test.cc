// The layers of docs/architecture.md, checked on every #include "..." of the tree: production code
// includes only its own part and the parts below it; test code (`*_test.cc`, `testing/` folders,
// `tests/`) may also use the simulator, the replay readers and the test helpers. A failure names
// the file, the line and the include.

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/support/test_data.h"

namespace cairn {
namespace {

namespace fs = std::filesystem;

struct Part {
  const char* folder;                // a file belongs to the longest folder that prefixes it
  std::vector<const char*> may_use;  // besides itself
};

// Bottom up. Generated protobuf headers ("cairn/*.pb.h", "foxglove/*.pb.h") count as io/proto.
const std::vector<Part>& Parts() {
  static const std::vector<Part> parts = {
      {"common/", {}},
      {"io/", {"common/"}},
      {"hal/", {"common/"}},
      {"stereo/", {"hal/", "io/", "common/"}},
      {"estimation/math/", {"common/"}},
      {"estimation/filter/", {"estimation/math/", "hal/", "common/"}},
      {"estimation/eval/", {"estimation/math/", "common/"}},
      {"estimation/graph/", {"estimation/math/", "common/"}},
      {"estimation/vo/", {"estimation/filter/", "estimation/math/", "stereo/", "hal/", "common/"}},
      {"estimation/testing/", {"estimation/", "hal/", "common/"}},
      {"mapping/", {"stereo/", "estimation/", "hal/", "io/", "common/"}},
      {"detection/", {"hal/", "common/"}},
      {"fpga/", {"stereo/", "hal/", "common/"}},
      {"drivers/", {"hal/", "io/", "common/"}},
      {"sim/", {"drivers/", "detection/", "mapping/", "stereo/", "estimation/", "hal/", "io/", "common/"}},
      {"daemon/telemetry/", {"mapping/", "stereo/", "estimation/", "hal/", "io/", "common/"}},
      {"daemon/pipeline/",
       {"daemon/telemetry/", "detection/", "fpga/", "mapping/", "stereo/", "estimation/", "hal/", "io/", "common/"}},
      {"daemon/comms/",
       {"daemon/pipeline/", "daemon/telemetry/", "mapping/", "estimation/", "hal/", "io/", "common/"}},
      {"daemon/",
       {"daemon/comms/", "daemon/pipeline/", "daemon/telemetry/", "sim/", "drivers/", "detection/", "fpga/", "mapping/", "stereo/",
        "estimation/", "hal/", "io/", "common/"}},
      // `cairn bench` runs the scenes the tests use, so the tools may include testing/ helpers.
      {"tools/",
       {"daemon/", "sim/", "drivers/", "detection/", "fpga/", "mapping/", "stereo/", "estimation/", "hal/", "io/",
        "common/", "testing/"}},
      {"tests/support/", {"hal/", "common/"}},
      {"tests/",
       {"tools/", "daemon/", "sim/", "drivers/", "detection/", "fpga/", "mapping/", "stereo/", "estimation/",
        "hal/", "io/", "common/"}},
  };
  return parts;
}

const Part* PartOf(const std::string& path) {
  const Part* best = nullptr;
  for (const Part& p : Parts()) {
    const std::string folder = p.folder;
    if (path.starts_with(folder) && (best == nullptr || folder.size() > std::string(best->folder).size()))
      best = &p;
  }
  return best;
}

bool IsTestCode(const std::string& path) {
  return path.ends_with("_test.cc") || path.find("/testing/") != std::string::npos ||
         path.starts_with("tests/");
}

bool IsTestHelper(const std::string& path) {
  return path.find("/testing/") != std::string::npos || path.starts_with("tests/support/");
}

// What test code may use beyond its part's own list: simulated inputs, recorded data, helpers.
bool TestMayUse(const std::string& target) {
  return target.starts_with("sim/") || target.starts_with("drivers/replay/") || IsTestHelper(target);
}

// The in-tree file an include names, as a path from the root; empty for other libraries' headers.
std::string Resolve(const fs::path& root, const std::string& include) {
  static const std::regex generated_proto(R"((cairn|foxglove)/[A-Za-z_]+\.pb\.h)");
  if (std::regex_match(include, generated_proto)) return "io/proto/" + include;
  if (fs::exists(root / include)) return include;
  return "";
}

bool Allowed(const std::string& from, const std::string& target) {
  const Part* part = PartOf(from);
  if (part == nullptr) return false;
  const bool test_code = IsTestCode(from);
  if (IsTestHelper(target) && !test_code) {
    if (!std::string(part->folder).starts_with("tools/")) return false;
  }
  if (test_code && TestMayUse(target)) return true;
  // Test code of a part reaches the part itself too (estimation/filter tests use estimation/testing).
  const std::string own = part->folder;
  if (target.starts_with(own)) return true;
  if (test_code) {
    const std::string top = own.substr(0, own.find('/') + 1);
    if (target.starts_with(top) && top != "daemon/" && top != "tests/") return true;
    if (own.starts_with("daemon/") && target.starts_with("daemon/")) return true;
  }
  for (const char* use : part->may_use) {
    const std::string u = use;
    if (u == "testing/") continue;
    if (target.starts_with(u)) return true;
  }
  return false;
}

std::vector<std::string> SourceFiles(const fs::path& root) {
  std::vector<std::string> files;
  for (auto it = fs::recursive_directory_iterator(root); it != fs::recursive_directory_iterator(); ++it) {
    const std::string name = it->path().filename().string();
    if (it->is_directory() &&
        (name.starts_with(".") || name == "build" || name == "out" || name == "node_modules")) {
      it.disable_recursion_pending();
      continue;
    }
    const std::string ext = it->path().extension().string();
    if (it->is_regular_file() && (ext == ".h" || ext == ".cc")) {
      files.push_back(fs::relative(it->path(), root).generic_string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(LayeringTest, EveryIncludePointsDownTheLayers) {
  const fs::path root = testing::SourceDir();
  const std::regex include_line(R"re(^\s*#\s*include\s+"([^"]+)")re");
  const std::vector<std::string> files = SourceFiles(root);
  ASSERT_GT(files.size(), 300u) << "the source tree was not found at " << root;
  int checked = 0;
  for (const std::string& file : files) {
    if (file.starts_with("cmake/")) continue;
    ASSERT_NE(PartOf(file), nullptr) << file << " is in no part of the layer table (tests/layering_test.cc)";
    std::ifstream in(root / file);
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
      ++number;
      std::smatch m;
      if (!std::regex_search(line, m, include_line)) continue;
      const std::string target = Resolve(root, m[1].str());
      if (target.empty()) continue;
      ++checked;
      EXPECT_TRUE(Allowed(file, target)) << file << ":" << number << " includes \"" << m[1].str()
                                         << "\", against the layers (docs/architecture.md)";
    }
  }
  EXPECT_GT(checked, 900);
}

// The table itself: a few directions that must never be allowed.
TEST(LayeringTest, ForbiddenDirectionsAreCaught) {
  EXPECT_FALSE(Allowed("mapping/submap_codec.cc", "drivers/replay/csv_reader.h"));
  EXPECT_FALSE(Allowed("mapping/local_mapper.h", "sim/terrain.h"));
  EXPECT_FALSE(Allowed("sim/world_file.cc", "daemon/cairnd_config.h"));
  EXPECT_FALSE(Allowed("estimation/filter/local_reference_filter.cc", "estimation/vo/vo_types.h"));
  EXPECT_FALSE(Allowed("estimation/graph/slam_graph.cc", "estimation/testing/slam_graph_scenario.h"));
  EXPECT_FALSE(Allowed("stereo/sgm_matcher.cc", "fpga/sgm_registers.h"));
  EXPECT_FALSE(Allowed("daemon/telemetry/graph_scene_encoder.h", "daemon/pipeline/graph_stage.h"));
  EXPECT_FALSE(Allowed("hal/calibration.h", "io/crc32.h"));
  EXPECT_FALSE(Allowed("drivers/socketcan_wheel_driver.cc", "sim/terrain.h"));
  EXPECT_FALSE(Allowed("tests/support/test_data.cc", "daemon/cairnd.h"));
  EXPECT_FALSE(Allowed("sim/camera_renderer.cc", "fpga/uio_stereo_device.h"));
  EXPECT_TRUE(Allowed("daemon/pipeline/pipeline.h", "daemon/telemetry/mcap_recorder.h"));
  EXPECT_TRUE(Allowed("mapping/depth_fusion_test.cc", "mapping/testing/mapping_test_scenes.h"));
  EXPECT_TRUE(
      Allowed("estimation/filter/local_reference_filter_test.cc", "estimation/testing/filter_scenario.h"));
  EXPECT_TRUE(Allowed("tools/map_commands.cc", "sim/testing/sim_depth_scenes.h"));
  EXPECT_TRUE(Allowed("drivers/replay/mcap_replay.cc", "io/proto/cairn/sensors.pb.h"));
}

}  // namespace
}  // namespace cairn
