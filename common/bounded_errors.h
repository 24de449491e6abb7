#pragma once
// The errors a stage keeps for its report: the first few, so that a teammate or a device that keeps
// failing the same way cannot grow the report (the counters still count every one).

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace cairn {

inline constexpr size_t kMaxReportedErrors = 10;

// Appends `what` unless kMaxReportedErrors are kept already; returns whether it was kept.
inline bool AppendBoundedError(std::vector<std::string>& errors, std::string what) {
  if (errors.size() >= kMaxReportedErrors) return false;
  errors.push_back(std::move(what));
  return true;
}

}  // namespace cairn
