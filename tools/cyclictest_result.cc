#include "tools/cyclictest_result.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "common/json_value.h"

namespace cairn::tools {

Expected<CyclictestResult> CyclictestReader::Read(const std::string& path) {
  std::ifstream in(path);
  if (!in) return NotFoundError(path + ": cannot open cyclictest's JSON result");
  std::stringstream text;
  text << in.rdbuf();
  return Parse(text.str(), path);
}

Expected<CyclictestResult> CyclictestReader::Parse(const std::string& json_text, const std::string& source_name) {
  // JsonValue reports malformed text by throwing; this is a tool's boundary, not a real-time path.
  try {
    const JsonValue root = JsonValue::Parse(json_text);
    if (!root.has("thread") || !root["thread"].has("0")) {
      return DataLossError(source_name + ": no thread 0 in cyclictest's result");
    }
    const JsonValue& t = root["thread"]["0"];
    for (const char* key : {"histogram", "cycles", "max"}) {
      if (!t.has(key)) return DataLossError(source_name + ": thread 0 has no \"" + key + "\" (run cyclictest with -h)");
    }
    CyclictestResult r;
    r.cycles = static_cast<uint64_t>(t["cycles"].number());
    r.max_us = t["max"].number();
    std::vector<std::pair<double, uint64_t>> buckets;  // latency in us, count
    uint64_t counted = 0;
    for (const auto& [key, count] : t["histogram"].object()) {
      char* end = nullptr;
      const double us = std::strtod(key.c_str(), &end);
      if (key.empty() || *end != '\0' || !std::isfinite(us) || us < 0.0 || count.number() < 0.0) {
        return DataLossError(source_name + ": histogram bucket \"" + key + "\" is not a latency in us");
      }
      buckets.emplace_back(us, static_cast<uint64_t>(count.number()));
      counted += buckets.back().second;
    }
    if (r.cycles == 0) return DataLossError(source_name + ": cyclictest ran no cycle");
    std::sort(buckets.begin(), buckets.end());
    // Cycles beyond the histogram's range are not in it: they sit above its last bucket, at max.
    if (counted < r.cycles) buckets.emplace_back(r.max_us, r.cycles - counted);
    const auto quantile = [&](double q) {
      const uint64_t rank = std::max<uint64_t>(1, static_cast<uint64_t>(std::ceil(q * static_cast<double>(r.cycles))));
      uint64_t seen = 0;
      for (const auto& [us, n] : buckets) {
        seen += n;
        if (seen >= rank) return us;
      }
      return r.max_us;
    };
    r.median_us = quantile(0.5);
    r.p999_us = quantile(0.999);
    for (const auto& [us, n] : buckets) {
      if (us > 1000.0) r.over_1ms += n;
    }
    return r;
  } catch (const std::exception& e) {
    return DataLossError(source_name + ": " + e.what());
  }
}

}  // namespace cairn::tools
