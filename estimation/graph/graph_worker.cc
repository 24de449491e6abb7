#include "estimation/graph/graph_worker.h"

namespace cairn {

GraphWorker::GraphWorker(bool own_thread) {
  if (own_thread) thread_ = std::jthread([this](std::stop_token stop) { Run(stop); });
}

GraphWorker::~GraphWorker() {
  if (thread_.joinable()) {
    thread_.request_stop();
    thread_.join();
  }
}

void GraphWorker::Post(std::function<void()> task) {
  {
    std::lock_guard lock(mutex_);
    tasks_.push_back(std::move(task));
  }
  wake_.notify_one();
}

void GraphWorker::Run(std::stop_token stop) {
  for (;;) {
    std::function<void()> task;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, stop, [&] { return !tasks_.empty(); });
      if (tasks_.empty()) return;
      task = std::move(tasks_.front());
      tasks_.pop_front();
    }
    task();
  }
}

}  // namespace cairn
