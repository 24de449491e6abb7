#pragma once

#include <cstdint>
#include <string>

namespace cairn {

// One link as the comms thread last saw it (refreshed every second), for the live status and
// diagnostics.json.
struct TeamLinkStatus {
  std::string peer;
  uint64_t sent_bytes = 0;
  uint64_t received_bytes = 0;
  uint64_t queued_items = 0;      // items the peer has not acknowledged
  uint64_t queued_bytes = 0;
  uint64_t queued_items_max = 0;  // over the run
  uint64_t queued_bytes_max = 0;
  double since_contact = -1.0;    // s since the peer was last heard; -1 = never
};

}  // namespace cairn
