// Recording one run of an effect as a hash log, and comparing a run on this machine with a log
// made on another.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/effect/EffectSettings.h"
#include "io/state/HashLog.h"

namespace tickfx::app {

/// This machine and build as a log's header names them: uname, the CPU's model name, the
/// compiler and its version, the build type and flags, the tickfx version. The effect's identity
/// and the run's frames are the caller's.
io::HashLogHeader describeThisBuild();

/// Runs `effect` through frames of 1/header.fps s covering header.length (the last one
/// shortened), on 1 thread with every tick run, and returns the log: `header` with the frame,
/// tick and column lists filled in, every tick's hashes, every frame's hash, and the whole state
/// after each tick of `snapshotTicks` (ascending; ticks past the end are ignored).
io::HashLog recordHashLog(const io::EffectSettings& effect, io::HashLogHeader header,
                          const std::vector<std::int64_t>& snapshotTicks);

/// A log that cannot be compared with this run of the effect (bad input, exit 2).
class HashLogRefused : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The first value that differs at the tick where the runs part, from the log's snapshot.
struct RowDifference {
  std::uint64_t id = 0;  // the particle (this run's id at that row)
  std::string column;    // a stateColumnNames() entry; "counters" when only the row counts differ
  std::uint64_t runBits = 0, logBits = 0;  // the column's bits (for "counters": the row counts)
};

struct LogComparison {
  std::int64_t ticks = 0;      // ticks this run ran
  std::int64_t frames = 0;     // frames this run made
  std::uint64_t lastHash = 0;  // this run's state hash after its last tick
  // The first tick whose state differs, or -1.
  std::int64_t partTick = -1;
  std::uint64_t runHash = 0, logHash = 0;
  std::vector<std::string> columns;  // the columns whose hashes differ there
  bool logHasState = false;          // the log holds a snapshot of partTick
  std::optional<RowDifference> row;  // the first difference in it, when it does
  // When every tick agrees: the first frame whose shown state differs, or -1.
  std::int64_t partFrame = -1;
};

/// Runs `effect` as `log` was recorded (same length and frames) and compares it tick by tick,
/// stopping after the frame where it parts. Throws HashLogRefused when the log does not describe
/// this effect: its step rate, seed or fingerprint (checked in that order, so a --set of the seed
/// or step rate is named as such) or its columns differ from this run's.
LogComparison compareWithHashLog(const io::EffectSettings& effect, std::uint64_t fingerprint,
                                 const std::string& logName, const io::HashLog& log);

}  // namespace tickfx::app
