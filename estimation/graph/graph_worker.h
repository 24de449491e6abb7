#pragma once
// Runs posted tasks in order on one thread: the background runner of SlamGraph's full solves.
// Either its own thread (the command-line tools; the destructor finishes the queued tasks and
// joins) or, for the daemon, a thread that an executor starts on Run().

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>

namespace cairn {

class GraphWorker {
 public:
  explicit GraphWorker(bool own_thread = true);
  ~GraphWorker();
  GraphWorker(const GraphWorker&) = delete;
  GraphWorker& operator=(const GraphWorker&) = delete;

  void Post(std::function<void()> task);
  // The worker loop, for an external thread: returns once `stop` is requested and the queue is
  // empty (a posted solve always finishes).
  void Run(std::stop_token stop);
  // A SlamGraph::BackgroundRunner posting to this worker (which must outlive its use).
  std::function<void(std::function<void()>)> Runner() {
    return [this](std::function<void()> task) { Post(std::move(task)); };
  }

 private:
  std::mutex mutex_;
  std::condition_variable_any wake_;
  std::deque<std::function<void()>> tasks_;
  std::jthread thread_;  // last: starts after the members it uses exist
};

}  // namespace cairn
