#include "BenchHarness.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <string>
#include <thread>
#include <utility>

#ifndef TICKFX_BENCH_CONFIG
#define TICKFX_BENCH_CONFIG "unknown"
#endif

namespace tickfx::bench {

double positionSum(const ParticlePool& pool) {
  const auto n = static_cast<Eigen::Index>(pool.size());
  double sum = 0.0;
  for (int c = 0; c < 3; ++c) sum += pool.position()[c].head(n).cast<double>().sum();
  return sum;
}

double processCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double stolenSeconds() {
  static const long ticksPerSecond = sysconf(_SC_CLK_TCK);
  std::ifstream in("/proc/stat");
  std::string cpu;
  // cpu user nice system idle iowait irq softirq steal: the first line sums every CPU.
  unsigned long long value[8] = {};
  if (!(in >> cpu) || cpu != "cpu" || ticksPerSecond <= 0) return 0.0;
  for (unsigned long long& v : value) {
    if (!(in >> v)) return 0.0;
  }
  return static_cast<double>(value[7]) / static_cast<double>(ticksPerSecond);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 == 1 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

// ---- cases and their timing ---------------------------------------------------------------------

Case::Case(std::string caseName, std::function<void(std::int64_t)> runTicks)
    : name(std::move(caseName)), run(std::move(runTicks)) {}

namespace {

// The median over the rounds both cases have of f(a's seconds, b's seconds) in that round; 0
// without one.
template <class F>
double medianOverRounds(const Case& a, const Case& b, const F& f) {
  const std::size_t rounds = std::min(a.secondsPerTick.size(), b.secondsPerTick.size());
  if (rounds == 0) return 0.0;
  std::vector<double> values(rounds);
  for (std::size_t r = 0; r < rounds; ++r) values[r] = f(a.secondsPerTick[r], b.secondsPerTick[r]);
  return median(std::move(values));
}

}  // namespace

double pairedShare(const Case& with, const Case& without) {
  return medianOverRounds(with, without, [](double w, double wo) { return (w - wo) / w; });
}

double pairedSpeedup(const Case& c, const Case& baseline) {
  return medianOverRounds(c, baseline, [](double s, double base) { return base / s; });
}

double Case::stolenShare() const {
  // hardware_concurrency(): the online CPUs, which /proc/stat's steal sums over.
  const double machine = timed * static_cast<double>(std::thread::hardware_concurrency());
  return machine > 0.0 ? stolen / machine : 0.0;
}

double Case::fastest() const {
  return *std::min_element(secondsPerTick.begin(), secondsPerTick.end());
}

double Case::slowest() const {
  return *std::max_element(secondsPerTick.begin(), secondsPerTick.end());
}

// The CPU clock, the steal and the counter are read outside the wall-clock interval, so they cost
// the figure nothing.
std::optional<double> timeBatch(Case& c, bool record) {
  if (c.before) c.before();
  const double count0 = c.counter ? c.counter() : 0.0;
  const double stolen0 = stolenSeconds();
  const double cpu0 = processCpuSeconds();
  const Clock::time_point start = Clock::now();
  c.run(c.batch);
  const double s = std::chrono::duration<double>(Clock::now() - start).count();
  const double cpu = processCpuSeconds() - cpu0;
  const double stolen = stolenSeconds() - stolen0;
  const double count = c.counter ? c.counter() - count0 : 0.0;
  if (record) {
    c.secondsPerTick.push_back(s / static_cast<double>(c.batch));
    if (c.counter) c.counts.push_back(count);
    c.timed += s;
    c.cpu += cpu;
    c.stolen += stolen;
  }
  if (c.after && !c.after()) return std::nullopt;
  return s;
}

bool prepareCase(Case& c, double target) {
  const std::int64_t unit = c.ticksPerFrame;
  c.batch = (std::max(c.minimumBatch, unit) + unit - 1) / unit * unit;
  if (!c.calibrated) return !c.warmUp || timeBatch(c, /*record=*/false).has_value();
  for (;;) {
    const std::optional<double> s = timeBatch(c, /*record=*/false);
    if (!s) return false;
    if (*s >= target) return true;
    const double grow = *s > 0.0 ? std::min(10.0, 1.2 * target / *s) : 10.0;
    const std::int64_t grown = std::max(
        c.batch + 1, static_cast<std::int64_t>(std::ceil(static_cast<double>(c.batch) * grow)));
    c.batch = (grown + unit - 1) / unit * unit;
  }
}

// ---- threads, the machine and the build ---------------------------------------------------------

std::string threadsLabel(int threads) {
  return std::to_string(threads) + (threads == 1 ? " thread" : " threads");
}

std::vector<int> oneAndAll(int allThreads) {
  if (allThreads > 1) return {1, allThreads};
  return {1};
}

std::string cpuModel() {
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

void printMachine(const std::string& more) {
  std::printf("machine: %s, %u hardware threads%s\n", cpuModel().c_str(),
              std::thread::hardware_concurrency(), more.c_str());
}

void printBuild() {
  std::printf("build: %s, compiler %s\n", TICKFX_BENCH_CONFIG, __VERSION__);
  if (std::string_view(TICKFX_BENCH_CONFIG) != "Release") {
    std::printf("warning: not a Release build, the figures mean little\n");
  }
}

// ---- summary lines ------------------------------------------------------------------------------

std::string g3(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  std::string s(buf);
  const std::size_t e = s.find('e');
  if (e == std::string::npos) return s;
  const std::size_t digits = s[e + 1] == '-' ? e + 2 : e + 1;
  s.erase(digits, s.find_first_not_of("+0", digits) - digits);
  return s;
}

std::string sizeLabel(std::size_t n) {
  int exponent = 0;
  std::size_t mantissa = n;
  while (mantissa >= 10 && mantissa % 10 == 0) {
    mantissa /= 10;
    ++exponent;
  }
  if (exponent < 3) return std::to_string(n);
  return std::to_string(mantissa) + "e" + std::to_string(exponent);
}

// ---- the command line ---------------------------------------------------------------------------

std::optional<std::size_t> parseCount(const std::string& item, double least) {
  char* end = nullptr;
  const double v = std::strtod(item.c_str(), &end);
  if (item.empty() || *end != '\0' || !(v >= least) || v > 4e9 || v != std::floor(v)) {
    return std::nullopt;
  }
  return static_cast<std::size_t>(v);
}

std::optional<std::vector<std::size_t>> parseSizes(std::string_view list) {
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

namespace {

// "bad --NAME: VALUE" and `note`, for a value an option does not take.
bool refuse(const std::string& name, const std::string& value, const std::string& note = "") {
  std::fprintf(stderr, "bad %s: %s%s\n", name.c_str(), value.c_str(), note.c_str());
  return false;
}

}  // namespace

CommandLine& CommandLine::flag(std::string name, bool& into) {
  options_.push_back({std::move(name), [&into](const std::string&) {
                        into = true;
                        return true;
                      }});
  return *this;
}

CommandLine& CommandLine::sizes(std::string name, std::optional<std::vector<std::size_t>>& into) {
  options_.push_back({name + "=", [name, &into](const std::string& value) {
                        into = parseSizes(value);
                        return into ? true : refuse(name, value);
                      }});
  return *this;
}

CommandLine& CommandLine::count(std::string name, std::optional<std::size_t>& into,
                                std::function<bool(std::size_t)> accept, std::string note) {
  options_.push_back({name + "=", [name, &into, accept, note](const std::string& value) {
                        into = parseCount(value, 0.0);
                        if (!into || (accept && !accept(*into))) return refuse(name, value, note);
                        return true;
                      }});
  return *this;
}

CommandLine& CommandLine::text(std::string name, std::optional<std::string>& into) {
  options_.push_back({name + "=", [&into](const std::string& value) {
                        into = value;
                        return true;
                      }});
  return *this;
}

CommandLine& CommandLine::withoutMinTime() {
  minTimeOption_ = false;
  return *this;
}

// One argument: nothing when it is taken, else the exit code.
std::optional<int> CommandLine::parseOne(std::string_view arg, const char* argv0,
                                         std::optional<double>& minTime, std::optional<int>& reps) {
  if (arg == "--quick") {
    quick = true;
    return std::nullopt;
  }
  for (const Option& o : options_) {
    const bool valued = o.name.back() == '=';
    if (valued ? arg.rfind(o.name, 0) != 0 : arg != o.name) continue;
    if (!o.take(std::string(arg.substr(valued ? o.name.size() : arg.size())))) return 2;
    return std::nullopt;
  }
  const auto valueOf = [&](std::string_view prefix) -> std::optional<std::string> {
    if (arg.substr(0, prefix.size()) != prefix) return std::nullopt;
    return std::string(arg.substr(prefix.size()));
  };
  if (const std::optional<std::string> t = minTimeOption_ ? valueOf("--min-time=") : std::nullopt) {
    minTime = std::atof(t->c_str());
    if (!(*minTime > 0.0)) {
      refuse("--min-time", *t);
      return 2;
    }
  } else if (const std::optional<std::string> r = valueOf("--reps=")) {
    reps = std::atoi(r->c_str());
    if (*reps < 1) {
      refuse("--reps", *r);
      return 2;
    }
  } else if (arg == "--help" || arg == "-h") {
    usage_(argv0);
    return 0;
  } else {
    std::fprintf(stderr, "unknown argument: %s\n", std::string(arg).c_str());
    usage_(argv0);
    return 2;
  }
  return std::nullopt;
}

// --min-time and --reps win over --quick whatever their order, hence the quick timing applied
// first.
std::optional<int> CommandLine::parse(int argc, char** argv) {
  std::optional<double> minTime;
  std::optional<int> reps;
  for (int i = 1; i < argc; ++i) {
    if (const std::optional<int> exitCode = parseOne(argv[i], argv[0], minTime, reps)) {
      return exitCode;
    }
  }
  if (quick) timing = quickTiming;
  if (minTime) timing.minTime = *minTime;
  if (reps) timing.reps = *reps;
  return std::nullopt;
}

}  // namespace tickfx::bench
