// What makes a fuzz run repeatable: the same seed and corpus give the same inputs, coverage and
// corpus, run after run (docs/testing.md, Fuzzing). Each target calls runOnOneThread() from its
// LLVMFuzzerInitialize.
#pragma once

#include <tbb/global_control.h>

namespace tickfx::fuzz {

/// Caps oneTBB at one thread, the calling one, for the whole process. Where several threads run
/// instrumented code (a reader's parallel loops, OpenVDB's reductions and oneTBB's own templates
/// compiled into the readers), which branches run depends on the schedule (a task stolen or not,
/// a reduction joined or not), so the coverage libFuzzer steers by would differ from run to run.
/// The fuzzers check memory and undefined behaviour; races are the ThreadSanitizer stage's.
inline void runOnOneThread() {
  static tbb::global_control oneThread(tbb::global_control::max_allowed_parallelism, 1);
}

}  // namespace tickfx::fuzz
