#include "estimation/filter/filter_result.h"

namespace cairn {

const char* FilterResultName(FilterResult r) {
  switch (r) {
    case FilterResult::kApplied: return "applied";
    case FilterResult::kPending: return "pending";
    case FilterResult::kInitializing: return "initializing";
    case FilterResult::kNotInitialized: return "not initialized";
    case FilterResult::kRejectedNotFinite: return "rejected: not finite";
    case FilterResult::kRejectedOutOfOrder: return "rejected: out of order";
    case FilterResult::kRejectedDuplicate: return "rejected: duplicate time";
    case FilterResult::kRejectedFarFuture: return "rejected: far future";
    case FilterResult::kRejectedTooOld: return "rejected: too old";
    case FilterResult::kRejectedUnknownClone: return "rejected: unknown clone";
    case FilterResult::kRejectedBadCovariance: return "rejected: bad covariance";
    case FilterResult::kRejectedGate: return "rejected: innovation gate";
    case FilterResult::kRejectedBufferFull: return "rejected: buffer full";
    case FilterResult::kRejectedDisabled: return "rejected: disabled";
    case FilterResult::kRejectedInvalid: return "rejected: invalid measurement";
  }
  return "unknown";
}

}  // namespace cairn
