#pragma once
// Decoders that read files get the fuzzer's bytes through one file per process, rewritten for
// every input and removed when the fuzzer exits (libFuzzer ends with exit(); after a crash the
// file stays, next to libFuzzer's own copy of the input).

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace cairn::fuzz {

inline std::string WriteInputFile(const uint8_t* data, size_t size, const char* extension) {
  static const std::string path = "/tmp/cairn_fuzz_" + std::to_string(getpid()) + extension;
  static const bool removed_at_exit = std::atexit([] { std::remove(path.c_str()); }) == 0;
  (void)removed_at_exit;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return path;
  if (size > 0) std::fwrite(data, 1, size, f);
  std::fclose(f);
  return path;
}

}  // namespace cairn::fuzz
