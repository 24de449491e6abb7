// cairn summary DIR...: one short block per cairnd output folder (what the run consumed, dropped
// and how it ended), read from its summary.json.

#include <cstdio>
#include <exception>
#include <string>

#include "daemon/json_value.h"
#include "tools/commands.h"

namespace cairn::tools {
namespace {

double CountOf(const JsonValue& streams, const char* name) {
  return streams.has(name) ? streams[name]["count"].number() : 0.0;
}

}  // namespace

int RunSummary(const CommandArgs& args) {
  if (args.args.empty()) {
    std::fprintf(stderr, "usage: cairn summary OUT_DIR [OUT_DIR ...]\n");
    return 2;
  }
  int rc = 0;
  for (const char* dir : args.args) {
    const std::string path = std::string(dir) + "/summary.json";
    try {
      const JsonValue s = JsonValue::ParseFile(path);
      const JsonValue& streams = s["streams"];
      double dropped = 0.0;
      for (const auto& [queue, n] : s["dropped"].object()) dropped += n.number();
      std::printf("%s: robot %s, %s, %s%s\n", dir, s["robot"].string().c_str(), s["mode"].string().c_str(),
                  s["stop_reason"].string().c_str(), s["complete"].boolean() ? "" : " (incomplete)");
      std::printf("  consumed: imu %.0f, stereo %.0f, wheel odometry %.0f; dropped %.0f; device faults %.0f\n",
                  CountOf(streams, "imu"), CountOf(streams, "stereo"), CountOf(streams, "wheel_odometry"),
                  dropped, s["faults"]["total"].number());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "cairn summary: %s: %s\n", path.c_str(), e.what());
      rc = 1;
    }
  }
  return rc;
}

}  // namespace cairn::tools
