#include "daemon/pipeline/executor.h"

#include "common/sanitizers.h"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <latch>

namespace cairn {
namespace {

// A real-time thread writes this much of its stack once before its body runs: a page first
// written in a deadline-bound step costs a page fault (microseconds each; about 7 us per page
// measured under this machine's hypervisor, even with the process's memory locked).
constexpr size_t kPrefaultStackBytes = 256 * 1024;

[[gnu::noinline]] void PrefaultStack() {
  unsigned char stack[kPrefaultStackBytes];
  std::memset(stack, 0, sizeof(stack));
  asm volatile("" : : "r"(stack) : "memory");  // keeps the writes
}

}  // namespace

Executor::Executor(std::string name, ExecutorOptions options)
    : name_(std::move(name)), options_(std::move(options)) {
  report_.name = name_;
  report_.realtime_requested = options_.realtime;
}

Executor::~Executor() { Join(); }

bool Executor::LockProcessMemory(std::string* why_not) {
#if CAIRN_ADDRESS_SANITIZER || CAIRN_THREAD_SANITIZER
  // Sanitizers reserve terabytes of shadow memory; locking it would exhaust the machine.
  *why_not = "mlockall skipped in a sanitizer build";
  return false;
#else
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    *why_not = std::string("mlockall: ") + std::strerror(errno);
    return false;
  }
  return true;
#endif
}

void Executor::ApplyScheduling() {
  pthread_setname_np(pthread_self(), name_.substr(0, 15).c_str());
  report_.policy = "SCHED_OTHER";
  if (options_.realtime) {
    sched_param p{};
    p.sched_priority = static_cast<int>(options_.priority);
    const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p);
    if (rc == 0) {
      report_.realtime_granted = true;
      report_.policy = "SCHED_FIFO";
      report_.priority = p.sched_priority;
    } else {
      report_.affinity_note = std::string("SCHED_FIFO refused: ") + std::strerror(rc);
    }
  }
  if (!report_.realtime_granted && options_.nice != 0) {
    // Linux applies nice per thread when addressed by thread id.
    if (setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)),
                    static_cast<int>(options_.nice)) != 0) {
      report_.affinity_note += std::string(report_.affinity_note.empty() ? "" : "; ") +
                               "nice refused: " + std::strerror(errno);
    }
  }
  if (!options_.cpus.empty()) {
    cpu_set_t set;
    CPU_ZERO(&set);
    const long online = sysconf(_SC_NPROCESSORS_ONLN);
    int usable = 0;
    for (double c : options_.cpus) {
      if (static_cast<long>(c) < online) {
        CPU_SET(static_cast<int>(c), &set);
        ++usable;
      }
    }
    if (usable == 0) {
      report_.affinity_note += std::string(report_.affinity_note.empty() ? "" : "; ") +
                               "none of the configured CPUs exist; running on any CPU";
    } else if (pthread_setaffinity_np(pthread_self(), sizeof(set), &set) != 0) {
      report_.affinity_note += std::string(report_.affinity_note.empty() ? "" : "; ") +
                               "affinity refused";
    }
  }
}

void Executor::Start(std::function<void(std::stop_token)> body) {
  std::latch ready(1);
  thread_ = std::jthread([this, &ready, body = std::move(body)](std::stop_token stop) {
    ApplyScheduling();
    if (options_.realtime) PrefaultStack();
    ready.count_down();
    body(stop);
    // The thread's own CPU time, for the cost figures in diagnostics.json.
    rusage usage{};
    if (getrusage(RUSAGE_THREAD, &usage) == 0) {
      report_.cpu_seconds = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                            static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-6;
    }
  });
  ready.wait();
}

void Executor::RequestStop() { thread_.request_stop(); }

void Executor::Join() {
  if (thread_.joinable()) thread_.join();
}

}  // namespace cairn
