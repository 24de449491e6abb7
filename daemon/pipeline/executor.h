#pragma once
// A named thread whose scheduling comes from ExecutorOptions. The thread applies its own policy,
// priority, nice value and affinity before running its body, so nothing runs unscheduled.

#include <atomic>
#include <functional>
#include <string>
#include <thread>

#include "daemon/pipeline/executor_options.h"

namespace cairn {

struct ExecutorReport {
  std::string name;
  bool realtime_requested = false;
  bool realtime_granted = false;
  std::string policy;        // "SCHED_FIFO" or "SCHED_OTHER"
  int priority = 0;
  std::string affinity_note; // empty when as requested
  double cpu_seconds = 0.0;  // CPU time the thread used, set when it ends
};

class Executor {
 public:
  Executor(std::string name, ExecutorOptions options);
  ~Executor();
  Executor(const Executor&) = delete;
  Executor& operator=(const Executor&) = delete;

  // Starts the thread; returns once it has applied its scheduling (so report() is final).
  void Start(std::function<void(std::stop_token)> body);
  void RequestStop();
  void Join();

  const ExecutorReport& report() const { return report_; }

  // Locks current and future memory once per process (for realtime executors). Returns false,
  // with the reason, where the system refuses or a sanitizer makes it unsafe.
  static bool LockProcessMemory(std::string* why_not);

 private:
  void ApplyScheduling();

  std::string name_;
  ExecutorOptions options_;
  ExecutorReport report_;
  std::jthread thread_;
};

}  // namespace cairn
