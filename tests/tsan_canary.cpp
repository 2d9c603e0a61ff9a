// The ThreadSanitizer stage's control (scripts/test): a kernel that breaks the gather-only rule,
// each block also writing the first row of the next, run through parallelForRows() on 4 threads.
// ThreadSanitizer must report it, or the stage's passing tests prove nothing; the stage fails
// unless this program's output holds a data race report.
#include <tbb/task_arena.h>

#include <cstddef>
#include <cstdio>
#include <vector>

#include "particles/ParallelFor.h"

int main() {
  std::vector<float> rows(8 * tickfx::kParallelBlockRows, 0.0f);
  tbb::task_arena arena(4);
  arena.execute([&] {
    tickfx::parallelForRows(rows.size(), [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) rows[i] += 1.0f;
      if (end < rows.size()) rows[end] += 1.0f;  // a scatter into the next block's first row
    });
  });
  std::printf("%g\n", static_cast<double>(rows[tickfx::kParallelBlockRows]));
  return 0;
}
