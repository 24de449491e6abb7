// Highway version of the interior of DisparityFilter::Median3x3: the same odd-even transposition
// sort of the 9 neighbours and the same pick, 8 or 16 pixels at a time (runtime dispatch).

#include <cstddef>
#include <cstdint>

#include "stereo/stereo_matcher_interface.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "stereo/disparity_filter_simd.cc"
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"

HWY_BEFORE_NAMESPACE();
namespace cairn {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Pixels x in [x0, x1) of one interior row (u, c, d: the rows above, at and below); returns the
// first x not done (the caller finishes the rest with the scalar loop).
static int MedianRowSimd(const int16_t* u, const int16_t* c, const int16_t* d, int16_t* o, int x0,
                         int x1) {
  const hn::ScalableTag<int16_t> di;
  using V = hn::Vec<decltype(di)>;
  const int n = static_cast<int>(hn::Lanes(di));
  const V invalid = hn::Set(di, kInvalidDisparity);
  const auto sort2 = [](V& a, V& b) {
    const V lo = hn::Min(a, b);
    b = hn::Max(a, b);
    a = lo;
  };
  int x = x0;
  for (; x + n <= x1; x += n) {
    V p0 = hn::LoadU(di, u + x - 1), p1 = hn::LoadU(di, u + x), p2 = hn::LoadU(di, u + x + 1);
    V p3 = hn::LoadU(di, c + x - 1), p4 = hn::LoadU(di, c + x), p5 = hn::LoadU(di, c + x + 1);
    V p6 = hn::LoadU(di, d + x - 1), p7 = hn::LoadU(di, d + x), p8 = hn::LoadU(di, d + x + 1);
    const V centre = p4;
    for (int round = 0; round < 4; ++round) {
      sort2(p0, p1); sort2(p2, p3); sort2(p4, p5); sort2(p6, p7);
      sort2(p1, p2); sort2(p3, p4); sort2(p5, p6); sort2(p7, p8);
    }
    sort2(p0, p1); sort2(p2, p3); sort2(p4, p5); sort2(p6, p7);
    // Invalid values are the smallest and come first: the median of the n valid ones sits at
    // invalid + (8 - invalid) / 2. VecFromMask is -1 per invalid lane.
    // (No arrays of vectors: they do not exist on scalable targets.)
    V count = hn::Zero(di);
    const auto add_invalid = [&](V p) {
      count = hn::Sub(count, hn::VecFromMask(di, hn::Eq(p, invalid)));
    };
    add_invalid(p0); add_invalid(p1); add_invalid(p2); add_invalid(p3); add_invalid(p4);
    add_invalid(p5); add_invalid(p6); add_invalid(p7); add_invalid(p8);
    const V at = hn::Add(count, hn::ShiftRight<1>(hn::Sub(hn::Set(di, int16_t{8}), count)));
    V m = p0;
    const auto pick = [&](int j, V p) {
      m = hn::IfThenElse(hn::Eq(at, hn::Set(di, static_cast<int16_t>(j))), p, m);
    };
    pick(1, p1); pick(2, p2); pick(3, p3); pick(4, p4);
    pick(5, p5); pick(6, p6); pick(7, p7); pick(8, p8);
    hn::StoreU(hn::IfThenElse(hn::Eq(centre, invalid), invalid, m), di, o + x);
  }
  return x;
}

}  // namespace HWY_NAMESPACE
}  // namespace cairn
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace cairn {

HWY_EXPORT(MedianRowSimd);

// Declared in disparity_filter.cc.
int MedianInteriorRow(const int16_t* u, const int16_t* c, const int16_t* d, int16_t* o, int x0,
                      int x1);
int MedianInteriorRow(const int16_t* u, const int16_t* c, const int16_t* d, int16_t* o, int x0,
                      int x1) {
  return HWY_DYNAMIC_DISPATCH(MedianRowSimd)(u, c, d, o, x0, x1);
}

}  // namespace cairn
#endif  // HWY_ONCE
