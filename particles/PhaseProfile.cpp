#include "particles/PhaseProfile.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <sstream>
#include <string>

#if defined(__linux__)
#include <unistd.h>
#endif

namespace tickfx::profile {
namespace {

using Clock = std::chrono::steady_clock;

// The recording: touched by the recording thread alone (tRecording says which thread that is),
// so it needs no lock.
struct Recording {
  Clock::time_point began;       // start()
  double startupSeconds = 0.0;   // the process's life before start()
  Clock::time_point mark;        // since when `current` is being charged
  Phase current = Phase::Other;  // the innermost open phase
  int parallelDepth = 0;
  Clock::time_point parallelBegan;
  std::array<PhaseTime, kPhaseCount> phases{};
};

Recording gRecording;
thread_local bool tRecording = false;

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

PhaseTime& timeOf(Phase p) { return gRecording.phases[static_cast<std::size_t>(p)]; }

// Charges the time since the last switch to the current phase, then makes `next` current.
void switchTo(Phase next) {
  const Clock::time_point now = Clock::now();
  timeOf(gRecording.current).wallSeconds += seconds(now - gRecording.mark);
  gRecording.mark = now;
  gRecording.current = next;
}

// Seconds since the process started, from the kernel's record of it (boot-relative clock ticks,
// 10 ms on most kernels); 0 where it cannot be read.
double processAgeSeconds() {
#if defined(__linux__)
  std::ifstream stat("/proc/self/stat");
  std::string text;
  std::getline(stat, text);
  // Field 22, counted after the command name's closing parenthesis (the name may hold spaces).
  const std::size_t close = text.rfind(')');
  if (close == std::string::npos) return 0.0;
  std::istringstream fields(text.substr(close + 2));
  std::string field;
  unsigned long long startTicks = 0;
  for (int i = 3; i <= 22 && fields >> field; ++i) {
    if (i == 22) startTicks = std::stoull(field);
  }
  const long hz = sysconf(_SC_CLK_TCK);
  timespec boot{};
  if (startTicks == 0 || hz <= 0 || clock_gettime(CLOCK_BOOTTIME, &boot) != 0) return 0.0;
  const double now = static_cast<double>(boot.tv_sec) + 1e-9 * static_cast<double>(boot.tv_nsec);
  return std::max(0.0, now - static_cast<double>(startTicks) / static_cast<double>(hz));
#else
  return 0.0;
#endif
}

}  // namespace

const char* phaseName(Phase phase) {
  static constexpr std::array<const char*, kPhaseCount> kNames = {
      "other",  "startup", "load", "growth",     "emission",    "step",
      "deaths", "capture", "hash", "checkpoint", "cache write", "release"};
  return kNames[static_cast<std::size_t>(phase)];
}

double Report::serialShare() const {
  double serial = 0.0;
  for (const PhaseTime& p : phases) serial += p.serialSeconds();
  return wallSeconds > 0.0 ? serial / wallSeconds : 0.0;
}

std::string Report::format(int threads) const {
  std::string out;
  char line[160];
  std::snprintf(line, sizeof line, "profile: %.3f s wall on %d thread%s\n", wallSeconds, threads,
                threads == 1 ? "" : "s");
  out += line;
  out += "  phase          wall s  of run   serial s  serial share\n";
  double serial = 0.0;
  for (std::size_t i = 0; i < kPhaseCount; ++i) {
    const PhaseTime& p = phases[i];
    if (p.wallSeconds <= 0.0) continue;
    serial += p.serialSeconds();
    std::snprintf(line, sizeof line, "  %-12s %8.3f  %5.1f %%  %8.3f  %5.1f %%\n",
                  phaseName(static_cast<Phase>(i)), p.wallSeconds,
                  wallSeconds > 0.0 ? 100.0 * p.wallSeconds / wallSeconds : 0.0, p.serialSeconds(),
                  100.0 * p.serialSeconds() / p.wallSeconds);
    out += line;
  }
  const double s = serialShare();
  std::snprintf(line, sizeof line, "  %-12s %8.3f  %5.1f %%  %8.3f  %5.1f %%\n", "total",
                wallSeconds, 100.0, serial, 100.0 * s);
  out += line;
  // Amdahl: the serial part stays, the parallel part divides by N at best (measured on
  // `threads`, it is threads × its wall time of work).
  const double parallelWork = (1.0 - s) * static_cast<double>(std::max(threads, 1));
  out += "  Amdahl bound on the speed-up over 1 thread:";
  for (const int n : {2, 4, 8, 16}) {
    const double oneThread = s + parallelWork;
    std::snprintf(line, sizeof line, " %d: %.1fx%s", n, oneThread / (s + parallelWork / n),
                  n == 16 ? "\n" : ",");
    out += line;
  }
  return out;
}

void start() {
  gRecording = Recording{};
  gRecording.startupSeconds = processAgeSeconds();
  gRecording.began = Clock::now();
  gRecording.mark = gRecording.began;
  timeOf(Phase::Startup).wallSeconds = gRecording.startupSeconds;
  tRecording = true;
}

Report stop() {
  Report report;
  if (!tRecording) return report;
  switchTo(Phase::Other);
  tRecording = false;
  report.phases = gRecording.phases;
  report.wallSeconds = gRecording.startupSeconds + seconds(gRecording.mark - gRecording.began);
  return report;
}

PhaseScope::PhaseScope(Phase phase) {
  if (!tRecording || gRecording.parallelDepth > 0) return;
  active_ = true;
  previous_ = gRecording.current;
  switchTo(phase);
}

PhaseScope::~PhaseScope() {
  if (active_) switchTo(previous_);
}

ParallelScope::ParallelScope() {
  if (!tRecording || gRecording.parallelDepth++ > 0) return;
  active_ = true;
  gRecording.parallelBegan = Clock::now();
}

ParallelScope::~ParallelScope() {
  if (!tRecording) return;
  --gRecording.parallelDepth;
  if (active_) {
    timeOf(gRecording.current).parallelSeconds += seconds(Clock::now() - gRecording.parallelBegan);
  }
}

}  // namespace tickfx::profile
