// What `tickfx run` is asked to do: the command line as read, then checked and resolved against
// the effect's own settings, once, before anything runs.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "app/Arguments.h"
#include "app/FrameTimes.h"
#include "io/cache/FrameCaches.h"
#include "io/effect/EffectParser.h"
#include "particles/Shard.h"

namespace tickfx::app {

/// The options of `tickfx run` as the command line gives them, unchecked. Reading them consumes
/// them from `args` in a fixed order (an option's value may look like another option).
struct RunArguments {
  std::string effectPath;
  std::vector<std::string> overrides;  // --set
  std::optional<std::string> seconds, frames, fps, jitter, frameTimes;
  std::optional<std::string> out, format, dump, trace;
  std::optional<std::string> checkpointEvery, checkpointDir, resume;
  std::optional<std::string> threads, vdbCompression, vdbPositions;
  std::optional<std::string> shard;
  bool durable = false;
  bool overlap = true;  // not --no-overlap
  bool printHash = false;
  bool quiet = false;
  bool profile = false;
};

/// Reads every option of `tickfx run` (after --help) and the effect file; UsageError for an
/// option without its value, an unknown one, or not exactly one effect file.
RunArguments readRunArguments(Arguments& args);

/// The frames of a run and how its summary names them ("at 24 fps", "jittered frames (seed 3)").
struct FramePlan {
  FrameSchedule schedule;
  std::string description;
};

/// The run's settings: every option checked and resolved against the effect's defaults.
struct RunSettings {
  std::string effectPath;
  FramePlan frames;
  std::optional<int> threads;  // --threads, else the effect's
  /// Where and how the caches are written; no formats: none are.
  io::CacheTargets caches;
  std::int64_t checkpointEvery = 0;  // 0: no checkpoints
  std::filesystem::path checkpointDir;
  std::optional<std::string> resume, dump, trace;
  bool overlap = true;
  bool printHash = false;
  bool quiet = false;
  bool profile = false;  // --profile: print where the wall time went, phase by phase
  /// --shard I/N: the part of the run this one simulates (0/1 is the whole run, as a shard). A
  /// shard writes its final state (finalStatePath()) and manifest beside its caches.
  std::optional<Shard> shard;

  /// Frames a second of the run's frame rate (--fps, else the effect's): a USD layer's time
  /// codes per second.
  double framesPerSecond = 24.0;

  bool writesCaches() const { return !caches.formats.empty(); }
  /// DIR/EFFECT.usda: the run's USD layer, when it writes one.
  std::filesystem::path usdaPath() const;
  /// DIR/checkpoint_000012.tfxc: the checkpoint written after `frame`.
  std::filesystem::path checkpointPath(std::int64_t frame) const;
  /// DIR/final.tfxc: a shard's state at the run's end, which `tickfx merge` merges.
  std::filesystem::path finalStatePath() const;
};

/// Checks `arguments` against `load`'s effect (loaded) and resolves the defaults it leaves to
/// the effect. Throws UsageError for a bad option; a length past the limits is printed to stderr
/// and gives nothing (exit 2).
std::optional<RunSettings> resolveRunSettings(const RunArguments& arguments,
                                              const io::LoadResult& load);

}  // namespace tickfx::app
