// tickfx determinism: one effect under every frame schedule and thread count of the guarantee,
// a table of state hashes, and a verdict a user's own CI can act on; or one run recorded as a hash
// log, or compared with a log recorded on another machine.
#include <algorithm>
#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "app/Commands.h"
#include "app/DeterminismCheck.h"
#include "app/DifferenceImage.h"
#include "app/FrameTimes.h"
#include "app/HashLogRun.h"
#include "app/LoadEffect.h"
#include "app/ProgressLine.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectParser.h"
#include "io/util/AtomicFile.h"
#include "particles/StateHash.h"

namespace tickfx::app {
namespace {

constexpr const char* kDeterminismHelp =
    "usage: tickfx determinism EFFECT.toml [--seconds S] [--threads LIST] [--frame-times FILE]\n"
    "                          [--diff-image OUT.png] [--set key.path=value]...\n"
    "\n"
    "Runs EFFECT.toml for S seconds (default 5) driven by 24, 25, 30, 30000/1001, 60 and 144 fps,\n"
    "three seeded jitter sequences and a sequence of recorded frame times (FILE, or a built-in\n"
    "irregular one), each on 1 thread, and at 60 fps and jitter 1 on each thread count of LIST\n"
    "(default 1,2,3,8). The cap on ticks per frame is lifted. It hashes the state after every "
    "tick\n"
    "and prints the hashes at 1 s, 2 s and S. Exit code 0 when every run agrees at every tick,\n"
    "1 otherwise (naming the first tick where they part), 2 for usage or effect errors.\n"
    "--diff-image OUT.png, when runs part, renders the state after that tick of the first run\n"
    "(1280x720 PNG), each particle coloured by the distance to its position (by id) in the first\n"
    "run that differs, both named in the image; nothing is written when every run agrees.\n"
    "\n"
    "usage: tickfx determinism EFFECT.toml --record FILE [--seconds S] [--fps F]\n"
    "                          [--snapshot-at TICKS] [--set key.path=value]...\n"
    "       tickfx determinism EFFECT.toml --compare FILE [--set key.path=value]...\n"
    "\n"
    "--record runs EFFECT.toml once for S seconds (default 5) in frames of 1/F s (default: the\n"
    "effect's output fps) and writes FILE, a hash log: a header naming this machine, CPU,\n"
    "compiler, build and tickfx version and the effect (its fingerprint: the file's bytes and\n"
    "every --set; its seed and step rate), then after every tick the state hash and one hash per\n"
    "column (counters, id, birth_tick, position.x, ...), and after every frame the hash of what\n"
    "it shows. --snapshot-at 120,121 also stores the whole state after those ticks.\n"
    "--compare runs the same effect with the same --set, length and frames on this machine and\n"
    "prints 'identical through tick N' (exit 0), or the first tick where the runs part with the\n"
    "columns that differ there (exit 1); when the log holds a snapshot of that tick, also the\n"
    "first particle id and column that differ with both values in hex. A log of another step\n"
    "rate, seed or effect, or one truncated or garbled, is refused (exit 2).\n";

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

std::vector<std::int64_t> parseTickList(const std::string& text) {
  std::vector<std::int64_t> ticks;
  std::stringstream list(text);
  std::string item;
  while (std::getline(list, item, ','))
    ticks.push_back(parseInteger(item, "determinism: --snapshot-at", 1, INT64_MAX));
  if (ticks.empty()) throw UsageError("determinism: --snapshot-at: empty list");
  std::sort(ticks.begin(), ticks.end());
  return ticks;
}

// "0x3f800000 (1)" for a float column's bits, "0x000000000000002a" for id and birth_tick.
std::string describeBits(const std::string& column, std::uint64_t bits) {
  char text[64];
  if (column == "id" || column == "birth_tick") {
    std::snprintf(text, sizeof text, "0x%016" PRIx64, bits);
  } else {
    const auto b = static_cast<std::uint32_t>(bits);
    float value = 0.0f;
    std::memcpy(&value, &b, sizeof value);
    std::snprintf(text, sizeof text, "0x%08" PRIx32 " (%.9g)", b, static_cast<double>(value));
  }
  return text;
}

std::string describeBuild(const io::HashLogHeader& h) {
  return "tickfx " + h.version + ", " + h.compiler + ", " + h.build + ", " + h.machine + ", " +
         h.cpu;
}

// What --record and --compare were given besides the effect.
struct LogOptions {
  std::string logPath;
  double seconds = 5.0;
  std::optional<FrameRate> fps;
  std::vector<std::int64_t> snapshots;
};

int recordCommand(const io::EffectSettings& effect, const std::string& effectPath,
                  std::uint64_t fingerprint, const LogOptions& options) {
  const std::string& logPath = options.logPath;
  const FrameRate fps = options.fps.value_or(effect.output.fps);
  const double seconds = options.seconds;
  const std::vector<std::int64_t>& snapshots = options.snapshots;

  io::HashLogHeader header = describeThisBuild();
  header.effect = effectPath;
  header.fingerprint = fingerprint;
  header.seed = effect.simulation.seed;
  header.stepRateHz = effect.simulation.stepRateHz;
  header.length = flicksFromSeconds(seconds);
  header.fps = fps;
  try {
    io::requireWritable(logPath);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kExitUsage;
  }
  io::HashLog log;
  try {
    log = recordHashLog(effect, header, snapshots);
  } catch (const io::BuildError& e) {  // a vector field's file that does not load: bad input
    std::fprintf(stderr, "%s\n", e.what());
    return kExitUsage;
  }
  io::writeHashLog(logPath, log);
  std::printf("recorded %s: %" PRId64 " ticks at %" PRId64 " Hz, %" PRId64
              " frames, state-hash %s, %zu snapshot(s)\n",
              logPath.c_str(), log.header.ticks, log.header.stepRateHz, log.header.frames,
              log.ticks.empty() ? "-" : hashToHex(log.ticks.back().state).c_str(),
              log.snapshots.size());
  std::printf("this build: %s\n", describeBuild(log.header).c_str());
  return kExitOk;
}

// Where the run parts from the log: the tick, the columns and, from the log's snapshot of that
// tick, the first particle and column that differ.
void reportParting(const LogComparison& c, const io::HashLog& log) {
  std::printf("the runs part at tick %" PRId64 " (t = %.9g s): state-hash %s here, %s in the log\n",
              c.partTick,
              static_cast<double>(c.partTick) / static_cast<double>(log.header.stepRateHz),
              hashToHex(c.runHash).c_str(), hashToHex(c.logHash).c_str());
  std::string columns;
  for (const std::string& name : c.columns) columns += " " + name;
  std::printf("columns that differ:%s\n", columns.empty() ? " -" : columns.c_str());
  if (c.row && c.row->column == "counters") {
    std::printf("first difference: particle id %" PRIu64 ": %" PRIu64 " particles here, %" PRIu64
                " in the log\n",
                c.row->id, c.row->runBits, c.row->logBits);
  } else if (c.row) {
    std::printf("first difference: particle id %" PRIu64 ", %s: %s here, %s in the log\n",
                c.row->id, c.row->column.c_str(),
                describeBits(c.row->column, c.row->runBits).c_str(),
                describeBits(c.row->column, c.row->logBits).c_str());
  } else if (!c.logHasState) {
    std::printf("the log holds no state of tick %" PRId64
                ": record it again with --snapshot-at %" PRId64
                " to name the particle and both values\n",
                c.partTick, c.partTick);
  }
}

int compareCommand(const io::EffectSettings& effect, std::uint64_t fingerprint,
                   const std::string& logPath) {
  LogComparison c;
  io::HashLog log;
  try {
    log = io::readHashLog(logPath);
    c = compareWithHashLog(effect, fingerprint, logPath, log);
  } catch (const io::BuildError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kExitUsage;
  } catch (const std::runtime_error& e) {  // the log is unreadable, or of another effect
    std::fprintf(stderr, "%s\n", e.what());
    return kExitUsage;
  }
  std::printf("log:       %s\n", describeBuild(log.header).c_str());
  std::printf("this run:  %s\n", describeBuild(describeThisBuild()).c_str());
  if (c.partTick >= 0) {
    reportParting(c, log);
    return kExitFailure;
  }
  if (c.partFrame >= 0) {
    std::printf("every tick agrees, but frame %" PRId64
                " shows other bits here than in the log (the interpolation between ticks)\n",
                c.partFrame);
    return kExitFailure;
  }
  std::printf("identical through tick %" PRId64 " and frame %" PRId64 " (state-hash %s)\n", c.ticks,
              c.frames, hashToHex(c.lastHash).c_str());
  return kExitOk;
}

// --record FILE or --compare FILE: every option is read before the effect file (Arguments wants
// the positional last), and the effect is loaded as for the table.
int logCommand(Arguments& args, const std::vector<std::string>& overrides,
               const std::optional<std::string>& record,
               const std::optional<std::string>& compare) {
  if (record && compare) throw UsageError("determinism: give --record or --compare, not both");
  for (const char* option : {"--threads", "--frame-times", "--diff-image"}) {
    if (args.value(option)) {
      throw UsageError(std::string("determinism: ") + option +
                       " does not go with --record or --compare");
    }
  }
  LogOptions options;
  const auto seconds = args.value("--seconds");
  const auto fps = args.value("--fps");
  const auto snapshotAt = args.value("--snapshot-at");
  if (compare) {
    // The log fixes the run: comparing another length or other frames would prove nothing.
    for (const auto& [given, option] : {std::pair{seconds, "--seconds"}, std::pair{fps, "--fps"},
                                        std::pair{snapshotAt, "--snapshot-at"}}) {
      if (given) {
        throw UsageError(std::string("determinism: --compare takes the length and frames from "
                                     "the log; drop ") +
                         option);
      }
    }
    options.logPath = *compare;
  } else {
    options.logPath = *record;
    if (seconds) options.seconds = parseNumber(*seconds, "determinism: --seconds", 0.001, 3600.0);
    if (fps) {
      try {
        options.fps = parseFrameRate(*fps);
      } catch (const std::invalid_argument& e) {
        throw UsageError(std::string("determinism: --fps: ") + e.what());
      }
    }
    if (snapshotAt) options.snapshots = parseTickList(*snapshotAt);
  }
  const std::string path =
      args.positionals(1, std::string("one effect file: tickfx determinism EFFECT.toml ") +
                              (compare ? "--compare FILE" : "--record FILE"))[0];
  const io::LoadResult load = loadEffectReporting(path, overrides);
  if (!load.ok()) return kExitUsage;
  return compare ? compareCommand(*load.effect, load.fingerprint, options.logPath)
                 : recordCommand(*load.effect, path, load.fingerprint, options);
}

std::string hashAt(const DriveTrace& t, std::int64_t tick) {
  for (std::size_t i = 0; i < t.ticks.size(); ++i) {
    if (t.ticks[i] == tick) return hashToHex(t.hashes[i]);
  }
  return "-";
}

// ---- the table: every frame schedule and thread count ------------------------------------------

// What the table of runs was asked for (after --set, --record and --compare).
struct TableSettings {
  std::vector<std::string> overrides;
  double seconds = 5.0;
  std::vector<int> threads;
  std::optional<std::string> frameTimes;
  std::optional<std::filesystem::path> diffImage;
  std::string effectPath;
};

TableSettings readTableSettings(Arguments& args, std::vector<std::string> overrides) {
  TableSettings s;
  s.overrides = std::move(overrides);
  s.seconds =
      parseNumber(args.value("--seconds").value_or("5"), "determinism: --seconds", 0.001, 3600.0);
  s.threads = parseThreadList(args.value("--threads").value_or("1,2,3,8"));
  s.frameTimes = args.value("--frame-times");
  s.diffImage = args.value("--diff-image");
  s.effectPath = args.positionals(1, "one effect file: tickfx determinism EFFECT.toml")[0];
  return s;
}

// The table's runs, ready: the effect loaded and its drives made.
struct PreparedTable {
  io::LoadResult load;
  std::int64_t rate = 0;      // the effect's step rate (Hz)
  std::int64_t lastTick = 0;  // the tick the runs end at
  std::vector<DriveCase> drives;

  const io::EffectSettings& effect() const { return *load.effect; }
};

// Nothing after printing why not (bad input: exit 2).
std::optional<PreparedTable> prepareTable(const TableSettings& s) {
  if (s.diffImage) {
    try {
      io::requireWritable(*s.diffImage);
    } catch (const io::WriteError& e) {
      std::fprintf(stderr, "%s\n", e.what());
      return std::nullopt;
    }
  }
  PreparedTable t;
  t.load = loadEffectReporting(s.effectPath, s.overrides);
  if (!t.load.ok()) return std::nullopt;
  const Flicks total = flicksFromSeconds(s.seconds);
  std::optional<std::vector<Flicks>> recorded;
  if (s.frameTimes) {
    try {
      recorded = readFrameTimes(*s.frameTimes);
    } catch (const std::runtime_error& e) {
      std::fprintf(stderr, "%s\n", e.what());
      return std::nullopt;
    }
  }
  t.rate = t.effect().simulation.stepRateHz;
  t.lastTick =
      static_cast<std::int64_t>((static_cast<__int128>(total) * t.rate) / kFlicksPerSecond);
  t.drives = standardDriveCases(total, s.threads, recorded);
  return t;
}

// Runs every drive, printing its row of the table as it ends; nothing after printing why a
// drive could not run (bad input: exit 2).
std::optional<std::vector<DriveTrace>> runDrives(const TableSettings& s, const PreparedTable& t) {
  std::printf("determinism: %s for %.6g s: %" PRId64 " ticks at %" PRId64 " Hz (%s)\n\n",
              s.effectPath.c_str(), s.seconds, t.lastTick, t.rate,
              t.effect().simulation.integrator.c_str());
  std::printf("%-18s %7s %7s  %-16s  %-16s  %-16s %8s\n", "frames", "threads", "ticks",
              "hash at 1 s", "hash at 2 s", "hash at the end", "wall s");
  std::vector<DriveTrace> traces;
  ProgressLine progress("schedules");
  for (const DriveCase& drive : t.drives) {
    const auto done = static_cast<std::int64_t>(traces.size());
    progress.update(done, static_cast<std::int64_t>(t.drives.size()), drive.label);
    try {
      traces.push_back(traceDrive(t.effect(), drive));
    } catch (const io::BuildError& e) {  // a vector field's file that does not load: bad input
      std::fprintf(stderr, "%s\n", e.what());
      return std::nullopt;
    }
    const DriveTrace& r = traces.back();
    progress.finish();  // the row below replaces the line
    std::printf("%-18s %7d %7zu  %-16s  %-16s  %-16s %8.3f%s\n", r.label.c_str(), r.threads,
                r.ticks.size(), hashAt(r, t.rate).c_str(), hashAt(r, 2 * t.rate).c_str(),
                hashAt(r, t.lastTick).c_str(), r.wallSeconds,
                r.ticksDropped > 0 ? "  (ticks dropped!)" : "");
    std::fflush(stdout);
  }
  return traces;
}

// --diff-image: the state after tick d.tick of the first run, coloured by how far each particle
// is from where the first run that differs has it.
void writeDifferenceImage(const PreparedTable& t, const Divergence& d,
                          const std::filesystem::path& path) {
  const std::vector<DriveCase>& drives = t.drives;
  const std::size_t other = d.runs.front();
  // Named without quotes: the image's pixel font has none.
  const auto name = [&](std::size_t r) {
    return drives[r].label + " on " + std::to_string(drives[r].threads) +
           (drives[r].threads == 1 ? " thread" : " threads");
  };
  const io::FrameData a = stateAfterTick(t.effect(), drives.front(), d.tick);
  const io::FrameData b = stateAfterTick(t.effect(), drives[other], d.tick);
  DifferenceSummary summary;
  renderDifference(a, b, name(0), name(other), d.tick, 1280, 720, &summary).writePng(path);
  std::printf("difference image: %s (tick %" PRId64
              ", %s against %s: %zu particles differ, by "
              "up to %.6g m)\n",
              path.c_str(), d.tick, name(0).c_str(), name(other).c_str(), summary.differing,
              summary.largest);
}

// The verdict under the table, and its exit code: 0 when every run agrees at every tick.
int reportVerdict(const TableSettings& s, const PreparedTable& t,
                  const std::vector<DriveTrace>& traces) {
  const Divergence d = firstDivergence(traces);
  std::printf("\n");
  if (d.tick < 0) {
    std::printf(
        "verdict: all %zu runs agree bit for bit after every one of %" PRId64
        " ticks (state-hash %s)\n",
        traces.size(), t.lastTick,
        traces.front().hashes.empty() ? "-" : hashToHex(traces.front().hashes.back()).c_str());
    if (s.diffImage) std::printf("no difference image: the runs agree\n");
    return kExitOk;
  }
  std::printf("verdict: runs part at tick %" PRId64 " (t = %.6g s):", d.tick,
              static_cast<double>(d.tick) / static_cast<double>(t.rate));
  for (std::size_t r : d.runs)
    std::printf(" '%s, %d thread(s)'", traces[r].label.c_str(), traces[r].threads);
  std::printf(" differ from '%s, %d thread(s)'\n", traces.front().label.c_str(),
              traces.front().threads);
  std::printf(
      "rerun two of them with `tickfx run ... --trace FILE` and compare the files to see the state "
      "there\n");
  if (s.diffImage) writeDifferenceImage(t, d, *s.diffImage);
  return kExitFailure;
}

}  // namespace

int determinismCommand(Arguments& args) {
  if (args.flag("--help")) {
    std::fputs(kDeterminismHelp, stdout);
    return kExitOk;
  }
  std::vector<std::string> overrides = args.values("--set");
  const auto record = args.value("--record");
  const auto compare = args.value("--compare");
  if (record || compare) return logCommand(args, overrides, record, compare);
  const TableSettings settings = readTableSettings(args, std::move(overrides));
  const std::optional<PreparedTable> table = prepareTable(settings);
  if (!table) return kExitUsage;
  const std::optional<std::vector<DriveTrace>> traces = runDrives(settings, *table);
  if (!traces) return kExitUsage;
  return reportVerdict(settings, *table, *traces);
}

}  // namespace tickfx::app
