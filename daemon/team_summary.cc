#include "daemon/team_summary.h"

#include "common/json_writer.h"

namespace cairn {
namespace {

double PerSecond(uint64_t bytes, double seconds) { return seconds > 0.0 ? static_cast<double>(bytes) / seconds : 0.0; }

}  // namespace

std::string BuildTeamJson(const TeamReport& r, const TeamFile& team, const GraphStage* graph) {
  JsonWriter j;
  j.BeginObject();
  j.Field("robot", r.robot);
  j.Field("letter", std::string(1, r.letter));
  j.Field("incarnation", r.incarnation);
  j.Field("seconds", r.seconds);
  j.Field("settled", r.settled);
  j.Key("linger").BeginObject();
  j.Field("seconds", r.linger_seconds).Field("ended", r.linger_ended);
  j.EndObject();
  j.Key("robots").BeginArray();
  for (const TeamMember& m : team.members) {
    const char letter = m.letter[0];
    j.BeginObject();
    j.Field("name", m.name);
    j.Field("letter", m.letter);
    const auto items = r.items.find(m.name);
    j.Field("heard", m.name == r.robot || items != r.items.end());
    j.Field("connected", graph != nullptr && graph->Connected(letter));
    j.Key("items").BeginObject();
    if (items != r.items.end()) {
      for (const auto& [kind, n] : items->second) j.Field(kind, n);
    }
    j.EndObject();
    if (graph != nullptr) {
      j.Field("origins", static_cast<uint64_t>(graph->FrameOrigins(letter).size()));
      j.Field("global_poses", static_cast<uint64_t>(graph->GlobalTrajectory(letter).poses.size()));
      // Runs before a restart: whether each is tied in (global_trajectory_<name>.run<k>.tum).
      const std::vector<uint32_t> runs = graph->Runs(letter);
      j.Key("earlier_runs").BeginArray();
      for (size_t i = 0; i + 1 < runs.size(); ++i) {
        j.BeginObject();
        j.Field("incarnation", static_cast<uint64_t>(IncarnationOfRun(runs[i])));
        j.Field("connected", graph->Connected(letter, runs[i]));
        j.EndObject();
      }
      j.EndArray();
    }
    j.EndObject();
  }
  j.EndArray();
  j.Key("peers").BeginArray();
  for (const ExchangePeerStats& p : r.peers) {
    j.BeginObject();
    j.Field("name", p.name);
    j.Field("heard", p.heard);
    j.Field("sent_bytes", p.sent_bytes);
    j.Field("received_bytes", p.received_bytes);
    j.Field("sent_bytes_per_s", PerSecond(p.sent_bytes, r.seconds));
    j.Field("received_bytes_per_s", PerSecond(p.received_bytes, r.seconds));
    j.Field("sent_messages", p.sent_messages);
    j.Field("received_messages", p.received_messages);
    j.Field("items_sent", p.items_sent);
    j.Field("items_received", p.items_received);
    j.Field("duplicates", p.duplicates);
    j.Field("resends", p.resends);
    j.Field("skipped_items", p.skipped_items);
    j.Field("resumed_bytes", p.resumed_bytes);
    j.Field("refused_messages", p.refused_messages);
    j.Field("refused_fragments", p.refused_fragments);
    j.Field("implausible_marks", p.implausible_marks);
    j.Field("transport_busy", p.transport_busy);
    j.Field("queued_items", p.queued_items);
    j.Field("queued_bytes", p.queued_bytes);
    // Seconds from the exchange's start; null when never heard.
    if (p.heard) {
      j.Field("first_contact_s", (p.first_contact - r.started_at).seconds());
      j.Field("last_contact_s", (p.last_contact - r.started_at).seconds());
    } else {
      j.Key("first_contact_s").Null();
      j.Key("last_contact_s").Null();
    }
    j.EndObject();
  }
  j.EndArray();
  j.Key("transport").BeginObject();
  j.Field("sent_messages", r.transport.sent_messages);
  j.Field("sent_bytes", r.transport.sent_bytes);
  j.Field("send_queue_full", r.transport.send_queue_full);
  j.Field("received_messages", r.transport.received_messages);
  j.Field("received_bytes", r.transport.received_bytes);
  j.Field("refused_unknown_key", r.transport.refused_unknown_key);
  j.Field("refused_malformed", r.transport.refused_malformed);
  j.EndObject();
  j.Key("exchange").BeginObject();
  j.Field("published", r.exchange.published);
  j.Field("stored", r.exchange.stored);
  j.Field("store_errors", r.exchange.store_errors);
  j.Field("reorder_dropped", r.exchange.reorder_dropped);
  j.Field("own_origin_refused", r.exchange.own_origin_refused);
  j.Field("decode_errors", r.decode_errors);
  j.Field("earlier_run_items", r.earlier_run_items);
  j.Key("sent_items").BeginObject();
  for (const auto& [kind, n] : r.sent_items_by_kind) j.Field(kind, n);
  j.EndObject();
  j.EndObject();
  if (graph != nullptr) {
    // The robots the graph has tied to this one's frame, and those it has not (never guessed).
    j.Key("connected").BeginArray();
    for (char c : graph->Robots()) {
      if (graph->Connected(c)) j.String(std::string(1, c));
    }
    j.EndArray();
    j.Key("not_connected").BeginArray();
    for (char c : graph->Robots()) {
      if (!graph->Connected(c)) j.String(std::string(1, c));
    }
    j.EndArray();
    const GraphStageReport g = graph->report();
    j.Field("team_matches", g.team_matches);
    j.Field("team_factors", g.team_factors);
    j.Field("team_matches_pending", g.team_matches_pending);
    j.Field("team_matches_held", g.team_matches_held);
    j.Field("team_matches_rejected", g.team_matches_rejected);
  }
  j.Key("errors").BeginArray();
  for (const std::string& e : r.errors) j.String(e);
  if (!r.exchange.last_error.empty()) j.String("last exchange error: " + r.exchange.last_error);
  j.EndArray();
  j.EndObject();
  return j.str() + "\n";
}

}  // namespace cairn
