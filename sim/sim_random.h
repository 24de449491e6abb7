#pragma once
// A small, fully specified random generator (SplitMix64 + Box-Muller) so that simulated bytes do
// not depend on the standard library's distribution implementations.

#include <cmath>
#include <cstdint>
#include <numbers>

namespace cairn::sim {

class SimRandom {
 public:
  explicit SimRandom(uint64_t seed) : state_(seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull) {}
  // Independent stream for a named purpose (robot index, sensor, ...).
  static SimRandom Stream(uint64_t seed, uint64_t a, uint64_t b = 0) {
    return SimRandom(Mix(Mix(seed ^ 0xA0761D6478BD642Full) ^ (a * 0xE7037ED1A0B428DBull) ^
                         (b * 0x8EBC6AF09C88C6E3ull)));
  }
  static uint64_t Mix(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  uint64_t Next() {
    state_ += 0x9E3779B97F4A7C15ull;
    return Mix(state_);
  }
  // Uniform in [0, 1).
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  double Normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = 1.0 - Uniform(), u2 = Uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * std::numbers::pi * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * std::numbers::pi * u2);
  }

 private:
  uint64_t state_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace cairn::sim
