#pragma once
// Runs a program as a child process for integration tests: captured output, a time limit, and an
// optional signal sent after a delay (to test shutdown paths).

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace cairn::testing {

struct ProcessResult {
  int exit_code = -1;       // -1 when killed by a signal
  int term_signal = 0;      // the signal that ended it, if any
  bool timed_out = false;
  std::string output;       // stdout and stderr interleaved
};

struct ProcessOptions {
  std::chrono::milliseconds timeout{120000};
  // Send `signal` (0 = never) `signal_after` after the start, or after this text first appears
  // in the output when it is not empty.
  int signal = 0;
  std::chrono::milliseconds signal_after{0};
  std::string signal_when_output_contains;
  // Once signalled, send `signal` once more when this text appears in the output after that.
  std::string signal_again_when_output_contains;
  // Extra environment variables ("NAME=value") on top of the test's own environment.
  std::vector<std::string> env;
};

ProcessResult RunProcess(const std::vector<std::string>& argv, const ProcessOptions& options = {});

}  // namespace cairn::testing
