// The harness every bench shares: its command line, the timing of cases that take turns, thread
// labels and the build and machine lines. A plain std::chrono driver rather than Google
// Benchmark: the figure that matters is the comparison between a case and its baseline (a loop
// written by hand, dd, OpenVDB's own advection), compiled into the same binary and measured in the
// same run, so the cases take turns instead of each being timed to completion on its own.
//
// Timing: each case runs in batches of ticks sized to take min-time/reps seconds; the cases take
// turns batch by batch (so a burst of outside load hits them all alike) until each has at least
// `reps` batches and `min-time` seconds. A case's figure is the median over its batches of the
// time per tick.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "particles/ParticlePool.h"

namespace tickfx::bench {

using Clock = std::chrono::steady_clock;

// Keeps the compiler from treating stores that nothing reads inside the timed loop as dead.
inline void escape(const void* p) {
#if defined(__GNUC__) || defined(__clang__)
  asm volatile("" : : "g"(p) : "memory");
#else
  static const void* volatile sink;
  sink = p;
#endif
}

// Summed into the printed checksum, so that the work of every case stays observable.
double positionSum(const ParticlePool& pool);

// Summed over the threads, so that CPU over wall time tells how many cores a case really had.
double processCpuSeconds();

// The median rather than the mean: a batch hit by outside load is an outlier, not a sample.
double median(std::vector<double> v);

// The CPU seconds the hypervisor has taken from this machine's virtual CPUs so far, all of them
// summed (the steal column of /proc/stat, in its 1/USER_HZ ticks); 0 where the kernel does not
// say. Machine-wide: on a guest whose host is busy, a case's batches slow down by what is stolen
// from them, which no figure of the process itself shows.
double stolenSeconds();

// ---- cases and their timing ---------------------------------------------------------------------

// One thing timed. A bench derives from it to carry what its own table needs (see timeCases).
struct Case {
  Case(std::string caseName, std::function<void(std::int64_t)> runTicks);

  std::string name;
  std::function<void(std::int64_t ticks)> run;
  /// Run before each batch, untimed, when set (a setting the batch is timed under).
  std::function<void()> before;
  /// Run after each batch, untimed, when set (files to delete, a result to check): false stops
  /// the timing.
  std::function<bool()> after;
  /// A count read just before and just after each batch, outside the timed part, when set (page
  /// faults): its rise over each timed batch goes to `counts`.
  std::function<double()> counter;
  /// Batches are whole multiples of this many ticks (a frame of several ticks).
  std::int64_t ticksPerFrame = 1;
  /// Batches are at least this many ticks (rounded up to whole frames): cases compared with each
  /// other take batches of one length, so that each batch's first, cold tick weighs alike (a
  /// case calibrated on one slow tick would otherwise time every tick cold).
  std::int64_t minimumBatch = 1;
  /// Whether the batch grows to min-time/reps seconds (its untimed runs are the warm-up). If not,
  /// every batch is one frame (a burst into a fresh pool cannot repeat within a batch), with one
  /// untimed batch first when `warmUp`.
  bool calibrated = true;
  bool warmUp = false;

  std::int64_t batch = 1;
  std::vector<double> secondsPerTick;
  std::vector<double> counts;
  double timed = 0.0;
  double cpu = 0.0;     // process CPU seconds over the timed batches, all threads
  double stolen = 0.0;  // stolenSeconds() over the timed batches, machine-wide

  /// The case's figure: the median over its batches of the seconds a tick.
  double seconds() const { return bench::median(secondsPerTick); }
  /// The fastest and the slowest batch, seconds a tick.
  double fastest() const;
  double slowest() const;
  /// The cores the process kept busy while the case ran: CPU over wall time.
  double cores() const { return timed > 0.0 ? cpu / timed : 0.0; }
  /// The share of the machine's CPU time the hypervisor took while the case's batches ran.
  double stolenShare() const;
};

/// How many times faster `c` ran than `baseline`, by their figures: above 1, faster.
inline double speedup(const Case& c, const Case& baseline) {
  return baseline.seconds() / c.seconds();
}

/// The share of `with`'s tick that `without` does not spend, (with − without) / with, paired
/// round by round: timeCases() runs one batch of each case a round, so a load on the machine that
/// changes between rounds moves both batches of a round alike and cancels in their ratio. The
/// median over the rounds; the batches' seconds must be of the same timeCases() call.
double pairedShare(const Case& with, const Case& without);

/// speedup() paired round by round as pairedShare() pairs them: the median over the rounds of
/// `baseline`'s seconds over `c`'s. Each figure of two cases moves with the machine's load, and
/// their ratio moved with it by up to half on a loaded guest; a round's two batches see the same
/// load.
double pairedSpeedup(const Case& c, const Case& baseline);

/// One batch of `c`: `before`, the timed run, `after`. When `record`, its time, CPU seconds and
/// count go to the case. Its seconds, or nothing when `after` says stop.
std::optional<double> timeBatch(Case& c, bool record);

/// Before `c` is timed: the batch grown until it takes `target` seconds (its runs are not
/// recorded, so they are also the warm-up: first-touch page faults of scratch columns, caches,
/// TBB workers waking up), or the untimed batch of an uncalibrated case. False when `after` says
/// stop.
bool prepareCase(Case& c, double target);

struct Timing {
  double minTime = 0.3;  // seconds each case is timed
  int reps = 5;          // minimum number of timed batches per case
};

/// Times `cases` taking turns, batch by batch. A template over the container so that a bench
/// can time its own Case-derived type in place. False when a case's `after` stopped it.
template <typename Cases>
bool timeCases(Cases& cases, const Timing& timing) {
  const double target = timing.minTime / timing.reps;
  for (Case& c : cases) {
    if (!prepareCase(c, target)) return false;
  }
  const auto finished = [&](const Case& c) {
    return static_cast<int>(c.secondsPerTick.size()) >= timing.reps && c.timed >= timing.minTime;
  };
  while (!std::all_of(cases.begin(), cases.end(), finished)) {
    for (Case& c : cases) {
      if (!timeBatch(c, /*record=*/true)) return false;
    }
  }
  return true;
}

// ---- threads, the machine and the build ---------------------------------------------------------

/// "1 thread", "2 threads": how the cases' names and the summary lines count threads.
std::string threadsLabel(int threads);

/// 1, and `allThreads` when that is more: the thread counts a bench compares.
std::vector<int> oneAndAll(int allThreads);

// Figures are only comparable between runs on the same kind of machine, so every run names it.
std::string cpuModel();

/// "machine: CPU, N hardware threads" and `more`, a line.
void printMachine(const std::string& more = "");

// So that figures from a Debug build are not mistaken for real ones.
void printBuild();

// ---- summary lines ------------------------------------------------------------------------------
// Each bench ends with one line a figure, `name: value unit (ratios, targets)`, whose name holds a
// size or a thread count; scripts/bench collects them from every bench's output.

/// %.3g without the exponent's plus sign and leading zeros: 1.27e7, 5e7, 0.62, 530.
std::string g3(double v);

/// 1e6 for 1000000; a count that is not a round power of ten as it is.
std::string sizeLabel(std::size_t n);

// ---- the command line ---------------------------------------------------------------------------

/// A whole count written as 1000000 or 1e6, at least `least` and at most 4e9; nothing otherwise.
std::optional<std::size_t> parseCount(const std::string& item, double least);

/// A comma-separated list of counts of at least 1 (`1e4,1e6`); nothing if any is not one.
std::optional<std::vector<std::size_t>> parseSizes(std::string_view list);

/// A bench's command line: the options every bench shares and those it declares of its own.
///   --quick        a smoke run: `quickTiming`, and the bench shrinks its scene
///   --min-time=S   seconds each case is timed (over --quick's)
///   --reps=N       minimum number of timed batches per case (over --quick's)
///   --help, -h     the usage
/// A bad value prints `bad --NAME: VALUE` and stops with exit code 2, an unknown argument prints
/// `unknown argument: ARG` and the usage.
class CommandLine {
 public:
  /// `usage` prints the usage, given the program's name.
  explicit CommandLine(void (*usage)(const char* argv0)) : usage_(usage) {}

  /// `--NAME`, a switch.
  CommandLine& flag(std::string name, bool& into);
  /// `--NAME=N[,N...]`, counts of at least 1 (see parseSizes).
  CommandLine& sizes(std::string name, std::optional<std::vector<std::size_t>>& into);
  /// `--NAME=N`, a whole count (see parseCount) that `accept` takes, when given; `note` follows
  /// the value in the message for one it does not.
  CommandLine& count(std::string name, std::optional<std::size_t>& into,
                     std::function<bool(std::size_t)> accept = {}, std::string note = "");
  /// `--NAME=TEXT`.
  CommandLine& text(std::string name, std::optional<std::string>& into);
  /// Without --min-time (a bench timing a fixed number of repetitions).
  CommandLine& withoutMinTime();

  /// Reads the arguments. The exit code when the program should stop (0 after --help, 2 after a
  /// bad argument), else nothing.
  std::optional<int> parse(int argc, char** argv);

  /// The timing: these defaults before parse(), what the command line asks for after.
  Timing timing;
  /// The timing of --quick (when --min-time and --reps do not say otherwise).
  Timing quickTiming{0.02, 5};
  bool quick = false;

 private:
  struct Option {
    std::string name;                                    // with its "--" and, for a value, its "="
    std::function<bool(const std::string& value)> take;  // false: a bad value, reported
  };
  std::optional<int> parseOne(std::string_view arg, const char* argv0,
                              std::optional<double>& minTime, std::optional<int>& reps);

  void (*usage_)(const char* argv0);
  std::vector<Option> options_;
  bool minTimeOption_ = true;
};

}  // namespace tickfx::bench
