// tickfx run: simulate an effect through the fixed-step driver and write one cache per frame.
#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "app/Commands.h"
#include "app/Interrupt.h"
#include "app/LoadEffect.h"
#include "app/ProgressLine.h"
#include "io/util/AtomicFile.h"
#include "app/FrameTimes.h"
#include "io/cache/BackgroundWriter.h"
#include "io/state/Checkpoint.h"
#include "io/cache/CsvCache.h"
#include "io/cache/FrameCaches.h"
#include "io/cache/FrameData.h"
#include "io/cache/PlyCache.h"
#include "io/state/StateDump.h"
#include "io/cache/VdbPointCache.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectLint.h"
#include "io/effect/EffectParser.h"
#include "particles/StateHash.h"

namespace tickfx::app {
namespace {

constexpr const char* kRunHelp =
    "usage: tickfx run EFFECT.toml [options]\n"
    "\n"
    "Simulates EFFECT.toml and writes one interpolated cache per frame (frame_0001.csv, ...).\n"
    "Frame times (the default comes from the effect's [output] table):\n"
    "  --seconds S           run for S seconds (the last frame is shortened to end exactly at S)\n"
    "  --frames N            run for N frames\n"
    "  --fps F               frames of 1/F s; F an integer or a ratio such as 30000/1001\n"
    "  --jitter SEED         seeded random frame durations in [1/240 s, 1/10 s] ending exactly at "
    "S\n"
    "  --frame-times FILE    one frame duration in seconds a line\n"
    "Output:\n"
    "  --out DIR             cache directory (default: the effect's output.directory)\n"
    "  --format LIST         comma-separated: csv, ply, vdb (OpenVDB points); 'none' writes no\n"
    "                        caches\n"
    "  --hash                print 'state-hash: <16 hex digits>' and 'ticks: N' of the last tick\n"
    "  --dump FILE           write the last tick's state as CSV: id,px,py,pz,vx,vy,vz,age\n"
    "  --trace FILE          write the state hash after every tick (tick,state_hash): diff two\n"
    "                        traces to find the first tick where two runs part\n"
    "  --vdb-compression C   none (default) or blosc: lossless, smaller, slower to write\n"
    "  --vdb-positions P     exact (default, every bit) or fixed16 (16-bit, to 1/65535 m)\n"
    "  --durable             flush each cache to the disk (fsync) before counting it written\n"
    "  --no-overlap          write each frame before simulating the next (by default frame f is\n"
    "                        written on a thread of its own while frame f + 1 simulates)\n"
    "Checkpoints:\n"
    "  --checkpoint-every N  write the whole state after every N-th frame ...\n"
    "  --checkpoint-dir D    ... into D/checkpoint_<frame>.tfxc (default: the cache directory)\n"
    "  --resume FILE         continue from a checkpoint of this effect (same --set and frame\n"
    "                        options as the run that wrote it); reaches the same state hash\n"
    "  Ctrl-C (SIGINT) or SIGTERM finishes the frame in hand, writes its checkpoint (with\n"
    "  --checkpoint-every), says how to resume and exits 130 or 143; a second one stops at once.\n"
    "Simulation:\n"
    "  --set key.path=value  override a key of the effect (repeatable), e.g. "
    "simulation.integrator=rk4\n"
    "  --threads N           worker threads (default: the effect's, 0 = all cores)\n"
    "  --quiet               no summary (errors, warnings and --hash lines still print)\n";

std::vector<io::CacheFormat> parseFormats(const std::string& text) {
  std::vector<io::CacheFormat> formats;
  if (text == "none") return formats;
  std::stringstream list(text);
  std::string name;
  while (std::getline(list, name, ',')) {
    const std::optional<io::CacheFormat> f = io::cacheFormatFromName(name);
    if (!f) {
      throw UsageError("run: --format: unknown format '" + name +
                       "' (expected csv, ply, vdb or none)");
    }
    formats.push_back(*f);
  }
  if (formats.empty())
    throw UsageError("run: --format: empty list (expected csv, ply, vdb or none)");
  return formats;
}

struct FramePlan {
  FrameSchedule schedule;
  std::string description;
};

// The run's length comes from the effect (or --seconds / --frames), whatever the frame rate:
// --fps only says how that length is cut into frames.
FramePlan planFrames(const io::OutputSettings& output, const std::optional<std::string>& seconds,
                     const std::optional<std::string>& frames,
                     const std::optional<std::string>& fps,
                     const std::optional<std::string>& jitter,
                     const std::optional<std::string>& frameTimes) {
  if (seconds && frames) throw UsageError("run: give --seconds or --frames, not both");
  if (jitter && frameTimes) throw UsageError("run: give --jitter or --frame-times, not both");
  if ((jitter || frameTimes) && fps)
    throw UsageError("run: --fps does not go with --jitter or --frame-times");
  if (frameTimes && (seconds || frames))
    throw UsageError("run: --frame-times sets the length; drop --seconds/--frames");
  if (jitter && frames) throw UsageError("run: --jitter needs a length in --seconds, not --frames");

  if (frameTimes) {
    return {FrameSchedule::recorded(readFrameTimes(*frameTimes)),
            "frame times from " + *frameTimes};
  }
  FrameRate rate = output.fps;
  if (fps) {
    try {
      rate = parseFrameRate(*fps);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("run: --fps: ") + e.what());
    }
  }
  Flicks total = 0;
  if (seconds) {
    total = flicksFromSeconds(parseNumber(*seconds, "run: --seconds", 0.0, io::kMaxRunSeconds));
  } else if (frames) {
    const long long count = parseInteger(*frames, "run: --frames", 0, io::kMaxRunFrames);
    total = lengthOfFrames(rate, count, "run: --frames");
  } else {
    total = lengthOfFrames(output.fps, output.frameCount(), "output length");
  }
  if (jitter) {
    const auto seed =
        static_cast<std::uint64_t>(parseInteger(*jitter, "run: --jitter", 0, INT64_MAX));
    return {FrameSchedule::jittered(seed, total), "jittered frames (seed " + *jitter + ")"};
  }
  const std::string rateText =
      std::to_string(rate.numerator) +
      (rate.denominator == 1 ? "" : "/" + std::to_string(rate.denominator));
  return {FrameSchedule::fixedRate(rate, total), "at " + rateText + " fps"};
}

// A --vdb-* option's value, by the names VdbCacheOptions gives.
template <typename Named>
auto parseVdbChoice(const std::string& option, const std::string& value,
                    const std::vector<std::string>& names, Named named) {
  const auto choice = named(value);
  if (!choice) {
    throw UsageError("run: " + option + ": unknown value '" + value + "' (expected " +
                     joinWords(names, " or ") + ")");
  }
  return *choice;
}

// "DIR (frame_0001 to frame_0036)": where a run's caches are, as its messages name them.
std::string cacheRange(const std::filesystem::path& dir, std::int64_t first, std::int64_t last) {
  char frames[64];
  std::snprintf(frames, sizeof frames, " (frame_%04lld to frame_%04lld)",
                static_cast<long long>(first), static_cast<long long>(last));
  return dir.string() + frames;
}

// After a stop: which cache files are there, every one whole.
void reportWritten(std::int64_t lastWritten, std::int64_t firstFrame,
                   const std::optional<std::filesystem::path>& out) {
  if (out && lastWritten >= firstFrame) {
    std::fprintf(stderr, "caches written: %s\n", cacheRange(*out, firstFrame, lastWritten).c_str());
  }
}

void reportInterruption(const std::string& effectPath, int signal, std::int64_t lastFrame,
                        std::int64_t firstFrame, Flicks elapsed,
                        const std::optional<std::filesystem::path>& out,
                        const std::optional<std::filesystem::path>& resumeFrom,
                        bool checkpointing) {
  if (lastFrame >= firstFrame) {
    std::fprintf(stderr, "%s: interrupted by %s after frame %lld (%.9g s)\n", effectPath.c_str(),
                 InterruptCatcher::name(signal), static_cast<long long>(lastFrame),
                 secondsFromFlicks(elapsed));
  } else {
    std::fprintf(stderr, "%s: interrupted by %s before the first frame\n", effectPath.c_str(),
                 InterruptCatcher::name(signal));
  }
  reportWritten(lastFrame, firstFrame, out);
  if (resumeFrom) {
    std::fprintf(stderr,
                 "checkpoint: %s\nresume with: tickfx run %s --resume %s (and the options "
                 "of this run)\n",
                 resumeFrom->c_str(), effectPath.c_str(), resumeFrom->c_str());
  } else if (!checkpointing) {
    std::fprintf(stderr, "no checkpoint: run with --checkpoint-every N to be able to resume\n");
  }
}

void reportNonfiniteStop(const std::string& effectPath, const NonfiniteEvent& event,
                         const std::vector<io::Diagnostic>& lint, std::int64_t lastWritten,
                         std::int64_t firstFrame, const std::optional<std::filesystem::path>& out) {
  std::fprintf(stderr,
               "%s: error: %s; the run stops there (simulation.nonfinite = \"stop\"; \"kill\" "
               "removes such particles instead)\n",
               effectPath.c_str(), event.describe().c_str());
  if (const io::Diagnostic* cause = io::instabilityWarning(lint)) {
    std::fprintf(stderr, "likely cause: %s\n", cause->format().c_str());
  }
  reportWritten(lastWritten, firstFrame, out);
}

std::filesystem::path checkpointPath(const std::filesystem::path& dir, std::int64_t frame) {
  char name[64];
  std::snprintf(name, sizeof name, "checkpoint_%06" PRId64 ".tfxc", frame);
  return dir / name;
}

}  // namespace

int runCommand(Arguments& args) {
  if (args.flag("--help")) {
    std::fputs(kRunHelp, stdout);
    return kExitOk;
  }
  const std::vector<std::string> overrides = args.values("--set");
  const auto seconds = args.value("--seconds");
  const auto frames = args.value("--frames");
  const auto fps = args.value("--fps");
  const auto jitter = args.value("--jitter");
  const auto frameTimes = args.value("--frame-times");
  const auto out = args.value("--out");
  const auto format = args.value("--format");
  const auto dump = args.value("--dump");
  const auto trace = args.value("--trace");
  const auto checkpointEvery = args.value("--checkpoint-every");
  const auto checkpointDir = args.value("--checkpoint-dir");
  const auto resume = args.value("--resume");
  const auto threads = args.value("--threads");
  const auto vdbCompression = args.value("--vdb-compression");
  const auto vdbPositions = args.value("--vdb-positions");
  const bool durable = args.flag("--durable");
  const bool overlap = !args.flag("--no-overlap");
  const bool printHash = args.flag("--hash");
  const bool quiet = args.flag("--quiet");
  const std::string effectPath = args.positionals(1, "one effect file: tickfx run EFFECT.toml")[0];

  // Everything that can be wrong with the request is found before anything is written.
  const io::LoadResult load = loadEffectReporting(effectPath, overrides);
  if (!load.ok()) return kExitUsage;
  const io::EffectSettings& effect = *load.effect;

  const std::vector<io::CacheFormat> formats =
      format ? parseFormats(*format) : effect.output.formats;
  const std::filesystem::path outDir = out ? *out : effect.output.directory;
  std::optional<int> threadOverride;
  if (threads) {
    threadOverride = static_cast<int>(parseInteger(*threads, "run: --threads", 0, io::kMaxThreads));
  }
  std::optional<FramePlan> plan;
  try {
    plan.emplace(planFrames(effect.output, seconds, frames, fps, jitter, frameTimes));
  } catch (const std::runtime_error& e) {
    if (dynamic_cast<const UsageError*>(&e) != nullptr) throw;
    std::fprintf(stderr, "%s\n", e.what());
    return kExitUsage;
  }
  FrameSchedule& schedule = plan->schedule;

  std::int64_t every = 0;
  if (checkpointEvery)
    every = parseInteger(*checkpointEvery, "run: --checkpoint-every", 1, 1'000'000'000);
  if (checkpointDir && !checkpointEvery)
    throw UsageError("run: --checkpoint-dir needs --checkpoint-every");
  const std::filesystem::path checkpoints =
      checkpointDir ? std::filesystem::path(*checkpointDir) : outDir;
  const std::uint64_t effectHash = load.fingerprint;
  io::CacheTargets targets;
  targets.directory = outDir;
  targets.formats = formats;
  // What a VDB cache records of the run, for the pipeline that reads it.
  targets.vdbMetadata = io::VdbCacheMetadata{hashToHex(effectHash), effect.simulation.seed,
                                             effect.simulation.stepRateHz,
                                             effect.simulation.integrator, TICKFX_VERSION};
  targets.vdbOptions = effect.output.vdb;
  if (vdbCompression) {
    targets.vdbOptions.compression = parseVdbChoice(
        "--vdb-compression", *vdbCompression, io::vdbCompressionNames(), io::vdbCompressionNamed);
  }
  if (vdbPositions) {
    targets.vdbOptions.positions = parseVdbChoice("--vdb-positions", *vdbPositions,
                                                  io::vdbPositionsNames(), io::vdbPositionsNamed);
  }
  targets.durability = durable ? io::Durability::Synced : io::Durability::Renamed;

  // Building loads the effect's vector fields: a file that does not load is bad input, reported
  // like an effect error, before anything is written. The lint comes after, so that such a file
  // is reported once, as the error. An offline run has no wall clock to keep up with: every
  // tick its frames cover runs (the effect's max_ticks_per_frame is for real-time hosts).
  std::unique_ptr<ParticleSystem> system;
  try {
    system = io::buildOfflineSystem(effect, threadOverride);
  } catch (const io::BuildError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kExitUsage;
  }
  const std::vector<io::Diagnostic> lint = io::lintEffect(effect, &system->forces());
  for (const io::Diagnostic& d : lint) std::fprintf(stderr, "%s\n", d.format().c_str());
  std::int64_t firstFrame = 1;
  Flicks elapsed = 0;
  if (resume) {
    // Verified whole before anything is written; a refusal is bad input (exit 2).
    io::CheckpointInfo info;
    try {
      info = io::readCheckpoint(*resume, *system, effectHash);
    } catch (const std::runtime_error& e) {
      std::fprintf(stderr, "%s\n", e.what());
      return kExitUsage;
    }
    for (std::int64_t f = 0; f < info.frame; ++f) {
      const std::optional<Flicks> d = schedule.next();
      if (!d) break;
      elapsed += *d;
    }
    if (schedule.framesDone() != info.frame || elapsed != info.elapsed) {
      std::fprintf(
          stderr,
          "%s: error: the checkpoint is at frame %lld (%.9g s) but this run's frame %lld ends at "
          "%.9g s (give the frame options of the run that wrote it)\n",
          resume->c_str(), static_cast<long long>(info.frame), secondsFromFlicks(info.elapsed),
          static_cast<long long>(info.frame), secondsFromFlicks(elapsed));
      return kExitUsage;
    }
    firstFrame = info.frame + 1;
  }
  // Every output is checked before the first tick: an unwritable --dump must not turn up after
  // hours of caches.
  try {
    if (!formats.empty()) std::filesystem::create_directories(outDir);
    if (every > 0) std::filesystem::create_directories(checkpoints);
    if (!formats.empty()) io::requireWritable(io::cacheFilePath(outDir, firstFrame, "tmp"));
    if (every > 0) io::requireWritable(checkpointPath(checkpoints, firstFrame));
    if (dump) io::requireWritable(*dump);
    if (trace) io::requireWritable(*trace);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kExitUsage;
  }
  std::vector<std::pair<std::int64_t, std::uint64_t>> tickHashes;
  if (trace) {
    system->setTickObserver([&](const ParticleSystem& s) {
      tickHashes.emplace_back(s.tickCount(), stateHash(s.pool()));
    });
  }

  const auto wallStart = std::chrono::steady_clock::now();
  ProgressLine progress("frames");
  const Flicks resumedAt = elapsed;         // the bar and the time left count this run's part alone
  std::int64_t lastFrame = firstFrame - 1;  // the last frame simulated
  const std::optional<std::filesystem::path> cacheDir =
      formats.empty() ? std::nullopt : std::optional(outDir);
  // Frame f's files are written while frame f + 1 simulates; the writer holds at most one frame.
  io::BackgroundWriter writer(
      [&targets](const io::FrameData& d) { io::writeFrameCaches(d, targets); },
      overlap && !formats.empty());
  // Every file of frames up to this one is whole (once the writer is idle).
  const auto writtenThrough = [&] {
    return formats.empty() ? lastFrame : writer.lastWritten().value_or(firstFrame - 1);
  };
  double simulationSeconds = 0.0;
  const InterruptCatcher interrupts;
  try {
    while (InterruptCatcher::caught() == 0) {
      const std::optional<Flicks> duration = schedule.next();
      if (!duration) break;
      const std::int64_t f = schedule.framesDone();
      const auto simulationStart = std::chrono::steady_clock::now();
      system->advance(*duration);
      if (system->nonfiniteStop()) {
        // The frame holding the tick is not written; those before it are, whole.
        writer.finish();
        progress.finish();
        reportNonfiniteStop(effectPath, *system->nonfiniteStop(), lint, writtenThrough(),
                            firstFrame, cacheDir);
        return kExitFailure;
      }
      elapsed += *duration;
      std::optional<io::FrameData> data;
      if (!formats.empty()) data = io::captureFrame(*system, f, secondsFromFlicks(elapsed));
      simulationSeconds +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - simulationStart).count();
      if (data) writer.submit(std::move(*data));
      if (every > 0 && f % every == 0) {
        // A checkpoint at frame f promises the caches through f: a run resumed from it writes
        // from f + 1 on.
        writer.finish();
        io::writeCheckpoint(checkpointPath(checkpoints, f), *system,
                            io::CheckpointInfo{effectHash, f, elapsed});
      }
      lastFrame = f;
      char detail[96];
      std::snprintf(detail, sizeof detail, "t = %.3f of %.3f s, %zu particles",
                    secondsFromFlicks(elapsed), secondsFromFlicks(schedule.total()),
                    system->pool().size());
      progress.update(f - firstFrame + 1, -1,
                      static_cast<double>(elapsed - resumedAt) /
                          static_cast<double>(std::max<Flicks>(1, schedule.total() - resumedAt)),
                      detail);
    }
    writer.finish();
    if (const int signal = InterruptCatcher::caught()) {
      progress.finish();
      // The state is that of the end of lastFrame: a checkpoint of it, unless one was just made.
      std::optional<std::filesystem::path> resumeFrom;
      if (every > 0 && lastFrame >= firstFrame) {
        resumeFrom = checkpointPath(checkpoints, lastFrame);
        if (lastFrame % every != 0) {
          io::writeCheckpoint(*resumeFrom, *system,
                              io::CheckpointInfo{effectHash, lastFrame, elapsed});
        }
      }
      reportInterruption(effectPath, signal, lastFrame, firstFrame, elapsed, cacheDir, resumeFrom,
                         every > 0);
      return 128 + signal;
    }
  } catch (const io::WriteError& e) {
    writer.drain();
    progress.finish();
    std::fprintf(stderr, "%s\n", e.what());
    reportWritten(writtenThrough(), firstFrame, cacheDir);
    return kExitFailure;
  }
  progress.finish();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();

  // The dump shows the run's end time, as the last cache frame does.
  if (dump)
    io::writeStateDump(io::captureFrame(*system, lastFrame, secondsFromFlicks(elapsed)), *dump);
  if (trace) {
    io::writeFileAtomically(*trace, [&](std::ostream& os) {
      os << "tick,state_hash\n";
      for (const auto& [tick, hash] : tickHashes) os << tick << ',' << hashToHex(hash) << '\n';
    });
  }
  const ParticlePool& pool = system->pool();
  if (!quiet) {
    std::printf("%s: %lld frames %s, %.6g s simulated (%lld ticks at %lld Hz, %s)\n",
                effectPath.c_str(), static_cast<long long>(lastFrame), plan->description.c_str(),
                secondsFromFlicks(elapsed), static_cast<long long>(system->tickCount()),
                static_cast<long long>(effect.simulation.stepRateHz),
                effect.simulation.integrator.c_str());
    std::printf("particles alive: %zu (emitted %llu, refused by max_particles: %llu)\n",
                pool.size(), static_cast<unsigned long long>(pool.nextId() + pool.droppedSpawns()),
                static_cast<unsigned long long>(pool.droppedSpawns()));
    if (effect.simulation.nonfinite == NonfinitePolicy::Kill) {
      std::printf("removed for a non-finite position or velocity: %llu\n",
                  static_cast<unsigned long long>(system->nonfiniteKilled()));
    }
    if (formats.empty()) {
      std::printf("wall time: %.3f s\n", wall);
    } else {
      // What writing cost on top of simulating: the overlap is the time both went on at once.
      const double writing = writer.writeSeconds();
      std::printf("wall time: %.3f s (simulating %.3f s, writing caches %.3f s, %s %.3f s)\n", wall,
                  simulationSeconds, writing,
                  overlap ? "overlapped" : "not overlapped (--no-overlap):",
                  std::max(0.0, simulationSeconds + writing - wall));
    }
    if (!formats.empty() && lastFrame >= firstFrame) {
      std::printf("caches: %s\n", cacheRange(outDir, firstFrame, lastFrame).c_str());
    }
    if (dump) std::printf("state dump: %s\n", dump->c_str());
  }
  if (printHash) {
    std::printf("state-hash: %s\n", hashToHex(stateHash(pool)).c_str());
    std::printf("ticks: %lld\n", static_cast<long long>(system->tickCount()));
  }
  return kExitOk;
}

}  // namespace tickfx::app
