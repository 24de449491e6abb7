#include "stereo/bidirectional_raster_matcher.h"

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "stereo/sgm_matcher.h"

namespace cairn {
namespace {

// Answers each pixel with 10 px plus its left grey value in 1/16 px (so a pass over the flipped
// pair answers from the flipped pixels), plus `offset[call]`; `invalid[call]` pixels (x, y of the
// image that pass saw) come back invalid.
class ScriptedMatcher final : public StereoMatcher {
 public:
  std::string_view name() const override { return "scripted"; }
  Status Match(const StereoMatcherInput& in, StereoMatcherOutput* out) override {
    const int call = calls++;
    if (call == fail_call) return InternalError("scripted failure");
    out->width = in.width;
    out->height = in.height;
    out->disparity.assign(static_cast<size_t>(in.width) * in.height, kInvalidDisparity);
    out->depth.assign(out->disparity.size(), 0.0f);
    out->depth_sigma.assign(out->disparity.size(), 0.0f);
    for (int y = 0; y < in.height; ++y) {
      for (int x = 0; x < in.width; ++x) {
        bool drop = false;
        for (const auto& [ix, iy] : invalid[call]) drop = drop || (ix == x && iy == y);
        if (!drop) {
          out->disparity[static_cast<size_t>(y) * in.width + x] =
              static_cast<int16_t>(160 + in.left[static_cast<size_t>(y) * in.stride + x] + offset[call]);
        }
      }
    }
    return Status::Ok();
  }
  int calls = 0, fail_call = -1;
  int offset[2] = {0, 0};
  std::vector<std::pair<int, int>> invalid[2];
};

struct Pair {
  int w = 6, h = 5, stride = 8;  // rows padded: the flip must honour the stride
  std::vector<uint8_t> l, r;
  Pair() : l(static_cast<size_t>(stride) * h, 255), r(l) {
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) l[static_cast<size_t>(y) * stride + x] = static_cast<uint8_t>(10 * y + x);
    }
  }
  StereoMatcherInput input() const { return {l.data(), r.data(), w, h, stride, 100.0, 0.1, 0.0}; }
};

TEST(BidirectionalRasterMatcherTest, AveragesThePassesRowByRowRoundingHalfToEven) {
  const Pair p;
  ScriptedMatcher inner;
  inner.offset[1] = 3;  // the flipped pass answers 3/16 px more
  BidirectionalRasterMatcher m(inner, 16, 0.5);
  StereoMatcherOutput out;
  ASSERT_TRUE(m.Match(p.input(), &out).ok());
  EXPECT_EQ(inner.calls, 2);
  EXPECT_EQ(m.name(), "scripted-bidirectional");
  for (int y = 0; y < p.h; ++y) {
    for (int x = 0; x < p.w; ++x) {
      // Both passes saw the same pixel (the flipped row h-1-y is row y): d and d + 3, whose mean
      // d + 1.5 rounds to the even neighbour.
      const int d = 160 + 10 * y + x, sum = 2 * d + 3;
      const int expected = (sum / 2) % 2 == 0 ? sum / 2 : sum / 2 + 1;
      ASSERT_EQ(out.disparity_at(x, y), expected) << x << ", " << y;
      const double z = 100.0 * 0.1 / (expected / 16.0);
      EXPECT_NEAR(out.depth[static_cast<size_t>(y) * p.w + x], z, 1e-5);
    }
  }
  EXPECT_EQ(m.last_counts().agreed, p.w * p.h);
}

TEST(BidirectionalRasterMatcherTest, DisagreementInvalidatesAndASinglePassIsKept) {
  const Pair p;
  ScriptedMatcher inner;
  inner.offset[1] = 17;                     // beyond max_diff 16 everywhere...
  inner.invalid[0] = {{1, 1}, {2, 2}};      // ...but here only the flipped pass is valid
  inner.invalid[1] = {{2, 4 - 2}, {3, 4 - 3}};  // (2, 2) invalid in both; (3, 3) only downward
  BidirectionalRasterMatcher m(inner, 16, 0.5);
  StereoMatcherOutput out;
  ASSERT_TRUE(m.Match(p.input(), &out).ok());
  EXPECT_EQ(out.disparity_at(0, 0), kInvalidDisparity);
  EXPECT_EQ(out.disparity_at(1, 1), 160 + 11 + 17);
  EXPECT_EQ(out.disparity_at(2, 2), kInvalidDisparity);
  EXPECT_TRUE(std::isnan(out.depth[2 * p.w + 2]));
  EXPECT_EQ(out.disparity_at(3, 3), 160 + 33);
  EXPECT_EQ(m.last_counts().one_pass, 2);
  EXPECT_EQ(m.last_counts().disagreed, p.w * p.h - 3);
  EXPECT_EQ(m.last_counts().agreed, 0);
}

TEST(BidirectionalRasterMatcherTest, AFailedPassIsReported) {
  const Pair p;
  ScriptedMatcher inner;
  inner.fail_call = 1;
  BidirectionalRasterMatcher m(inner, 16, 0.5);
  StereoMatcherOutput out;
  const Status s = m.Match(p.input(), &out);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.ToString().find("flipped pass"), std::string::npos) << s.ToString();
}

// A textured plane whose disparity grows by `slope` px per row, as the ground ahead of a camera
// does: right(x, y) = left(x + d(y), y), the left texture smooth enough to interpolate.
struct Ramp {
  int w = 320, h = 240;
  double d0 = 12.0, slope = 0.05;
  std::vector<uint8_t> l, r;
  Ramp() {
    std::mt19937 rng(7);
    std::vector<double> noise(static_cast<size_t>(w + 64) * h);
    for (double& v : noise) v = static_cast<double>(rng() % 256);
    const auto tex = [&](double x, int y) {  // 3-tap smoothed noise, linear in x
      const int x0 = static_cast<int>(std::floor(x));
      const double a = x - x0;
      const auto at = [&](int xi) {
        double s = 0.0;
        for (int k = -1; k <= 1; ++k) s += noise[static_cast<size_t>(y) * (w + 64) + std::clamp(xi + k, 0, w + 63)];
        return s / 3.0;
      };
      return (1.0 - a) * at(x0) + a * at(x0 + 1);
    };
    l.resize(static_cast<size_t>(w) * h);
    r.resize(l.size());
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        l[static_cast<size_t>(y) * w + x] = static_cast<uint8_t>(std::lround(tex(x, y)));
        r[static_cast<size_t>(y) * w + x] = static_cast<uint8_t>(std::lround(tex(x + disparity(y), y)));
      }
    }
  }
  double disparity(int y) const { return d0 + slope * y; }
  StereoMatcherInput input() const { return {l.data(), r.data(), w, h, w, 300.0, 0.1, 0.0}; }
  // Mean signed disparity error (px) over valid pixels clear of the borders.
  double MeanError(const StereoMatcherOutput& out, int64_t* valid) const {
    double sum = 0.0;
    *valid = 0;
    for (int y = 8; y < h - 8; ++y) {
      for (int x = 64; x < w - 8; ++x) {
        const int16_t d = out.disparity_at(x, y);
        if (d == kInvalidDisparity) continue;
        sum += d / 16.0 - disparity(y);
        ++*valid;
      }
    }
    return *valid > 0 ? sum / static_cast<double>(*valid) : 0.0;
  }
};

TEST(BidirectionalRasterMatcherTest, CancelsTheRasterPathsBiasOnASlantedPlane) {
  const Ramp ramp;
  SgmOptions o;
  o.raster_paths = true;
  o.num_disparities = 32;
  o.threads = 1;
  auto raster = SgmMatcher::Create(o);
  ASSERT_TRUE(raster.ok()) << raster.status().ToString();
  StereoMatcherOutput single, both;
  ASSERT_TRUE((*raster)->Match(ramp.input(), &single).ok());
  BidirectionalRasterMatcher m(**raster, 16, o.pixel_error_px);
  ASSERT_TRUE(m.Match(ramp.input(), &both).ok());
  int64_t n_single = 0, n_both = 0;
  const double e_single = ramp.MeanError(single, &n_single), e_both = ramp.MeanError(both, &n_both);
  std::printf("mean disparity error: raster paths %.4f px (%ld px), bidirectional %.4f px (%ld px)\n", e_single,
              static_cast<long>(n_single), e_both, static_cast<long>(n_both));
  // Top-down smoothing pulls each row toward the smaller disparities above it.
  EXPECT_LT(e_single, -0.03);
  EXPECT_LT(std::abs(e_both), 0.25 * std::abs(e_single));
  EXPECT_GT(n_both, n_single * 9 / 10);
}

}  // namespace
}  // namespace cairn
