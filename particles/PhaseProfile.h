// Where a run's wall time goes, phase by phase, and how much of it no parallel loop covered: the
// serial share that bounds what more threads can give (Amdahl's law). `tickfx run --profile`
// prints it; docs/performance.md reads it.
#pragma once

#include <array>
#include <cstddef>
#include <string>

namespace tickfx::profile {

/// The phases of a run, each charged the wall time of the recording thread while inside it.
enum class Phase : int {
  Other,       // the thread's time in no phase below (the frame loop's own work)
  Startup,     // from the process's start to start(): exec, loading the libraries
  Load,        // reading the effect, building the system (vector fields loaded), checking outputs
  Growth,      // the pool's storage made or grown: moving the rows into it
  Emission,    // births: rows appended, spawned, event children
  Step,        // integrating and colliding, fused or tick by tick
  Deaths,      // the clock, the expiry and non-finite scans, removing the dead
  Capture,     // a frame's rows copied out: interpolated positions, ages, attributes
  Hash,        // state hashes (--hash, --trace)
  Checkpoint,  // checkpoints and a shard's final state
  CacheWrite,  // caches encoded and written, or waited for while another thread writes them
  Release,     // the system and its buffers freed at the end
  Count
};

inline constexpr std::size_t kPhaseCount = static_cast<std::size_t>(Phase::Count);

/// "other", "startup", "load", ...: the name the report gives.
const char* phaseName(Phase phase);

/// What a phase cost: its wall time, and the part of it spent inside parallel loops (the rest ran
/// on one thread).
struct PhaseTime {
  double wallSeconds = 0.0;
  double parallelSeconds = 0.0;
  double serialSeconds() const { return wallSeconds - parallelSeconds; }
};

/// A whole recording. The phases partition its time: their wall times add up to `wallSeconds`
/// (each instant is charged to exactly one phase, the innermost open one).
struct Report {
  double wallSeconds = 0.0;  // from the process's start (or start(), see there) to stop()
  std::array<PhaseTime, kPhaseCount> phases{};
  const PhaseTime& operator[](Phase p) const { return phases[static_cast<std::size_t>(p)]; }
  /// The serial share of the whole: sum of serial seconds / wallSeconds.
  double serialShare() const;
  /// The table `tickfx run --profile` prints, with Amdahl's bound for 2 to 16 threads and
  /// `threads` (the thread count the run had) named in its title.
  std::string format(int threads) const;
};

/// Starts recording on the calling thread, which from then on is the only one whose PhaseScopes
/// and ParallelScopes count (helper threads and pool workers are covered by the loop that runs
/// them). The time before, from the process's start on, is charged to Startup where the system
/// says when the process started (Linux), else not recorded. Not reentrant: one recording at a
/// time per process.
void start();

/// Ends the recording and returns it. Calling it on another thread than start()'s, or without
/// start(), returns an empty report.
Report stop();

/// While alive on the recording thread, its time goes to `phase` (a scope inside it takes its own
/// time back). Does nothing on any other thread, or inside a parallel loop. Costs one
/// thread-local test when nothing records.
class PhaseScope {
 public:
  explicit PhaseScope(Phase phase);
  ~PhaseScope();
  PhaseScope(const PhaseScope&) = delete;
  PhaseScope& operator=(const PhaseScope&) = delete;

 private:
  Phase previous_ = Phase::Other;
  bool active_ = false;
};

/// Marks a parallel loop run from the recording thread: the time inside counts as parallel for
/// the phase it falls in (only the outermost of nested loops counts). Every loop that may hand
/// work to other threads opens one (parallelForRows and parallelForTasks do).
class ParallelScope {
 public:
  ParallelScope();
  ~ParallelScope();
  ParallelScope(const ParallelScope&) = delete;
  ParallelScope& operator=(const ParallelScope&) = delete;

 private:
  bool active_ = false;
};

}  // namespace tickfx::profile
