#pragma once
// A small persistent thread pool for per-frame data parallelism: the threads are created once,
// so a frame costs two condition-variable handshakes instead of thread creation.

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

namespace cairn {

class WorkerPool {
 public:
  // `threads` >= 1 counts the calling thread, which also works during Run().
  explicit WorkerPool(int threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  // Calls fn(ctx, i) once for every i in [0, tasks) and returns when all calls have returned.
  void Run(int tasks, void (*fn)(void*, int), void* ctx);

  // Same for a callable taking the task index; no allocation.
  template <class F>
  void ForEach(int tasks, F&& f) {
    Run(tasks, [](void* c, int i) { (*static_cast<std::remove_reference_t<F>*>(c))(i); }, &f);
  }

 private:
  void WorkerLoop();
  void Drain();

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_cv_;
  std::condition_variable done_cv_;
  uint64_t generation_ = 0;
  bool stop_ = false;
  int active_ = 0;  // workers still inside the current generation
  void (*fn_)(void*, int) = nullptr;
  void* ctx_ = nullptr;
  int tasks_ = 0;
  std::atomic<int> next_{0};
};

}  // namespace cairn
