#pragma once
// Keys of the team exchange's delivery: budgets per link, how often peers announce what they hold,
// when unacknowledged items go again, and the sizes of what travels.

#include <cstdint>

#include "common/options_visitor.h"

namespace cairn {

struct ExchangeOptions {
  // Every link's mean byte rate, both directions counted separately (the thesis' radios carried
  // 58 KB/s between robots; cairn's submaps are smaller).
  double link_bytes_per_s = 15000.0;
  double link_burst_bytes = 16384.0;
  double summary_interval = 1.0;  // s between announcements of what this robot holds
  double summary_min_interval = 0.2;  // s: earliest announcement after new items were stored
  // An item sent but not acknowledged after this long goes again (lost with a broken link).
  double resend_timeout = 10.0;
  // A teammate's items go on to a third robot only after this long unacknowledged: in a meshed
  // team the third hears them from their origin first, and relays carry only what it cannot.
  double relay_delay = 2.5;
  int64_t fragment_bytes = 8192;    // pieces of larger items; small items pass between them
  int64_t message_bytes = 16384;    // a message stops growing past this
  int64_t max_item_bytes = 16 << 20;
  int64_t reorder_bytes = 64 << 20;  // complete items held until the ones before them arrive

  void Visit(OptionsVisitor& v) {
    v.Number("link_bytes_per_s", link_bytes_per_s, 100.0, 1e9, "B/s");
    v.Number("link_burst_bytes", link_burst_bytes, 1024.0, 1e9, "B");
    v.Number("summary_interval", summary_interval, 0.01, 3600.0, "s");
    v.Number("summary_min_interval", summary_min_interval, 0.0, 3600.0, "s");
    v.Number("resend_timeout", resend_timeout, 0.1, 86400.0, "s");
    v.Number("relay_delay", relay_delay, 0.0, 3600.0, "s");
    v.Integer("fragment_bytes", fragment_bytes, 256, 16 << 20, "B");
    v.Integer("message_bytes", message_bytes, 256, 64 << 20, "B");
    v.Integer("max_item_bytes", max_item_bytes, 1024, 1 << 30, "B");
    v.Integer("reorder_bytes", reorder_bytes, 0, int64_t{1} << 34, "B");
  }
};

}  // namespace cairn
