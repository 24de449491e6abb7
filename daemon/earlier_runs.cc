#include "daemon/earlier_runs.h"

#include <algorithm>
#include <filesystem>
#include <system_error>

namespace cairn {
namespace {

namespace fs = std::filesystem;

// The number a run folder is named by, or -1 for anything else.
long RunNumber(const fs::path& p) {
  const std::string name = p.filename().string();
  if (name.empty() || name.size() > 9 || !std::all_of(name.begin(), name.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return -1;
  }
  return std::stol(name);
}

// The entries of `dir`, or an error naming it (never an exception).
Expected<std::vector<fs::path>> List(const fs::path& dir) {
  std::vector<fs::path> out;
  std::error_code ec;
  fs::directory_iterator it(dir, ec);
  for (; !ec && it != fs::directory_iterator(); it.increment(ec)) out.push_back(it->path());
  if (ec) return IoError(dir.string() + ": cannot list it: " + ec.message());
  return out;
}

// Whether `q` is `p` or lies inside it.
bool Holds(const fs::path& p, const fs::path& q) {
  std::error_code ec;
  const fs::path a = fs::weakly_canonical(p, ec);
  const fs::path b = fs::weakly_canonical(q, ec);
  auto [ai, bi] = std::mismatch(a.begin(), a.end(), b.begin(), b.end());
  return ai == a.end();
}

}  // namespace

Expected<EarlierRunsReport> EarlierRuns::Keep(const std::string& dir, int keep,
                                              const std::vector<std::string>& persistent) {
  EarlierRunsReport report;
  std::error_code ec;
  if (!fs::exists(dir, ec)) return report;
  if (!fs::is_directory(dir, ec)) return IoError(dir + ": the output folder is not a folder");
  const fs::path runs = fs::path(dir) / kFolder;

  auto listed = List(dir);
  if (!listed.ok()) return listed.status();
  std::vector<fs::path> entries;
  for (const fs::path& p : *listed) {
    if (p.filename() == kFolder) continue;
    if (std::any_of(persistent.begin(), persistent.end(), [&](const std::string& q) { return Holds(p, q); })) {
      continue;
    }
    entries.push_back(p);
  }

  std::vector<long> numbers;
  if (fs::is_directory(runs, ec)) {
    auto earlier = List(runs);
    if (!earlier.ok()) return earlier.status();
    for (const fs::path& p : *earlier) {
      const long n = RunNumber(p);
      if (n >= 0) numbers.push_back(n);
    }
  }
  std::sort(numbers.begin(), numbers.end());

  if (!entries.empty()) {
    const long next = numbers.empty() ? 1 : numbers.back() + 1;
    const fs::path target = runs / std::to_string(next);
    fs::create_directories(target, ec);
    if (ec) return IoError(target.string() + ": cannot create the folder for the earlier run: " + ec.message());
    for (const fs::path& p : entries) {
      fs::rename(p, target / p.filename(), ec);
      if (ec) return IoError(p.string() + ": cannot move it to " + target.string() + ": " + ec.message());
      ++report.moved_entries;
    }
    report.kept_in = target.string();
    numbers.push_back(next);
  }

  for (size_t i = 0; i + static_cast<size_t>(std::max(keep, 0)) < numbers.size(); ++i) {
    const fs::path old = runs / std::to_string(numbers[i]);
    fs::remove_all(old, ec);
    if (ec) return IoError(old.string() + ": cannot remove an earlier run: " + ec.message());
    ++report.removed_runs;
    if (report.kept_in == old.string()) report.kept_in.clear();
  }
  return report;
}

}  // namespace cairn
