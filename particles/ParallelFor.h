// Per-particle parallel loops whose results cannot depend on the thread count.
#pragma once

#include <cstddef>
#include <functional>

namespace tickfx {

class TaskExecutor;

/// Rows per block. Blocks are fixed by the row count alone, never by the number of threads, so
/// a kernel that writes only its own rows gives the same bits under any schedule.
inline constexpr std::size_t kParallelBlockRows = 8192;

/// Calls `body(begin, end)` for consecutive blocks of [0, rows), in parallel when there is more
/// than one block: on the calling thread's executor (see ExecutorScope), else with TBB. `body`
/// must write only rows [begin, end) of its outputs; reading any row of inputs that no block
/// writes during the loop is fine (a gather).
void parallelForRows(std::size_t rows, const std::function<void(std::size_t, std::size_t)>& body);

/// Runs task(i) for every i in [0, tasks), each once, on the same threads as parallelForRows().
/// For a few coarse independent jobs (moving the columns of a removal, one column a task).
void parallelForTasks(std::size_t tasks, const std::function<void(std::size_t)>& task);

/// While alive, parallelForRows() on this thread hands its blocks to `executor` (nullptr: TBB).
/// ParticleSystem opens one around each tick when the host gave it an executor.
class ExecutorScope {
 public:
  explicit ExecutorScope(TaskExecutor* executor);
  ~ExecutorScope();
  ExecutorScope(const ExecutorScope&) = delete;
  ExecutorScope& operator=(const ExecutorScope&) = delete;

 private:
  TaskExecutor* previous_;
};

}  // namespace tickfx
