// tickfx run: simulate an effect through the fixed-step driver and write one cache per frame.
// The command runs in stages: its settings (app/RunSettings.h), the prepared run (the system built
// and resumed, every output checked), the frames, then the report.
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "app/Commands.h"
#include "app/FrameTimes.h"
#include "app/Interrupt.h"
#include "app/LoadEffect.h"
#include "app/ProgressLine.h"
#include "app/RunSettings.h"
#include "io/cache/BackgroundWriter.h"
#include "io/cache/FrameCaches.h"
#include "io/cache/FrameData.h"
#include "io/cache/ShardManifest.h"
#include "io/cache/UsdaPointsWriter.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectLint.h"
#include "io/effect/EffectParser.h"
#include "io/state/Checkpoint.h"
#include "io/state/StateDump.h"
#include "io/util/AtomicFile.h"
#include "particles/Clock.h"
#include "particles/ParticleSystem.h"
#include "particles/PhaseProfile.h"
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
    "  --format LIST         comma-separated: csv, ply, vdb (OpenVDB points), usda (one USD\n"
    "                        layer a run, DIR/EFFECT.usda); 'none' writes no caches\n"
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
    "Shards (one run split over processes or machines; docs/sharding.md):\n"
    "  --shard I/N           simulate shard I (from 0) of N only, into DIR/shard_I_of_N unless\n"
    "                        --out says where, with the shard's final state and shard.toml;\n"
    "                        `tickfx merge` makes the whole run's files of every shard's\n"
    "  Ctrl-C (SIGINT) or SIGTERM finishes the frame in hand, writes its checkpoint (with\n"
    "  --checkpoint-every), says how to resume and exits 130 or 143; a second one stops at once.\n"
    "Simulation:\n"
    "  --set key.path=value  override a key of the effect (repeatable), e.g. "
    "simulation.integrator=rk4\n"
    "  --threads N           worker threads (default: the effect's, 0 = all cores)\n"
    "  --quiet               no summary (errors, warnings and --hash lines still print)\n"
    "  --profile             print where the wall time went, phase by phase, and the share of\n"
    "                        each that ran on one thread (docs/performance.md)\n";

// ---- the prepared run -------------------------------------------------------------------------

// A run ready for its first frame: the system built (and resumed from a checkpoint), its lint
// printed, every output checked writable and the cache writer made. The frames advance it.
struct PreparedRun {
  PreparedRun(const io::EffectSettings& runEffect, std::uint64_t fingerprint, FrameSchedule frames)
      : effect(runEffect), effectHash(fingerprint), schedule(std::move(frames)) {}

  const io::EffectSettings& effect;
  std::uint64_t effectHash;  // the effect's fingerprint, which its checkpoints carry
  FrameSchedule schedule;
  std::unique_ptr<ParticleSystem> system;
  std::vector<io::Diagnostic> lint;
  std::int64_t firstFrame = 1;  // the first frame this run simulates
  Flicks elapsed = 0;           // the run's time: where it starts, then the last frame's end
  // --trace: the state hash after every tick.
  std::vector<std::pair<std::int64_t, std::uint64_t>> tickHashes;
  // Frame f's files are written while frame f + 1 simulates; the writer holds at most one frame.
  std::optional<io::BackgroundWriter> writer;
  // The run's USD layer (--format usda), written whole by finishUsda(); and the cache targets
  // that append to it.
  std::unique_ptr<io::UsdaPointsWriter> usda;
  io::CacheTargets targets;
};

// Writes the run's USD layer from the frames written so far (the writer drained), if it has one.
void finishUsda(PreparedRun& run) {
  if (run.usda && run.usda->hasFrames()) {
    run.usda->finish();
    run.usda.reset();
  }
}

// Reads --resume's checkpoint into the system and skips the frames it covers. False after
// printing why it does not fit this run: verified whole before anything is written, a refusal is
// bad input (exit 2).
bool resumeRun(PreparedRun& run, const std::string& checkpoint) {
  io::CheckpointInfo info;
  try {
    info = io::readCheckpoint(checkpoint, *run.system, run.effectHash);
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return false;
  }
  for (std::int64_t f = 0; f < info.frame; ++f) {
    const std::optional<Flicks> d = run.schedule.next();
    if (!d) break;
    run.elapsed += *d;
  }
  if (run.schedule.framesDone() != info.frame || run.elapsed != info.elapsed) {
    std::fprintf(
        stderr,
        "%s: error: the checkpoint is at frame %lld (%.9g s) but this run's frame %lld ends at "
        "%.9g s (give the frame options of the run that wrote it)\n",
        checkpoint.c_str(), static_cast<long long>(info.frame), secondsFromFlicks(info.elapsed),
        static_cast<long long>(info.frame), secondsFromFlicks(run.elapsed));
    return false;
  }
  run.firstFrame = info.frame + 1;
  return true;
}

// Makes the run's system simulate its shard. False after printing why the effect cannot be
// sharded exactly (bad input: exit 2): the rules are particles/Shard.h's and docs/sharding.md's.
bool shardRun(PreparedRun& run, const RunSettings& s) {
  const auto refuse = [&](const std::string& why) {
    std::fprintf(stderr, "%s: error: cannot shard: %s\n", s.effectPath.c_str(), why.c_str());
    return false;
  };
  for (const EmitterSettings& e : run.effect.emitters) {
    if (!e.sub.parent.empty()) {
      return refuse("emitter '" + e.name + "' emits at the events of '" + e.sub.parent +
                    "': a child's id counts the events of every shard before it, which no "
                    "shard knows alone (run this effect unsharded)");
    }
  }
  // The bound covers every tick the run's frames reach.
  const __int128 flicks =
      static_cast<__int128>(run.schedule.total()) * run.effect.simulation.stepRateHz;
  const auto ticks =
      static_cast<std::int64_t>((flicks + kFlicksPerSecond - 1) / kFlicksPerSecond) + 1;
  const std::uint64_t bound = run.system->particleBound(ticks);
  const std::size_t cap = run.system->pool().maxParticles();
  if (bound > cap) {
    return refuse("simulation.max_particles = " + std::to_string(cap) + " may bind: up to " +
                  std::to_string(bound) +
                  " particles may be alive at once (from the emitters' schedules and longest "
                  "lifetimes), and a cap is a count over every shard (give max_particles >= " +
                  std::to_string(bound) + " to shard)");
  }
  run.system->setShard(*s.shard);
  return true;
}

// A shard's end: its final state, then its manifest, which says the folder is whole.
void finishShard(const RunSettings& s, const PreparedRun& run, std::int64_t lastFrame) {
  const profile::PhaseScope phase(profile::Phase::Checkpoint);
  io::writeCheckpoint(s.finalStatePath(), *run.system,
                      io::CheckpointInfo{run.effectHash, lastFrame, run.elapsed});
  io::ShardManifest m;
  m.effect = s.effectPath;
  m.effectHash = hashToHex(run.effectHash);
  m.seed = run.effect.simulation.seed;
  m.stepRateHz = run.effect.simulation.stepRateHz;
  m.integrator = run.effect.simulation.integrator;
  m.shard = *s.shard;
  m.formats = s.caches.formats;
  m.vdb = s.caches.vdbOptions;
  m.framesPerSecond = s.framesPerSecond;
  m.lastFrame = lastFrame;
  m.ticks = run.system->tickCount();
  if (std::find(m.formats.begin(), m.formats.end(), io::CacheFormat::Usda) != m.formats.end())
    m.usdaName = s.usdaPath().filename().string();
  io::writeShardManifest(m, s.caches.directory);
}

// Every output is checked before the first tick: an unwritable --dump must not turn up after
// hours of caches. False after printing why.
bool checkOutputs(const RunSettings& s, std::int64_t firstFrame) {
  try {
    if (s.writesCaches() || s.shard) std::filesystem::create_directories(s.caches.directory);
    // A shard's folder is whole once its manifest is written again at its end.
    if (s.shard) std::filesystem::remove(io::shardManifestPath(s.caches.directory));
    if (s.checkpointEvery > 0) std::filesystem::create_directories(s.checkpointDir);
    if (s.writesCaches())
      io::requireWritable(io::cacheFilePath(s.caches.directory, firstFrame, "tmp"));
    if (s.checkpointEvery > 0) io::requireWritable(s.checkpointPath(firstFrame));
    if (s.dump) io::requireWritable(*s.dump);
    if (s.trace) io::requireWritable(*s.trace);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return false;
  }
  return true;
}

// The run of `effect` that `s` asks for, ready for its first frame; nothing after printing why
// not (bad input: exit 2).
std::unique_ptr<PreparedRun> prepareRun(const RunSettings& s, const io::EffectSettings& effect,
                                        std::uint64_t fingerprint) {
  auto run = std::make_unique<PreparedRun>(effect, fingerprint, s.frames.schedule);
  // Building loads the effect's vector fields: a file that does not load is bad input, reported
  // like an effect error, before anything is written. The lint comes after, so that such a file
  // is reported once, as the error. An offline run has no wall clock to keep up with: every
  // tick its frames cover runs (the effect's max_ticks_per_frame is for real-time hosts).
  try {
    run->system = io::buildOfflineSystem(effect, s.threads);
  } catch (const io::BuildError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return nullptr;
  }
  run->lint = io::lintEffect(effect, &run->system->forces(), run->system->colliders());
  for (const io::Diagnostic& d : run->lint) std::fprintf(stderr, "%s\n", d.format().c_str());
  if (s.shard && !shardRun(*run, s)) return nullptr;
  if (s.resume && !resumeRun(*run, *s.resume)) return nullptr;
  if (!checkOutputs(s, run->firstFrame)) return nullptr;
  if (s.trace) {
    PreparedRun* const r = run.get();
    r->system->setTickObserver([r](const ParticleSystem& system) {
      r->tickHashes.emplace_back(system.tickCount(), stateHash(system));
    });
  }
  run->targets = s.caches;
  if (std::find(s.caches.formats.begin(), s.caches.formats.end(), io::CacheFormat::Usda) !=
      s.caches.formats.end()) {
    if (s.resume) {
      std::fprintf(stderr,
                   "%s: error: --resume cannot continue a .usda layer, which a run writes whole "
                   "(expected --format without usda, or the run from its start)\n",
                   s.resume->c_str());
      return nullptr;
    }
    try {
      run->usda = std::make_unique<io::UsdaPointsWriter>(
          s.usdaPath(), io::UsdaLayerSettings{s.framesPerSecond, "particles"}, s.caches.durability);
    } catch (const io::WriteError& e) {
      std::fprintf(stderr, "%s\n", e.what());
      return nullptr;
    }
    run->targets.usda = run->usda.get();
  }
  const io::CacheTargets* const targets = &run->targets;
  run->writer.emplace([targets](const io::FrameData& d) { io::writeFrameCaches(d, *targets); },
                      s.overlap && s.writesCaches());
  return run;
}

// ---- what a stopped run reports -----------------------------------------------------------------

// "DIR (frame_0001 to frame_0036)": where a run's caches are, as its messages name them.
std::string cacheRange(const std::filesystem::path& dir, std::int64_t first, std::int64_t last) {
  char frames[64];
  std::snprintf(frames, sizeof frames, " (frame_%04lld to frame_%04lld)",
                static_cast<long long>(first), static_cast<long long>(last));
  return dir.string() + frames;
}

// After a stop: which cache files are there, every one whole.
void reportWritten(const RunSettings& s, std::int64_t firstFrame, std::int64_t lastWritten) {
  if (s.writesCaches() && lastWritten >= firstFrame) {
    std::fprintf(stderr, "caches written: %s\n",
                 cacheRange(s.caches.directory, firstFrame, lastWritten).c_str());
  }
}

void reportInterruption(const RunSettings& s, const PreparedRun& run, int signal,
                        std::int64_t lastFrame,
                        const std::optional<std::filesystem::path>& resumeFrom) {
  const char* const effectPath = s.effectPath.c_str();
  if (lastFrame >= run.firstFrame) {
    std::fprintf(stderr, "%s: interrupted by %s after frame %lld (%.9g s)\n", effectPath,
                 InterruptCatcher::name(signal), static_cast<long long>(lastFrame),
                 secondsFromFlicks(run.elapsed));
  } else {
    std::fprintf(stderr, "%s: interrupted by %s before the first frame\n", effectPath,
                 InterruptCatcher::name(signal));
  }
  reportWritten(s, run.firstFrame, lastFrame);
  if (resumeFrom) {
    std::fprintf(stderr,
                 "checkpoint: %s\nresume with: tickfx run %s --resume %s (and the options "
                 "of this run)\n",
                 resumeFrom->c_str(), effectPath, resumeFrom->c_str());
  } else if (s.checkpointEvery == 0) {
    std::fprintf(stderr, "no checkpoint: run with --checkpoint-every N to be able to resume\n");
  }
}

void reportNonfiniteStop(const RunSettings& s, const PreparedRun& run, std::int64_t lastWritten) {
  std::fprintf(stderr,
               "%s: error: %s; the run stops there (simulation.nonfinite = \"stop\"; \"kill\" "
               "removes such particles instead)\n",
               s.effectPath.c_str(), run.system->nonfiniteStop()->describe().c_str());
  if (const io::Diagnostic* cause = io::instabilityWarning(run.lint)) {
    std::fprintf(stderr, "likely cause: %s\n", cause->format().c_str());
  }
  reportWritten(s, run.firstFrame, lastWritten);
}

// ---- the frames ---------------------------------------------------------------------------------

using SteadyClock = std::chrono::steady_clock;

double secondsSince(SteadyClock::time_point start) {
  return std::chrono::duration<double>(SteadyClock::now() - start).count();
}

// The frame loop: each frame simulated, captured and handed to the writer, with its checkpoint.
// Ctrl-C (or SIGTERM) finishes the frame in hand and stops there, for as long as the loop lives.
class FrameLoop {
 public:
  FrameLoop(const RunSettings& settings, PreparedRun& run)
      : s_(settings), run_(run), resumedAt_(run.elapsed), lastFrame_(run.firstFrame - 1) {}

  // Runs every frame left in the schedule. The exit code when the run stops early (reported),
  // else nothing.
  std::optional<int> run();

  std::int64_t lastFrame() const { return lastFrame_; }
  double simulationSeconds() const { return simulationSeconds_; }
  double wallSeconds() const { return wallSeconds_; }

 private:
  bool simulateFrame(Flicks duration);
  void showProgress(std::int64_t f);
  int stopAtNonfinite();
  int stopAtInterruption(int signal);
  int stopAtWriteError(const io::WriteError& e);
  // Every file of frames up to this one is whole (once the writer is idle).
  std::int64_t writtenThrough() const {
    return s_.writesCaches() ? run_.writer->lastWritten().value_or(run_.firstFrame - 1)
                             : lastFrame_;
  }

  const RunSettings& s_;
  PreparedRun& run_;
  const SteadyClock::time_point wallStart_ = SteadyClock::now();
  ProgressLine progress_{"frames"};
  const Flicks resumedAt_;  // the bar and the time left count this run's part alone
  std::int64_t lastFrame_;  // the last frame simulated
  double simulationSeconds_ = 0.0;
  double wallSeconds_ = 0.0;
  const InterruptCatcher interrupts_;
};

std::optional<int> FrameLoop::run() {
  try {
    while (InterruptCatcher::caught() == 0) {
      const std::optional<Flicks> duration = run_.schedule.next();
      if (!duration) break;
      if (!simulateFrame(*duration)) return stopAtNonfinite();
    }
    {
      const profile::PhaseScope phase(profile::Phase::CacheWrite);
      run_.writer->finish();
    }
    if (const int signal = InterruptCatcher::caught()) return stopAtInterruption(signal);
    finishUsda(run_);
  } catch (const io::WriteError& e) {
    return stopAtWriteError(e);
  }
  progress_.finish();
  wallSeconds_ = secondsSince(wallStart_);
  return std::nullopt;
}

// The schedule's next frame, of `duration`. False when a tick of it went non-finite.
bool FrameLoop::simulateFrame(Flicks duration) {
  const std::int64_t f = run_.schedule.framesDone();
  const auto simulationStart = SteadyClock::now();
  run_.system->advance(duration);
  if (run_.system->nonfiniteStop()) return false;
  run_.elapsed += duration;
  std::optional<io::FrameData> data;
  if (s_.writesCaches()) {
    const profile::PhaseScope phase(profile::Phase::Capture);
    data = io::captureFrame(*run_.system, f, secondsFromFlicks(run_.elapsed));
  }
  simulationSeconds_ += secondsSince(simulationStart);
  if (data) {
    const profile::PhaseScope phase(profile::Phase::CacheWrite);
    run_.writer->submit(std::move(*data));
  }
  if (s_.checkpointEvery > 0 && f % s_.checkpointEvery == 0) {
    // A checkpoint at frame f promises the caches through f: a run resumed from it writes
    // from f + 1 on.
    {
      const profile::PhaseScope phase(profile::Phase::CacheWrite);
      run_.writer->finish();
    }
    const profile::PhaseScope phase(profile::Phase::Checkpoint);
    io::writeCheckpoint(s_.checkpointPath(f), *run_.system,
                        io::CheckpointInfo{run_.effectHash, f, run_.elapsed});
  }
  lastFrame_ = f;
  showProgress(f);
  return true;
}

void FrameLoop::showProgress(std::int64_t f) {
  const Flicks total = run_.schedule.total();
  char detail[96];
  std::snprintf(detail, sizeof detail, "t = %.3f of %.3f s, %zu particles",
                secondsFromFlicks(run_.elapsed), secondsFromFlicks(total),
                run_.system->pool().size());
  progress_.update(f - run_.firstFrame + 1, -1,
                   static_cast<double>(run_.elapsed - resumedAt_) /
                       static_cast<double>(std::max<Flicks>(1, total - resumedAt_)),
                   detail);
}

int FrameLoop::stopAtNonfinite() {
  // The frame holding the tick is not written; those before it are, whole (the USD layer too).
  run_.writer->finish();
  finishUsda(run_);
  progress_.finish();
  reportNonfiniteStop(s_, run_, writtenThrough());
  return kExitFailure;
}

int FrameLoop::stopAtInterruption(int signal) {
  finishUsda(run_);
  progress_.finish();
  // The state is that of the end of lastFrame: a checkpoint of it, unless one was just made.
  std::optional<std::filesystem::path> resumeFrom;
  if (s_.checkpointEvery > 0 && lastFrame_ >= run_.firstFrame) {
    resumeFrom = s_.checkpointPath(lastFrame_);
    if (lastFrame_ % s_.checkpointEvery != 0) {
      io::writeCheckpoint(*resumeFrom, *run_.system,
                          io::CheckpointInfo{run_.effectHash, lastFrame_, run_.elapsed});
    }
  }
  reportInterruption(s_, run_, signal, lastFrame_, resumeFrom);
  return 128 + signal;
}

int FrameLoop::stopAtWriteError(const io::WriteError& e) {
  run_.writer->drain();
  progress_.finish();
  std::fprintf(stderr, "%s\n", e.what());
  reportWritten(s_, run_.firstFrame, writtenThrough());
  return kExitFailure;
}

// ---- the report ---------------------------------------------------------------------------------

// The files of the run's end: --dump's last state and --trace's hash of every tick.
void writeEndFiles(const RunSettings& s, const PreparedRun& run, std::int64_t lastFrame) {
  // The dump shows the run's end time, as the last cache frame does.
  if (s.dump) {
    io::writeStateDump(io::captureFrame(*run.system, lastFrame, secondsFromFlicks(run.elapsed)),
                       *s.dump);
  }
  if (s.trace) {
    io::writeFileAtomically(*s.trace, [&](std::ostream& os) {
      os << "tick,state_hash\n";
      for (const auto& [tick, hash] : run.tickHashes) os << tick << ',' << hashToHex(hash) << '\n';
    });
  }
}

// What the run did and what it cost (not with --quiet).
void printRunSummary(const RunSettings& s, const PreparedRun& run, const FrameLoop& frames) {
  const ParticleSystem& system = *run.system;
  const ParticlePool& pool = system.pool();
  const SystemSettings& simulation = run.effect.simulation;
  std::printf("%s: %lld frames %s, %.6g s simulated (%lld ticks at %lld Hz, %s)\n",
              s.effectPath.c_str(), static_cast<long long>(frames.lastFrame()),
              s.frames.description.c_str(), secondsFromFlicks(run.elapsed),
              static_cast<long long>(system.tickCount()),
              static_cast<long long>(simulation.stepRateHz), simulation.integrator.c_str());
  std::printf("particles alive: %zu (emitted %llu, refused by max_particles: %llu)\n", pool.size(),
              static_cast<unsigned long long>(pool.nextId() + pool.droppedSpawns()),
              static_cast<unsigned long long>(pool.droppedSpawns()));
  if (simulation.nonfinite == NonfinitePolicy::Kill) {
    std::printf("removed for a non-finite position or velocity: %llu\n",
                static_cast<unsigned long long>(system.nonfiniteKilled()));
  }
  const double wall = frames.wallSeconds();
  if (!s.writesCaches()) {
    std::printf("wall time: %.3f s\n", wall);
  } else {
    // What writing cost on top of simulating: the overlap is the time both went on at once.
    const double simulating = frames.simulationSeconds();
    const double writing = run.writer->writeSeconds();
    std::printf("wall time: %.3f s (simulating %.3f s, writing caches %.3f s, %s %.3f s)\n", wall,
                simulating, writing, s.overlap ? "overlapped" : "not overlapped (--no-overlap):",
                std::max(0.0, simulating + writing - wall));
  }
  const std::vector<io::CacheFormat>& formats = s.caches.formats;
  const bool usda =
      std::find(formats.begin(), formats.end(), io::CacheFormat::Usda) != formats.end();
  if (formats.size() > (usda ? 1u : 0u) && frames.lastFrame() >= run.firstFrame) {
    std::printf("caches: %s\n",
                cacheRange(s.caches.directory, run.firstFrame, frames.lastFrame()).c_str());
  }
  if (usda && frames.lastFrame() >= run.firstFrame) {
    std::printf("usd layer: %s (time codes %lld to %lld)\n", s.usdaPath().c_str(),
                static_cast<long long>(run.firstFrame), static_cast<long long>(frames.lastFrame()));
  }
  if (s.dump) std::printf("state dump: %s\n", s.dump->c_str());
}

}  // namespace

int runCommand(Arguments& args) {
  if (args.flag("--help")) {
    std::fputs(kRunHelp, stdout);
    return kExitOk;
  }
  const RunArguments arguments = readRunArguments(args);
  if (arguments.profile) profile::start();
  std::optional<profile::PhaseScope> loading(std::in_place, profile::Phase::Load);
  // Everything that can be wrong with the request is found before anything is written.
  const io::LoadResult load = loadEffectReporting(arguments.effectPath, arguments.overrides);
  if (!load.ok()) return kExitUsage;
  const std::optional<RunSettings> settings = resolveRunSettings(arguments, load);
  if (!settings) return kExitUsage;
  // --threads N holds every loop of the run to N threads, the caches' encoding too (the system
  // keeps its ticks to N in its own arena; the rest would take every core).
  const int threads = settings->threads.value_or(load.effect->simulation.threads);
  std::optional<tbb::global_control> threadLimit;
  if (threads > 0) {
    threadLimit.emplace(tbb::global_control::max_allowed_parallelism,
                        static_cast<std::size_t>(threads));
  }
  std::unique_ptr<PreparedRun> run = prepareRun(*settings, *load.effect, load.fingerprint);
  if (!run) return kExitUsage;
  loading.reset();

  FrameLoop frames(*settings, *run);
  if (const std::optional<int> stopped = frames.run()) return *stopped;
  writeEndFiles(*settings, *run, frames.lastFrame());
  if (settings->shard) finishShard(*settings, *run, frames.lastFrame());
  if (!settings->quiet) printRunSummary(*settings, *run, frames);
  if (settings->printHash) {
    std::printf("state-hash: %s\n", hashToHex(stateHash(*run->system)).c_str());
    std::printf("ticks: %lld\n", static_cast<long long>(run->system->tickCount()));
  }
  if (settings->profile) {
    const double writerSeconds = run->writer->writeSeconds();
    {
      const profile::PhaseScope phase(profile::Phase::Release);
      run.reset();
    }
    const profile::Report report = profile::stop();
    std::fputs(
        report.format(threads > 0 ? threads : tbb::this_task_arena::max_concurrency()).c_str(),
        stdout);
    if (settings->writesCaches() && settings->overlap) {
      std::printf(
          "  the cache writer's own thread: %.3f s encoding and writing, beside the "
          "phases above\n",
          writerSeconds);
    }
  }
  return kExitOk;
}

}  // namespace tickfx::app
