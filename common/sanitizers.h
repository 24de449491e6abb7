#pragma once

// CAIRN_ADDRESS_SANITIZER / CAIRN_THREAD_SANITIZER are 1 in builds instrumented by that sanitizer.
// GCC says so through __SANITIZE_*__, Clang only through __has_feature; code that must behave
// differently under a sanitizer (no mlockall of the shadow memory, no ifunc resolvers before the
// runtime is up) asks these instead of either compiler's spelling.

#if defined(__SANITIZE_ADDRESS__)
#define CAIRN_ADDRESS_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CAIRN_ADDRESS_SANITIZER 1
#endif
#endif
#ifndef CAIRN_ADDRESS_SANITIZER
#define CAIRN_ADDRESS_SANITIZER 0
#endif

#if defined(__SANITIZE_THREAD__)
#define CAIRN_THREAD_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define CAIRN_THREAD_SANITIZER 1
#endif
#endif
#ifndef CAIRN_THREAD_SANITIZER
#define CAIRN_THREAD_SANITIZER 0
#endif
