// `cairn keys generate`: a robot's CURVE key pair for the team exchange.

#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cctype>
#include <cstring>
#include <string>

#include "daemon/comms/curve_keys.h"
#include "tools/commands.h"

namespace cairn::tools {
namespace {

constexpr const char* kUsage = "usage: cairn keys generate --name ROBOT [--dir DIR] [--force]\n";

bool ValidName(const std::string& name) {
  if (name.empty() || name.size() > 32) return false;
  for (char c : name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_')) return false;
  }
  return true;
}

}  // namespace

int RunKeysGenerate(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kUsage);
  std::string name, dir = ".";
  bool force = false;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    const bool has_value = i + 1 < args.args.size();
    if (a == "--name" && has_value) name = args.args[++i];
    else if (a == "--dir" && has_value) dir = args.args[++i];
    else if (a == "--force") force = true;
    else {
      std::fprintf(stderr, "%s", kUsage);
      return 2;
    }
  }
  if (!ValidName(name)) {
    std::fprintf(stderr, "cairn keys generate: --name must be the robot's name (letters, digits, '-', '_')\n%s",
                 kUsage);
    return 2;
  }
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    std::fprintf(stderr, "cairn keys generate: %s is not a directory\n", dir.c_str());
    return 1;
  }
  auto keys = CurveKeys::Generate();
  if (!keys.ok()) {
    std::fprintf(stderr, "cairn keys generate: %s\n", keys.status().message().c_str());
    return 1;
  }
  if (Status s = CurveKeys::Write(dir, name, *keys, force); !s.ok()) {
    std::fprintf(stderr, "cairn keys generate: %s\n", s.message().c_str());
    return 1;
  }
  std::printf("%s/%s.key  secret key (mode 0600): team.secret_key_file on %s only\n", dir.c_str(), name.c_str(),
              name.c_str());
  std::printf("%s/%s.pub  public key %s: the public_key of %s in the team file\n", dir.c_str(), name.c_str(),
              keys->public_key.c_str(), name.c_str());
  return 0;
}

}  // namespace cairn::tools
