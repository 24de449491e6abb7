#pragma once
// The `team` section of cairnd's configuration: who the teammates are (the team file), this
// robot's CURVE key pair, where the item store lives, and the exchange's budgets.

#include <string>

#include "common/options_visitor.h"
#include "daemon/comms/exchange_options.h"
#include "daemon/comms/zmq_transport_options.h"

namespace cairn {

struct TeamOptions {
  bool enabled = false;
  // Every member's name, graph letter, address and public key (daemon/comms/team_file.h); the same
  // file on every robot.
  std::string members_file = "/etc/cairn/team.yaml";
  // This robot's key pair, as `cairn keys generate` writes it (mode 0600).
  std::string secret_key_file = "/etc/cairn/keys/robot.key";
  // Where this robot binds; "" = the address of its own entry in the team file.
  std::string listen;
  // The durable item logs of every robot; "" = <output.dir>/exchange.
  std::string store_dir;
  // This robot's estimates travel in batches of this many seconds (and at every frame switch).
  double pose_batch_interval = 1.0;
  // Replays and simulations: after the data ends, how long to go on exchanging until every
  // teammate holds everything (and this robot everything of theirs).
  double linger = 60.0;
  // After a stop signal (systemctl stop, Ctrl-C), the exchange goes on at most this long: the
  // service's stop timeout (TimeoutStopSec, 30 s in the shipped units) must also cover writing the
  // outputs. A second signal ends it at once.
  double stop_linger = 10.0;
  ExchangeOptions exchange;
  ZmqTransportOptions transport;

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Text("members_file", members_file);
    v.Text("secret_key_file", secret_key_file);
    v.Text("listen", listen);
    v.Text("store_dir", store_dir);
    v.Number("pose_batch_interval", pose_batch_interval, 0.01, 3600.0, "s");
    v.Number("linger", linger, 0.0, 86400.0, "s");
    v.Number("stop_linger", stop_linger, 0.0, 86400.0, "s");
    v.Section("exchange", exchange);
    v.Section("transport", transport);
  }
};

}  // namespace cairn
