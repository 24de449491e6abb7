#include "drivers/replay/csv_reader.h"

#include <charconv>
#include <cmath>
#include <fstream>

namespace cairn {
namespace {

std::string Trim(const std::string& s) {
  size_t b = 0, e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t' || s[b] == '\r')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t' || s[e - 1] == '\r')) --e;
  return s.substr(b, e - b);
}

std::string At(const std::string& path, const CsvRow& row) {
  return path + ":" + std::to_string(row.line);
}

}  // namespace

Expected<std::vector<CsvRow>> CsvReader::ReadAll(const std::string& path, size_t fields) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return NotFoundError(path + ": cannot open");
  std::vector<CsvRow> rows;
  std::string line;
  int number = 0;
  bool last_line_had_newline = true;
  while (std::getline(in, line)) {
    ++number;
    last_line_had_newline = !in.eof();
    const std::string t = Trim(line);
    if (t.empty() || t[0] == '#') continue;
    CsvRow row;
    row.line = number;
    size_t start = 0;
    while (true) {
      const size_t comma = t.find(',', start);
      row.fields.push_back(Trim(t.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (row.fields.size() != fields) {
      return DataLossError(At(path, row) + ": expected " + std::to_string(fields) +
                           " comma-separated fields, found " + std::to_string(row.fields.size()) +
                           (last_line_had_newline ? "" : " (the file looks truncated)"));
    }
    rows.push_back(std::move(row));
  }
  if (in.bad()) return IoError(path + ": read failed");
  return rows;
}

Expected<int64_t> CsvReader::Int(const std::string& path, const CsvRow& row, size_t column) {
  const std::string& f = row.fields.at(column);
  int64_t v = 0;
  const auto [ptr, ec] = std::from_chars(f.data(), f.data() + f.size(), v);
  if (ec != std::errc() || ptr != f.data() + f.size()) {
    return DataLossError(At(path, row) + ": column " + std::to_string(column + 1) + " '" + f +
                         "' is not an integer");
  }
  return v;
}

Expected<double> CsvReader::Double(const std::string& path, const CsvRow& row, size_t column) {
  const std::string& f = row.fields.at(column);
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(f.data(), f.data() + f.size(), v);
  if (ec != std::errc() || ptr != f.data() + f.size() || !std::isfinite(v)) {
    return DataLossError(At(path, row) + ": column " + std::to_string(column + 1) + " '" + f +
                         "' is not a finite number");
  }
  return v;
}

}  // namespace cairn
