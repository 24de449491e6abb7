#include "daemon/pipeline/latency_histogram.h"

#include <algorithm>
#include <cmath>

namespace cairn {

int LatencyHistogram::Bucket(int64_t us) {
  if (us <= 1) return 0;
  const int b = static_cast<int>(std::ceil(std::log2(static_cast<double>(us)) * kPerOctave));
  return std::min(b, kPerOctave * kOctaves);
}

int64_t LatencyHistogram::UpperEdgeUs(int bucket) {
  return static_cast<int64_t>(std::ceil(std::exp2(static_cast<double>(bucket) / kPerOctave)));
}

void LatencyHistogram::Record(Duration d) {
  const int64_t ns = std::max<int64_t>(0, d.nanoseconds());
  ++buckets_[static_cast<size_t>(Bucket((ns + 999) / 1000))];
  ++count_;
  if (ns > 1'000'000) ++over_1ms_;
  max_ns_ = std::max(max_ns_, ns);
}

Duration LatencyHistogram::Quantile(double q) const {
  if (count_ == 0) return Duration();
  const uint64_t rank = static_cast<uint64_t>(std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(count_)));
  uint64_t seen = 0;
  for (size_t b = 0; b < buckets_.size(); ++b) {
    seen += buckets_[b];
    if (seen >= std::max<uint64_t>(rank, 1)) {
      if (b + 1 == buckets_.size()) return max();  // the overflow bucket has no upper edge
      return std::min(Duration::Microseconds(UpperEdgeUs(static_cast<int>(b))), max());
    }
  }
  return max();
}

}  // namespace cairn
