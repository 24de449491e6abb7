#pragma once

#include "common/sanitizers.h"

// CAIRN_SIM_CLONES marks the simulator's hot loops for compilation twice, for the x86-64 baseline
// (SSE2) and for AVX2, the dynamic loader picking the version the CPU runs. "avx2" does not enable
// fused multiply-add, so both versions perform the same IEEE operations in the same order and
// compute identical bits: rendered images do not depend on the machine that renders them.
//
// It belongs on function definitions only: on a declaration in a header, every caller's object
// file would emit its own resolver for clones that are local to the defining one. ThreadSanitizer
// builds go without: the loader runs the resolvers before the sanitizer's runtime is set up, and
// the instrumented resolvers crash.

#if defined(__x86_64__) && defined(__linux__) && defined(__GNUC__) && !defined(__clang__) && \
    !CAIRN_THREAD_SANITIZER
#define CAIRN_SIM_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define CAIRN_SIM_CLONES
#endif
