#pragma once
// Small dense kernels of the local reference filter (internal). The products have one long
// dimension (the 72 clone rows) and short others, where Eigen's fixed-size product paths spend
// much of their time on packing or scalar code. Written with GCC/Clang vector extensions, so they
// vectorize on every target (SSE2, NEON) without ISA-specific flags; on x86-64 the main ones are
// also built for AVX2 and picked at load time.

#include "common/sanitizers.h"

namespace cairn::kernels {

// Two and four doubles (the latter lowered to pairs of two-double operations where AVX2 is not
// available), accessed in place through unaligned, aliasing types. Never passed by value: that
// would change the ABI between the two builds of a CAIRN_WIDE_KERNEL.
typedef double V2u __attribute__((vector_size(16), aligned(8), may_alias));
typedef double V4u __attribute__((vector_size(32), aligned(8), may_alias));
// By lane count (as a template argument a typedef would lose its attributes).
template <int Lanes> struct Unaligned;
template <> struct Unaligned<1> { using type = double; };
template <> struct Unaligned<2> { using type = V2u; };
template <> struct Unaligned<4> { using type = V4u; };

// A kernel compiled for AVX2 and for the baseline ISA, chosen once at load time by the CPU: the
// result does not depend on the path taken (no FMA: the same operations, lane by lane).
// ThreadSanitizer builds go without: the loader runs the resolvers before the sanitizer's runtime
// is set up, and the instrumented resolvers crash (as in sim/simd_clones.h).
#if defined(__x86_64__) && defined(__linux__) && defined(__GNUC__) && !defined(__clang__) && \
    !CAIRN_THREAD_SANITIZER
#define CAIRN_WIDE_KERNEL __attribute__((target_clones("avx2", "default")))
#else
#define CAIRN_WIDE_KERNEL
#endif

enum Mode { kSet, kAdd, kSub };

namespace detail {

// Rows i .. i + Lanes - 1 of the product (in the order of the scalar tail: same rounding).
template <int Lanes, int Inner, int K, Mode kMode>
[[gnu::always_inline]] inline void MulRowsAt(double* R, int ldr, const double* A, int lda, const double* B,
                                             int ldb, int i) {
  using T = typename Unaligned<Lanes>::type;
  T acc[K];
  {
    const T a = *reinterpret_cast<const T*>(A + i);
    for (int k = 0; k < K; ++k) acc[k] = a * B[k * ldb];
  }
  for (int c = 1; c < Inner; ++c) {
    const T a = *reinterpret_cast<const T*>(A + c * lda + i);
    for (int k = 0; k < K; ++k) acc[k] += a * B[c + k * ldb];
  }
  for (int k = 0; k < K; ++k) {
    T* r = reinterpret_cast<T*>(R + k * ldr + i);
    if constexpr (kMode == kSet) {
      *r = acc[k];
    } else if constexpr (kMode == kAdd) {
      *r += acc[k];
    } else {
      *r -= acc[k];
    }
  }
}

}  // namespace detail

// R (rows x K) =, += or -= A (rows x Inner) * B (Inner x K). All column-major with leading
// dimensions lda, ldb, ldr; R must not overlap A or B. Internal linkage: target_clones makes one
// dispatched copy per translation unit.
template <int Inner, int K, Mode kMode>
CAIRN_WIDE_KERNEL static void MulRows(double* R, int ldr, const double* A, int lda, int rows, const double* B,
                                      int ldb) {
  // B copied to a local, packed table: R is accessed through an aliasing type, so B's elements
  // would otherwise be reloaded through their strided addresses (kept in spilled registers).
  double b[Inner * K];
  for (int k = 0; k < K; ++k) {
    for (int c = 0; c < Inner; ++c) b[c + k * Inner] = B[c + k * ldb];
  }
  int i = 0;
  for (; i + 4 <= rows; i += 4) detail::MulRowsAt<4, Inner, K, kMode>(R, ldr, A, lda, b, Inner, i);
  for (; i + 2 <= rows; i += 2) detail::MulRowsAt<2, Inner, K, kMode>(R, ldr, A, lda, b, Inner, i);
  for (; i < rows; ++i) detail::MulRowsAt<1, Inner, K, kMode>(R, ldr, A, lda, b, Inner, i);
}

// The same with K split into chunks of at most 6 columns (keeps the accumulators in registers).
template <int Inner, int K, Mode kMode>
static void MulRowsWide(double* R, int ldr, const double* A, int lda, int rows, const double* B, int ldb) {
  constexpr int kChunk = K % 6 == 0 ? 6 : (K % 5 == 0 ? 5 : (K < 6 ? K : 4));
  static_assert(K % kChunk == 0);
  for (int k0 = 0; k0 < K; k0 += kChunk) {
    MulRows<Inner, kChunk, kMode>(R + k0 * ldr, ldr, A, lda, rows, B + k0 * ldb, ldb);
  }
}

}  // namespace cairn::kernels
