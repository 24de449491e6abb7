// cairnd: the onboard SLAM daemon.
//   cairnd --config FILE [--set key=value ...] [--replay DATASET_DIR | --sim] [--out DIR] [--log-level L]

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/sinks/systemd_sink.h>
#include <spdlog/spdlog.h>

#include "daemon/cairnd.h"
#include "daemon/cairnd_config.h"

namespace {

void Usage(FILE* f) {
  std::fprintf(f,
               "usage: cairnd --config FILE [--set key.path=value ...] [--replay DATASET_DIR | --sim]\n"
               "              [--out DIR] [--log-level trace|debug|info|warn|error]\n"
               "  --replay DIR  replay an EuRoC/ASL folder or a cairnd MCAP recording\n"
               "  --sim         play robot.name in the simulated mission of the config's sim section\n");
}

void SetupLogging(const std::string& level) {
  // Under systemd, log to the journal with proper priorities; elsewhere to the terminal.
  std::shared_ptr<spdlog::logger> logger;
  if (std::getenv("JOURNAL_STREAM") != nullptr && std::getenv("INVOCATION_ID") != nullptr) {
    logger = std::make_shared<spdlog::logger>("cairnd", std::make_shared<spdlog::sinks::systemd_sink_mt>());
  } else {
    logger = spdlog::stdout_color_mt("cairnd");
  }
  spdlog::set_default_logger(logger);
  spdlog::set_level(spdlog::level::from_str(level));
  spdlog::flush_on(spdlog::level::info);
}

// A YAML single-quoted scalar holds any path literally ('' stands for ').
std::string YamlQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += (c == '\'' ? std::string("''") : std::string(1, c));
  return q + "'";
}

}  // namespace

int main(int argc, char** argv) {
  std::string config, replay, out, level = "info";
  bool simulate = false;
  std::vector<std::string> overrides;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&](const char* name) -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "cairnd: %s needs a value\n", name);
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--config") config = value("--config");
    else if (a == "--set") overrides.emplace_back(value("--set"));
    else if (a == "--replay") replay = value("--replay");
    else if (a == "--sim") simulate = true;
    else if (a == "--out") out = value("--out");
    else if (a == "--log-level") level = value("--log-level");
    else if (a == "--help" || a == "-h") { Usage(stdout); return 0; }
    else {
      std::fprintf(stderr, "cairnd: unknown argument '%s'\n", a.c_str());
      Usage(stderr);
      return 2;
    }
  }
  if (config.empty()) {
    std::fprintf(stderr, "cairnd: --config FILE is required\n");
    Usage(stderr);
    return 2;
  }
  if (spdlog::level::from_str(level) == spdlog::level::off && level != "off") {
    std::fprintf(stderr, "cairnd: unknown log level '%s'\n", level.c_str());
    return 2;
  }
  if (simulate && !replay.empty()) {
    std::fprintf(stderr, "cairnd: --replay and --sim exclude each other\n");
    return 2;
  }
  // --replay, --sim and --out are shorthands for the matching --set overrides.
  if (simulate) overrides.push_back("source=sim");
  if (!replay.empty()) {
    overrides.push_back("source=replay");
    overrides.push_back("replay.dataset=" + YamlQuote(replay));
  }
  if (!out.empty()) overrides.push_back("output.dir=" + YamlQuote(out));

  auto options = cairn::LoadCairndOptions(config, overrides);
  if (!options.ok()) {
    std::fprintf(stderr, "cairnd: invalid configuration:\n%s\n", options.status().message().c_str());
    return 1;
  }
  SetupLogging(level);
  cairn::Cairnd::BlockTerminationSignals();
  cairn::Cairnd daemon(*options, config);
  if (cairn::Status s = daemon.Prepare(); !s.ok()) {
    spdlog::error("{}", s.ToString());
    return 1;
  }
  return daemon.Run();
}
