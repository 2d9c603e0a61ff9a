// The ThreadSanitizer stage's control (scripts/test): a kernel that breaks the gather-only rule,
// each block also writing the first row of the next, run through parallelForRows() on 4 threads.
// ThreadSanitizer must report it, or the stage's passing tests prove nothing; the stage fails
// unless this program's output holds a data race report.
//
// The race is only seen when two neighbouring blocks run on two threads at once: on a loaded
// 2-core machine the calling thread can finish all eight tiny blocks before a helper thread has
// started (seen in CI), and ThreadSanitizer may miss the race when one thread has run all its
// blocks and ended before the other wrote (seen on one core). So each thread's first block starts
// only when a second thread has taken a block, and ends only when the other's first block has
// written too: two neighbouring blocks always write on two live threads.
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <thread>
#include <vector>

#include "particles/ParallelFor.h"

namespace {

// Waits, up to 5 s, until `count` reaches 2. Relaxed: an acquire would order one thread's writes
// after the other's for ThreadSanitizer and hide the race this program is here to show.
void waitUntilTwo(const std::atomic<int>& count) {
  const auto giveUp = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (count.load(std::memory_order_relaxed) < 2 && std::chrono::steady_clock::now() < giveUp)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

}  // namespace

int main() {
  std::vector<float> rows(8 * tickfx::kParallelBlockRows, 0.0f);
  std::atomic<int> started{0};
  std::atomic<int> finished{0};
  tbb::task_arena arena(4);
  arena.execute([&] {
    tickfx::parallelForRows(rows.size(), [&](std::size_t begin, std::size_t end) {
      thread_local bool first = true;
      if (first) {
        started.fetch_add(1, std::memory_order_relaxed);
        waitUntilTwo(started);
      }
      for (std::size_t i = begin; i < end; ++i) rows[i] += 1.0f;
      if (end < rows.size()) rows[end] += 1.0f;  // a scatter into the next block's first row
      if (first) {
        first = false;
        finished.fetch_add(1, std::memory_order_relaxed);
        waitUntilTwo(finished);
      }
    });
  });
  std::printf("%d threads\n", started.load(std::memory_order_relaxed));
  return 0;
}
