// Running one effect under many frame schedules and thread counts, and comparing the states.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "io/cache/FrameData.h"
#include "io/effect/EffectSettings.h"
#include "particles/Clock.h"

namespace tickfx::app {

/// One way to drive an effect: its frame durations (summing to the run's length) and threads.
struct DriveCase {
  std::string label;  // "24 fps", "jitter 2", ...
  std::vector<Flicks> frames;
  int threads = 1;
};

/// The frame schedules the guarantee is stated for, each ending exactly at `total`: 24, 25, 30,
/// 30000/1001, 60 and 144 fps, seeded jitter 1, 2 and 3, and an irregular recorded sequence (or
/// the frames of `recorded` when given). Every schedule runs on 1 thread; 60 fps and jitter 1 also
/// run on each of `threadCounts`.
std::vector<DriveCase> standardDriveCases(
    Flicks total, const std::vector<int>& threadCounts,
    const std::optional<std::vector<Flicks>>& recorded = std::nullopt);

/// What one drive produced: the state hash after each tick (or only after the ticks asked for).
struct DriveTrace {
  std::string label;
  int threads = 1;
  std::vector<std::int64_t> ticks;    // which ticks were hashed, ascending
  std::vector<std::uint64_t> hashes;  // the state hash after each of them
  std::int64_t ticksDropped = 0;      // must be 0: the cap is lifted for these runs
  double wallSeconds = 0.0;
};

/// Runs `effect` driven by `drive`. The cap on ticks per frame is lifted (a dropped tick would
/// make two schedules differ by design, not by a fault). Hashes the state after every tick, or
/// after each tick in `onlyTicks` when it is not empty.
DriveTrace traceDrive(const io::EffectSettings& effect, const DriveCase& drive,
                      const std::vector<std::int64_t>& onlyTicks = {});

/// The state right after tick `tick` of `effect` driven by `drive`: the pool's own columns (not a
/// frame's interpolation), rows in id order, timeSeconds the tick's time. Empty when the drive
/// ends before that tick.
io::FrameData stateAfterTick(const io::EffectSettings& effect, const DriveCase& drive,
                             std::int64_t tick);

/// Where a set of traces over the same ticks first disagree.
struct Divergence {
  std::int64_t tick = -1;         // the first tick whose hashes differ; -1 when all agree
  std::vector<std::size_t> runs;  // the traces that differ from the first one there
};
Divergence firstDivergence(const std::vector<DriveTrace>& traces);

}  // namespace tickfx::app
