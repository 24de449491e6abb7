// cairn trajectory convert IN OUT [--from tum|euroc|kitti] [--to tum|euroc|kitti] [--times FILE]
// Converts trajectories between the formats evaluation tools expect (e.g. EuRoC ground truth to
// TUM for evo or the TUM scripts). KITTI output writes OUT and OUT.times.

#include <cstdio>
#include <string>

#include "common/atomic_file.h"
#include "estimation/eval/trajectory.h"
#include "tools/commands.h"

namespace cairn::tools {

constexpr const char* kTrajectoryConvertUsage =
    "usage: cairn trajectory convert IN OUT [--from F] [--to F] [--times FILE]\n";

int RunTrajectoryConvert(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kTrajectoryConvertUsage);
  std::string in, out, from, to, times;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    const bool has_value = i + 1 < args.args.size();
    if (a == "--from" && has_value) from = args.args[++i];
    else if (a == "--to" && has_value) to = args.args[++i];
    else if (a == "--times" && has_value) times = args.args[++i];
    else if (in.empty() && a.rfind("--", 0) != 0) in = a;
    else if (out.empty() && a.rfind("--", 0) != 0) out = a;
    else {
      std::fputs(kTrajectoryConvertUsage, stderr);
      return 2;
    }
  }
  if (in.empty() || out.empty()) {
    std::fputs(kTrajectoryConvertUsage, stderr);
    return 2;
  }
  auto in_format = from.empty() ? TrajectoryIo::FormatFromPath(in) : TrajectoryIo::FormatFromName(from);
  auto out_format = to.empty() ? TrajectoryIo::FormatFromPath(out) : TrajectoryIo::FormatFromName(to);
  for (const Status& s : {in_format.status(), out_format.status()}) {
    if (!s.ok()) {
      std::fprintf(stderr, "cairn trajectory convert: %s\n", s.message().c_str());
      return 2;
    }
  }
  auto t = TrajectoryIo::Read(in, *in_format, times);
  if (!t.ok()) {
    std::fprintf(stderr, "cairn trajectory convert: %s\n", t.status().message().c_str());
    return 1;
  }
  Status s = WriteFileAtomically(out, TrajectoryIo::Format(*t, *out_format));
  if (s.ok() && *out_format == TrajectoryFormat::kKitti) s = WriteFileAtomically(out + ".times", TrajectoryIo::KittiTimes(*t));
  if (!s.ok()) {
    std::fprintf(stderr, "cairn trajectory convert: %s\n", s.message().c_str());
    return 1;
  }
  std::printf("%zu poses -> %s\n", t->poses.size(), out.c_str());
  return 0;
}

}  // namespace cairn::tools
