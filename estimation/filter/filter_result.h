#pragma once
// What became of an input to the local reference filter.

#include <cstdint>

namespace cairn {

// Outcome of a call into the filter; each logged event keeps its own.
enum class FilterResult : uint8_t {
  kApplied,
  kPending,          // accepted, applied once the IMU data reaches its time
  kInitializing,     // IMU sample used for static initialization
  kNotInitialized,
  kRejectedNotFinite,
  kRejectedOutOfOrder,
  kRejectedDuplicate,
  kRejectedFarFuture,
  kRejectedTooOld,
  kRejectedUnknownClone,
  kRejectedBadCovariance,
  kRejectedGate,
  kRejectedBufferFull,
  kRejectedDisabled,
  kRejectedInvalid,  // a wheel sample that does not determine the body velocity
};

// Its name in reports ("applied", "rejected: too old", ...).
const char* FilterResultName(FilterResult r);

}  // namespace cairn
