// cairn config check FILE [--set key=value ...] and cairn config doc.

#include <cstdio>
#include <string>
#include <vector>

#include "common/options_yaml_writer.h"
#include "daemon/cairnd_config.h"
#include "tools/commands.h"

namespace cairn::tools {

constexpr const char* kConfigCheckUsage =
    "usage: cairn config check FILE [--set key.path=value ...]\n";

int RunConfigCheck(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kConfigCheckUsage);
  std::string file;
  std::vector<std::string> overrides;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    if (a == "--set" && i + 1 < args.args.size()) {
      overrides.emplace_back(args.args[++i]);
    } else if (file.empty() && a.rfind("--", 0) != 0) {
      file = a;
    } else {
      std::fputs(kConfigCheckUsage, stderr);
      return 2;
    }
  }
  if (file.empty()) {
    std::fputs(kConfigCheckUsage, stderr);
    return 2;
  }
  auto options = LoadCairndOptions(file, overrides);
  if (!options.ok()) {
    std::fprintf(stderr, "%s\n", options.status().message().c_str());
    return 1;
  }
  std::printf("%s: ok\n", file.c_str());
  return 0;
}

int RunConfigDoc(const CommandArgs& /*args*/) {
  CairndOptions defaults;
  std::printf("# cairnd configuration keys with their defaults, units and ranges.\n%s",
              OptionsYamlWriter::Write(defaults).c_str());
  return 0;
}

}  // namespace cairn::tools
