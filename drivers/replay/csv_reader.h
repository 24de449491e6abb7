#pragma once
// Numeric CSV rows as in EuRoC/ASL files: '#' comment lines, comma separated, CR tolerated. Every
// malformed row is reported with file and line instead of being skipped, because a silently
// shortened sensor stream is worse than no replay.

#include <cstdint>
#include <string>
#include <vector>

#include "common/status.h"

namespace cairn {

struct CsvRow {
  int line = 0;                      // 1-based line in the file
  std::vector<std::string> fields;   // trimmed
};

class CsvReader {
 public:
  // Reads every non-comment, non-blank row; each must have exactly `fields` fields.
  static Expected<std::vector<CsvRow>> ReadAll(const std::string& path, size_t fields);
  // Parses a field as a signed 64-bit integer / finite double, or returns an error naming
  // path:line and the column.
  static Expected<int64_t> Int(const std::string& path, const CsvRow& row, size_t column);
  static Expected<double> Double(const std::string& path, const CsvRow& row, size_t column);
};

}  // namespace cairn
