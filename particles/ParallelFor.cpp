#include "particles/ParallelFor.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <algorithm>

#include "particles/TaskExecutor.h"

namespace tickfx {
namespace {

// The executor of the system this thread is ticking. Thread-local, not a global: two systems
// driven from two host threads may use different executors.
thread_local TaskExecutor* tExecutor = nullptr;

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
  auto block = [&](std::size_t b) {
    const std::size_t begin = b * kParallelBlockRows;
    body(begin, std::min(rows, begin + kParallelBlockRows));
  };
  if (tExecutor != nullptr) {
    tExecutor->run(blocks, block);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks, 1),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t b = range.begin(); b != range.end(); ++b) block(b);
                    });
}

}  // namespace tickfx
