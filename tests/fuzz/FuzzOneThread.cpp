// Linked into every fuzz target (tests/fuzz/CMakeLists.txt): caps oneTBB at one thread, the
// calling one, for the whole process. Where several threads run instrumented code (a reader's
// parallel loops, OpenVDB's reductions and oneTBB's own templates compiled into the readers),
// which branches run depends on the schedule (a task stolen or not, a reduction joined or not), so
// the coverage libFuzzer steers by would differ from run to run (docs/testing.md, Fuzzing). The
// fuzzers check memory and undefined behaviour; races are the ThreadSanitizer stage's.
#include <tbb/global_control.h>

namespace {

const tbb::global_control kOneThread(tbb::global_control::max_allowed_parallelism, 1);

}  // namespace
