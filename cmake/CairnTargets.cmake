# Project-wide target helpers: warnings, include roots, tests.

function(cairn_warnings target)
  target_compile_options(${target} PRIVATE
    -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Woverloaded-virtual
    -Wcast-align -Wmissing-declarations -Wimplicit-fallthrough)
  # GCC 12 reports -Wrestrict false positives inside libstdc++'s std::string operator+ at -O2/-O3
  # (GCC bug 105329); the warning stays on for other compilers.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    target_compile_options(${target} PRIVATE -Wno-restrict)
    # With the standard headers precompiled, GCC 12 no longer treats code inlined from them as
    # system-header code, and reports the same family of false positives (bug 105329) as
    # -Warray-bounds inside std::string's operator+. Sanitizer builds only; ASan checks bounds.
    if(CAIRN_PCH)
      target_compile_options(${target} PRIVATE -Wno-array-bounds -Wno-stringop-overflow -Wno-stringop-overread)
    endif()
  endif()
endfunction()

# Precompiled headers (CAIRN_PCH, on in the sanitizer presets, which CI builds from scratch): the
# standard library, Eigen's Core and Geometry and, for tests, GoogleTest are parsed once per build
# instead of once per file. Builds without it (release, cross) keep every file's own includes
# honest. cairn_define_pch() makes the two header-only targets the others reuse.
# The same presets also build in unity batches of eight files (CMAKE_UNITY_BUILD), which parse
# Ceres', OpenCV's and GoogleTest's headers once per batch: names local to a file (anonymous
# namespaces) must therefore be unique within their target; shared constants live in headers.
function(cairn_define_pch)
  if(NOT CAIRN_PCH)
    return()
  endif()
  set(common <algorithm> <array> <atomic> <chrono> <cmath> <cstdint> <cstring> <functional> <map>
             <memory> <mutex> <optional> <string> <string_view> <thread> <unordered_map> <utility>
             <variant> <vector> <Eigen/Core> <Eigen/Geometry>)
  add_library(cairn_pch STATIC ${PROJECT_SOURCE_DIR}/cmake/pch_anchor.cc)
  target_link_libraries(cairn_pch PRIVATE Eigen3::Eigen)
  target_precompile_headers(cairn_pch PRIVATE ${common})
  cairn_warnings(cairn_pch)
  if(TARGET GTest::gtest)
    add_library(cairn_test_pch STATIC ${PROJECT_SOURCE_DIR}/cmake/pch_anchor.cc)
    target_link_libraries(cairn_test_pch PRIVATE Eigen3::Eigen GTest::gtest)
    target_precompile_headers(cairn_test_pch PRIVATE ${common} <gtest/gtest.h>)
    cairn_warnings(cairn_test_pch)
  endif()
endfunction()

# Executables that run real-time threads (cairnd, and cairn for its benchmarks) resolve every
# dynamically linked symbol at start-up: a lazily bound first call costs tens of microseconds
# inside a deadline (the first relative-pose update of `cairn bench filter` was its slowest).
function(cairn_bind_now target)
  target_link_options(${target} PRIVATE -Wl,-z,now -Wl,-z,relro)
endfunction()

function(cairn_use_pch target pch)
  if(CAIRN_PCH AND TARGET ${pch})
    target_precompile_headers(${target} REUSE_FROM ${pch})
  endif()
endfunction()

# cairn_library(NAME SOURCES ... DEPS ...): a library rooted at the source tree so that includes
# read "common/timestamp.h".
function(cairn_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} ${ARG_SOURCES})
  add_library(cairn::${name} ALIAS ${name})
  target_include_directories(${name} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>)
  target_link_libraries(${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  cairn_warnings(${name})
  cairn_use_pch(${name} cairn_pch)
endfunction()

# cairn_test(NAME SOURCES ... DEPS ... [LABELS ...] [TIMEOUT s] [COST s]): one GoogleTest binary,
# each TEST a ctest entry. Tests find the shared data through CAIRN_DATA_DIR and skip, naming the
# path, when it is missing. COST, the longest test's seconds under the sanitizers, lets a fresh
# clone (no timings of an earlier run) start the long tests first instead of last, alone.
function(cairn_test name)
  if(NOT CAIRN_BUILD_TESTS OR CAIRN_PORTABLE_CORE_ONLY)
    return()
  endif()
  cmake_parse_arguments(ARG "" "TIMEOUT;COST" "SOURCES;DEPS;LABELS" ${ARGN})
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  if(NOT ARG_COST)
    set(ARG_COST 0)
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gmock GTest::gtest_main)
  target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR})
  # Fallbacks for running a test binary by hand; ctest also sets CAIRN_DATA_DIR.
  target_compile_definitions(${name} PRIVATE
    CAIRN_TEST_DATA_DIR="${CAIRN_DATA_DIR}"
    CAIRN_TEST_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    CAIRN_TEST_BINARY_DIR="${PROJECT_BINARY_DIR}")
  cairn_warnings(${name})
  cairn_use_pch(${name} cairn_test_pch)
  if("concurrency" IN_LIST ARG_LABELS)
    add_dependencies(concurrency_tests ${name})
  endif()
  set(labels unit)
  if(ARG_LABELS)
    set(labels ${ARG_LABELS})
  endif()
  string(REPLACE ";" "\\;" labels "${labels}")
  gtest_discover_tests(${name}
    DISCOVERY_MODE PRE_TEST
    PROPERTIES
      LABELS "${labels}"
      TIMEOUT ${ARG_TIMEOUT}
      COST ${ARG_COST}
      ENVIRONMENT "CAIRN_DATA_DIR=${CAIRN_DATA_DIR}")
endfunction()

# Tests labelled "concurrency" also run under ThreadSanitizer (the tsan preset builds only them).
if(NOT TARGET concurrency_tests)
  add_custom_target(concurrency_tests)
endif()

# Generated sources of `target` (everything outside the source tree or inside the build tree:
# Verilator's model and runtime, protoc's output) are compiled without the sanitizers of a
# CAIRN_SANITIZER build. It is not our code to fix, its instrumentation was a tenth of the
# sanitizer builds' compile time, and the cosimulation tests spend their time in it. Our code
# that calls it stays instrumented.
function(cairn_generated_without_sanitizers target)
  if(NOT CAIRN_SANITIZER)
    return()
  endif()
  get_target_property(sources ${target} SOURCES)
  foreach(src IN LISTS sources)
    cmake_path(ABSOLUTE_PATH src BASE_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR} NORMALIZE OUTPUT_VARIABLE abs)
    cmake_path(IS_PREFIX PROJECT_SOURCE_DIR "${abs}" NORMALIZE in_tree)
    # The presets' build folders lie inside the source tree; what is generated there is not ours.
    cmake_path(IS_PREFIX PROJECT_BINARY_DIR "${abs}" NORMALIZE in_build)
    if((NOT in_tree OR in_build) AND abs MATCHES "\\.(c|cc|cpp|cxx)$")
      set_property(SOURCE ${src} TARGET_DIRECTORY ${target} APPEND PROPERTY COMPILE_OPTIONS -fno-sanitize=all)
    endif()
  endforeach()
endfunction()
