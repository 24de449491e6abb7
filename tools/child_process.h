#pragma once
// A program a tool runs next to itself (a load generator, a reference measurement, a daemon):
// started with its output appended to a log file, signalled, waited for. A child still running
// when the object goes away is killed and reaped, so a failing tool leaves no load behind.

#include <sys/types.h>

#include <string>
#include <vector>

#include "common/status.h"

namespace cairn::tools {

class ChildProcess {
 public:
  ChildProcess() = default;
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  // Runs argv[0] (looked up on PATH when it has no '/') with stdout and stderr appended to
  // log_path. Fails, naming the program, when it cannot be started.
  Status Start(const std::vector<std::string>& argv, const std::string& log_path);
  // True until the child has exited (and been reaped).
  bool Running();
  // Sends `signal` to a running child; nothing otherwise.
  void Signal(int signal);
  // Waits for the exit: the exit code, 128 + signal number if a signal ended it, -1 if never
  // started. A second call returns the same value.
  int Wait();
  pid_t pid() const { return pid_; }

 private:
  void Reaped(int wait_status);

  pid_t pid_ = -1;
  bool exited_ = false;
  int exit_code_ = -1;
};

// Whether `program` can be run: an executable path, or a name found on PATH.
bool ProgramAvailable(const std::string& program);

}  // namespace cairn::tools
