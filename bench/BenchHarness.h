// The timing harness shared by tick_bench and spring_bench. A plain std::chrono driver rather than
// Google Benchmark: the figure that matters is the comparison between cases measured in the same
// run, so the cases take turns instead of each being timed to completion on its own.
//
// Timing: each case runs in batches of ticks sized to take min-time/reps seconds; the cases take
// turns batch by batch (so a burst of outside load hits them all alike) until each has at least
// `reps` batches and `min-time` seconds. A case's figure is the median over its batches of the
// time per tick.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "particles/ParticlePool.h"

#ifndef TICKFX_BENCH_CONFIG
#define TICKFX_BENCH_CONFIG "unknown"
#endif

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
inline double positionSum(const ParticlePool& pool) {
  const auto n = static_cast<Eigen::Index>(pool.size());
  double sum = 0.0;
  for (int c = 0; c < 3; ++c) sum += pool.position()[c].head(n).cast<double>().sum();
  return sum;
}

// Summed over the threads, so that CPU over wall time tells how many cores a case really had.
inline double processCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// A bench derives from it to carry what its own table needs (see timeCases).
struct Case {
  Case(std::string caseName, std::function<void(std::int64_t)> runTicks)
      : name(std::move(caseName)), run(std::move(runTicks)) {}

  std::string name;
  std::function<void(std::int64_t ticks)> run;
  /// Run before each batch, untimed, when set (a setting the batch is timed under).
  std::function<void()> before;
  /// Batches are whole multiples of this many ticks (a frame of several ticks).
  std::int64_t ticksPerFrame = 1;
  std::int64_t batch = 1;
  std::vector<double> secondsPerTick;
  double timed = 0.0;
  double cpu = 0.0;  // process CPU seconds over the timed batches, all threads
};

// The CPU clock is read outside the wall-clock interval, so it costs the figure nothing.
inline double timeBatch(Case& c, double* cpu = nullptr) {
  if (c.before) c.before();
  const double cpu0 = cpu != nullptr ? processCpuSeconds() : 0.0;
  const Clock::time_point start = Clock::now();
  c.run(c.batch);
  const double s = std::chrono::duration<double>(Clock::now() - start).count();
  if (cpu != nullptr) *cpu += processCpuSeconds() - cpu0;
  return s;
}

// Grows the batch until it takes `target` seconds. Its runs are not recorded, so they are also
// the warm-up (first-touch page faults of scratch columns, caches, TBB workers waking up).
inline void calibrate(Case& c, double target) {
  const std::int64_t unit = c.ticksPerFrame;
  c.batch = unit;
  for (;;) {
    const double s = timeBatch(c);
    if (s >= target) return;
    const double grow = s > 0.0 ? std::min(10.0, 1.2 * target / s) : 10.0;
    const std::int64_t grown = std::max(
        c.batch + 1, static_cast<std::int64_t>(std::ceil(static_cast<double>(c.batch) * grow)));
    c.batch = (grown + unit - 1) / unit * unit;
  }
}

// The median rather than the mean: a batch hit by outside load is an outlier, not a sample.
inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 == 1 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

struct Timing {
  double minTime = 0.3;  // seconds each case is timed
  int reps = 5;          // minimum number of timed batches per case
};

// A template over the container so that a bench can time its own Case-derived type in place.
template <typename Cases>
void timeCases(Cases& cases, const Timing& timing) {
  const double target = timing.minTime / timing.reps;
  for (Case& c : cases) calibrate(c, target);
  const auto finished = [&](const Case& c) {
    return static_cast<int>(c.secondsPerTick.size()) >= timing.reps && c.timed >= timing.minTime;
  };
  while (!std::all_of(cases.begin(), cases.end(), finished)) {
    for (Case& c : cases) {
      const double s = timeBatch(c, &c.cpu);
      c.secondsPerTick.push_back(s / static_cast<double>(c.batch));
      c.timed += s;
    }
  }
}

// Figures are only comparable between runs on the same kind of machine, so every run names it.
inline std::string cpuModel() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      const std::size_t colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(" \t", colon + 1));
    }
  }
  return "unknown CPU";
}

// So that figures from a Debug build are not mistaken for real ones.
inline void printBuild() {
  std::printf("build: %s, compiler %s\n", TICKFX_BENCH_CONFIG, __VERSION__);
  if (std::string_view(TICKFX_BENCH_CONFIG) != "Release") {
    std::printf("warning: not a Release build, the figures mean little\n");
  }
}

// ---- summary lines --------------------------------------------------------------------------
// Each bench ends with one line a figure, `name: value unit (ratios, targets)`, whose name holds a
// size or a thread count; scripts/bench collects them from every bench's output.

// %.3g without the exponent's plus sign and leading zeros: 1.27e7, 5e7, 0.62, 530.
inline std::string g3(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  std::string s(buf);
  const std::size_t e = s.find('e');
  if (e == std::string::npos) return s;
  const std::size_t digits = s[e + 1] == '-' ? e + 2 : e + 1;
  s.erase(digits, s.find_first_not_of("+0", digits) - digits);
  return s;
}

// A whole count written as 1000000 or 1e6, at least `least` and at most 4e9; nothing otherwise.
inline std::optional<std::size_t> parseCount(const std::string& item, double least) {
  char* end = nullptr;
  const double v = std::strtod(item.c_str(), &end);
  if (item.empty() || *end != '\0' || !(v >= least) || v > 4e9 || v != std::floor(v)) {
    return std::nullopt;
  }
  return static_cast<std::size_t>(v);
}

// A comma-separated list of counts of at least 1 (`--sizes=1e4,1e6`); nothing if any is not one.
inline std::optional<std::vector<std::size_t>> parseSizes(std::string_view list) {
  std::vector<std::size_t> sizes;
  while (!list.empty()) {
    const std::size_t comma = list.find(',');
    const std::optional<std::size_t> n = parseCount(std::string(list.substr(0, comma)), 1.0);
    if (!n) return std::nullopt;
    sizes.push_back(*n);
    list = comma == std::string_view::npos ? std::string_view{} : list.substr(comma + 1);
  }
  if (sizes.empty()) return std::nullopt;
  return sizes;
}

// 1e6 for 1000000; a count that is not a round power of ten as it is.
inline std::string sizeLabel(std::size_t n) {
  int exponent = 0;
  std::size_t mantissa = n;
  while (mantissa >= 10 && mantissa % 10 == 0) {
    mantissa /= 10;
    ++exponent;
  }
  if (exponent < 3) return std::to_string(n);
  return std::to_string(mantissa) + "e" + std::to_string(exponent);
}

// The value of a `--key=value` argument, or nothing when `arg` is another argument.
inline std::optional<std::string> valueOf(std::string_view arg, std::string_view prefix) {
  if (arg.substr(0, prefix.size()) != prefix) return std::nullopt;
  return std::string(arg.substr(prefix.size()));
}

// What a bench's own argument handler says of one argument. On kBad it has printed why.
enum class Arg { kNotMine, kTaken, kBad };

struct CommandLine {
  Timing timing;
  bool quick = false;  // the bench shrinks its scene; the timing part is done here
};

// Parses --quick, --min-time=, --reps= and --help, and hands every other argument to `own`.
// Returns the exit code when the program should stop (help, or a bad argument), else nothing.
// --min-time wins over --quick whatever their order, hence the quick default applied last.
inline std::optional<int> parseCommandLine(int argc, char** argv, CommandLine& cl,
                                           void (*usage)(const char* argv0),
                                           const std::function<Arg(std::string_view)>& own) {
  std::optional<double> minTime;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--quick") {
      cl.quick = true;
      continue;
    }
    const Arg mine = own(arg);
    if (mine == Arg::kBad) return 2;
    if (mine == Arg::kTaken) continue;
    if (auto t = valueOf(arg, "--min-time=")) {
      minTime = std::atof(t->c_str());
      if (!(*minTime > 0.0)) {
        std::fprintf(stderr, "bad --min-time: %s\n", t->c_str());
        return 2;
      }
    } else if (auto r = valueOf(arg, "--reps=")) {
      cl.timing.reps = std::atoi(r->c_str());
      if (cl.timing.reps < 1) {
        std::fprintf(stderr, "bad --reps: %s\n", r->c_str());
        return 2;
      }
    } else if (arg == "--help" || arg == "-h") {
      usage(argv[0]);
      return 0;
    } else {
      std::fprintf(stderr, "unknown argument: %s\n", argv[i]);
      usage(argv[0]);
      return 2;
    }
  }
  if (cl.quick) cl.timing.minTime = 0.02;
  if (minTime) cl.timing.minTime = *minTime;
  return std::nullopt;
}

}  // namespace tickfx::bench
