// tickfx determinism: one effect under every frame schedule and thread count of the guarantee,
// a table of state hashes, and a verdict a user's own CI can act on.
#include <cinttypes>
#include <cstdio>
#include <sstream>

#include "app/Commands.h"
#include "app/DeterminismCheck.h"
#include "io/EffectBuilder.h"
#include "io/EffectParser.h"
#include "io/FrameTimes.h"
#include "particles/StateHash.h"

namespace tickfx::app {
namespace {

constexpr const char* kHelp =
    "usage: tickfx determinism EFFECT.toml [--seconds S] [--threads LIST] [--frame-times FILE]\n"
    "                          [--set key.path=value]...\n"
    "\n"
    "Runs EFFECT.toml for S seconds (default 5) driven by 24, 25, 30, 30000/1001, 60 and 144 fps,\n"
    "three seeded jitter sequences and a sequence of recorded frame times (FILE, or a built-in\n"
    "irregular one), each on 1 thread, and at 60 fps and jitter 1 on each thread count of LIST\n"
    "(default 1,2,3,8). The cap on ticks per frame is lifted. It hashes the state after every "
    "tick\n"
    "and prints the hashes at 1 s, 2 s and S. Exit code 0 when every run agrees at every tick,\n"
    "1 otherwise (naming the first tick where they part), 2 for usage or effect errors.\n";

std::vector<int> parseThreadList(const std::string& text) {
  std::vector<int> threads;
  std::stringstream list(text);
  std::string item;
  while (std::getline(list, item, ',')) {
    threads.push_back(static_cast<int>(parseInteger(item, "determinism: --threads", 1, 256)));
  }
  if (threads.empty()) throw UsageError("determinism: --threads: empty list");
  return threads;
}

std::string hashAt(const DriveTrace& t, std::int64_t tick) {
  for (std::size_t i = 0; i < t.ticks.size(); ++i) {
    if (t.ticks[i] == tick) return hashToHex(t.hashes[i]);
  }
  return "-";
}

}  // namespace

int determinismCommand(Arguments& args) {
  if (args.flag("--help")) {
    std::fputs(kHelp, stdout);
    return kExitOk;
  }
  const std::vector<std::string> overrides = args.values("--set");
  const double seconds =
      parseNumber(args.value("--seconds").value_or("5"), "determinism: --seconds", 0.001, 3600.0);
  const std::vector<int> threads = parseThreadList(args.value("--threads").value_or("1,2,3,8"));
  const auto frameTimes = args.value("--frame-times");
  const std::string path =
      args.positionals(1, "one effect file: tickfx determinism EFFECT.toml")[0];

  const io::LoadResult load = io::loadEffectFile(path, overrides);
  for (const io::Diagnostic& d : load.diagnostics) std::fprintf(stderr, "%s\n", d.format().c_str());
  if (!load.ok()) return kExitUsage;
  const io::EffectSettings& effect = *load.effect;
  const Flicks total = flicksFromSeconds(seconds);
  std::optional<std::vector<Flicks>> recorded;
  if (frameTimes) {
    try {
      recorded = io::readFrameTimes(*frameTimes);
    } catch (const std::runtime_error& e) {
      std::fprintf(stderr, "%s\n", e.what());
      return kExitUsage;
    }
  }

  const std::int64_t rate = effect.simulation.stepRateHz;
  const std::int64_t lastTick =
      static_cast<std::int64_t>((static_cast<__int128>(total) * rate) / kFlicksPerSecond);
  std::printf("determinism: %s for %.6g s: %" PRId64 " ticks at %" PRId64 " Hz (%s)\n\n",
              path.c_str(), seconds, lastTick, rate, effect.simulation.integrator.c_str());
  std::printf("%-18s %7s %7s  %-16s  %-16s  %-16s %8s\n", "frames", "threads", "ticks",
              "hash at 1 s", "hash at 2 s", "hash at the end", "wall s");

  std::vector<DriveTrace> traces;
  for (const DriveCase& drive : standardDriveCases(total, threads, recorded)) {
    try {
      traces.push_back(traceDrive(effect, drive));
    } catch (const io::BuildError& e) {  // a vector field's file that does not load: bad input
      std::fprintf(stderr, "%s\n", e.what());
      return kExitUsage;
    }
    const DriveTrace& t = traces.back();
    std::printf("%-18s %7d %7zu  %-16s  %-16s  %-16s %8.3f%s\n", t.label.c_str(), t.threads,
                t.ticks.size(), hashAt(t, rate).c_str(), hashAt(t, 2 * rate).c_str(),
                hashAt(t, lastTick).c_str(), t.wallSeconds,
                t.ticksDropped > 0 ? "  (ticks dropped!)" : "");
    std::fflush(stdout);
  }

  const Divergence d = firstDivergence(traces);
  std::printf("\n");
  if (d.tick < 0) {
    std::printf(
        "verdict: all %zu runs agree bit for bit after every one of %" PRId64
        " ticks (state-hash %s)\n",
        traces.size(), lastTick,
        traces.front().hashes.empty() ? "-" : hashToHex(traces.front().hashes.back()).c_str());
    return kExitOk;
  }
  std::printf("verdict: runs part at tick %" PRId64 " (t = %.6g s):", d.tick,
              static_cast<double>(d.tick) / static_cast<double>(rate));
  for (std::size_t r : d.runs)
    std::printf(" '%s, %d thread(s)'", traces[r].label.c_str(), traces[r].threads);
  std::printf(" differ from '%s, %d thread(s)'\n", traces.front().label.c_str(),
              traces.front().threads);
  std::printf(
      "rerun two of them with `tickfx run ... --trace FILE` and compare the files to see the state "
      "there\n");
  return kExitFailure;
}

}  // namespace tickfx::app
