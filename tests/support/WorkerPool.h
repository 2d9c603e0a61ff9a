// A host's job system for tests: the executor a game engine or a DCC would hand tickfx.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "particles/TaskExecutor.h"

namespace tickfx {

// A host's job system with `workers` threads of its own, taking task indices from a counter: the
// order in which blocks run differs from run to run.
class WorkerPool final : public TaskExecutor {
 public:
  explicit WorkerPool(int workers) {
    for (int w = 0; w < workers; ++w) threads_.emplace_back([this] { work(); });
  }
  ~WorkerPool() override {
    {
      const std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : threads_) t.join();
  }
  void run(std::size_t count, const std::function<void(std::size_t)>& task) override {
    std::unique_lock lock(mutex_);
    task_ = &task;
    count_ = count;
    next_ = 0;
    done_ = 0;
    ++generation_;
    wake_.notify_all();
    finished_.wait(lock, [&] { return done_ == count_; });
    task_ = nullptr;
    tasks_ += count;
  }
  std::size_t tasksRun() const { return tasks_; }

 private:
  void work() {
    std::uint64_t seen = 0;
    std::unique_lock lock(mutex_);
    for (;;) {
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      while (task_ != nullptr && next_ < count_) {
        const std::size_t i = next_++;
        const auto* task = task_;
        lock.unlock();
        (*task)(i);
        lock.lock();
        if (++done_ == count_) finished_.notify_one();
      }
    }
  }
  std::mutex mutex_;
  std::condition_variable wake_, finished_;
  std::vector<std::thread> threads_;
  const std::function<void(std::size_t)>* task_ = nullptr;
  std::size_t count_ = 0, next_ = 0, done_ = 0, tasks_ = 0;
  std::uint64_t generation_ = 0;
  bool stop_ = false;
};

}  // namespace tickfx
