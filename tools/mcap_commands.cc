// cairn mcap info FILE...: what a recording holds, read through its summary, or by scanning it when
// the file was never closed (a crash or power loss).

#include <cstdio>
#include <string>

#include "common/json_writer.h"
#include "io/mcap/mcap_reader.h"
#include "tools/commands.h"

namespace cairn::tools {

constexpr const char* kMcapInfoUsage =
    "usage: cairn mcap info FILE.mcap [FILE.mcap ...]\n";

int RunMcapInfo(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kMcapInfoUsage);
  if (args.args.empty()) {
    std::fputs(kMcapInfoUsage, stderr);
    return 2;
  }
  int rc = 0;
  for (const char* file : args.args) {
    McapReader reader(file);
    JsonWriter j;
    j.BeginObject();
    j.Field("file", file);
    auto summary = reader.ReadSummary();
    if (summary.ok()) {
      j.Field("closed", true);
      j.Field("messages", summary->statistics.message_count);
      j.Field("chunks", summary->statistics.chunk_count);
      j.Field("start_ns", summary->statistics.message_start_time);
      j.Field("end_ns", summary->statistics.message_end_time);
      j.Key("channels").BeginArray();
      for (const auto& [id, c] : summary->channels) {
        j.BeginObject();
        j.Field("id", id).Field("topic", c.topic).Field("encoding", c.message_encoding);
        const auto it = summary->statistics.channel_message_counts.find(id);
        j.Field("messages", it == summary->statistics.channel_message_counts.end() ? 0 : it->second);
        j.EndObject();
      }
      j.EndArray();
    } else {
      // No usable footer: count what a linear scan recovers.
      auto scan = reader.Scan(nullptr);
      if (!scan.ok()) {
        std::fprintf(stderr, "cairn mcap info: %s\n", scan.status().message().c_str());
        rc = 1;
        continue;
      }
      j.Field("closed", false);
      j.Field("note", summary.status().message());
      j.Field("recoverable_messages", scan->messages);
      j.Field("whole_chunks", scan->chunks);
      j.Key("channels").BeginArray();
      for (const auto& [id, c] : reader.channels()) {
        j.BeginObject().Field("id", id).Field("topic", c.topic).Field("encoding", c.message_encoding).EndObject();
      }
      j.EndArray();
    }
    j.EndObject();
    std::fputs(j.str().c_str(), stdout);
  }
  return rc;
}

}  // namespace cairn::tools
