#include "particles/ParallelFor.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

#include "particles/PhaseProfile.h"
#include "particles/TaskExecutor.h"

namespace tickfx {
namespace {

// The executor of the system this thread is ticking. Thread-local, not a global: two systems
// driven from two host threads may use different executors.
thread_local TaskExecutor* tExecutor = nullptr;

#if defined(__SANITIZE_THREAD__)
#define TICKFX_THREAD_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define TICKFX_THREAD_SANITIZER 1
#endif
#endif

#ifdef TICKFX_THREAD_SANITIZER
// ThreadSanitizer cannot see the synchronisation inside Debian's libtbb, which is not
// instrumented: a correct ten-line tbb::parallel_for reports dozens of races. Its builds hand the
// blocks to plain threads instead, as many as the calling thread's TBB arena allows, forked and
// joined around each loop: every kernel, every block and every thread count stays as in any other
// build, and the race detector checks the kernels' own reads and writes (the gather-only rule).
void runBlocks(std::size_t blocks, const std::function<void(std::size_t)>& block) {
  const auto arenaThreads = static_cast<std::size_t>(tbb::this_task_arena::max_concurrency());
  const std::size_t threads = std::clamp<std::size_t>(arenaThreads, 1, blocks);
  std::atomic<std::size_t> next{0};
  const auto work = [&] {
    for (std::size_t b = next.fetch_add(1, std::memory_order_relaxed); b < blocks;
         b = next.fetch_add(1, std::memory_order_relaxed))
      block(b);
  };
  std::vector<std::thread> helpers;
  for (std::size_t t = 1; t < threads; ++t) helpers.emplace_back(work);
  work();
  for (std::thread& t : helpers) t.join();
}
#else
void runBlocks(std::size_t blocks, const std::function<void(std::size_t)>& block) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks, 1),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t b = range.begin(); b != range.end(); ++b) block(b);
                    });
}
#endif

}  // namespace

ExecutorScope::ExecutorScope(TaskExecutor* executor) : previous_(tExecutor) {
  tExecutor = executor;
}

ExecutorScope::~ExecutorScope() { tExecutor = previous_; }

void parallelForRows(std::size_t rows, const std::function<void(std::size_t, std::size_t)>& body) {
  const std::size_t blocks = (rows + kParallelBlockRows - 1) / kParallelBlockRows;
  if (blocks <= 1) {
    if (rows > 0) body(0, rows);
    return;
  }
  parallelForTasks(blocks, [&](std::size_t b) {
    const std::size_t begin = b * kParallelBlockRows;
    body(begin, std::min(rows, begin + kParallelBlockRows));
  });
}

void parallelForTasks(std::size_t tasks, const std::function<void(std::size_t)>& task) {
  if (tasks <= 1) {
    if (tasks == 1) task(0);
    return;
  }
  const profile::ParallelScope parallel;
  if (tExecutor != nullptr) {
    tExecutor->run(tasks, task);
    return;
  }
  runBlocks(tasks, task);
}

}  // namespace tickfx
