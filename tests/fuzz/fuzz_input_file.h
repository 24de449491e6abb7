#pragma once
// Decoders that read files get the fuzzer's bytes through one file per process, rewritten for
// every input.

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

namespace cairn::fuzz {

inline std::string WriteInputFile(const uint8_t* data, size_t size, const char* extension) {
  static const std::string path = "/tmp/cairn_fuzz_" + std::to_string(getpid()) + extension;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return path;
  if (size > 0) std::fwrite(data, 1, size, f);
  std::fclose(f);
  return path;
}

}  // namespace cairn::fuzz
