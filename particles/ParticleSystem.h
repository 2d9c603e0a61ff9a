// A pool, its emitters, its forces and an integrator, advanced by the fixed-step driver.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "particles/Emitter.h"
#include "particles/EventEmission.h"
#include "particles/FixedStepDriver.h"
#include "particles/LifeAttributeSet.h"
#include "particles/NonfiniteState.h"
#include "particles/ParticlePool.h"
#include "particles/RenderDestination.h"
#include "particles/Shard.h"
#include "particles/Structure.h"

namespace tickfx {

struct StateBound;  // particles/StateBound.h

// The system composes the layers above particles/: its forces (fields/ForceSet.h) and its scheme
// (integrators/Integrator.h). This header only declares them; a host that builds a system
// includes fields/ForceSet.h for the ForceSet it hands over.
class ColliderSet;
class ForceSet;
class Integrator;
class SpringNetwork;
struct StepTime;
class TaskExecutor;

/// Settings of a whole simulation (the [simulation] table of an effect file).
struct SystemSettings {
  std::int64_t stepRateHz = 60;                    // ticks per second
  std::string integrator = "semi_implicit_euler";  // see integratorNames()
  std::uint64_t seed = 0;                          // the effect seed of every random number
  std::size_t maxParticles = 1'000'000;            // spawns past this are dropped, counted
  std::int64_t maxTicksPerFrame = 16;              // cap on ticks per advance() (real-time hosts)
  OverrunPolicy overrunPolicy = OverrunPolicy::DropExcess;
  FrameTiming frameTiming = FrameTiming::AtFrameTime;  // which time advance() leaves on show
  int threads = 0;                                     // 0: all cores
  /// What a tick does with particles whose position or velocity stops being finite.
  NonfinitePolicy nonfinite = NonfinitePolicy::Stop;
};

/// The simulation. One tick does, in this order: emit the tick's particles, let the forces
/// rebuild their tables, integrate every particle from t_k to t_{k+1} (or advect it, when the
/// forces prescribe velocity), let the forces flag particles dead at the new state (a field's
/// kill region), recompute ages from the tick count and remove the dead. Nothing in a tick reads
/// the frame time, so the state after tick k is the same for any sequence of frames that reaches
/// it.
///
/// A frame of several ticks under forces that interleave ticks (local modules with no per-tick
/// tables: ForceSet::interleavesTicks) is fused: each block of rows goes through all the frame's
/// ticks while it is in cache, then the next block. The frame's births are spawned first, each
/// block starting at its birth tick, and the deaths of all its ticks are removed at its end. The
/// rows, ids and bits are those of the ticks one by one (tested for every integrator); a frame
/// whose ticks a tick observer watches, that may reach maxParticles, that gives birth to a
/// structure or that kills non-finite particles runs tick by tick. Under NonfinitePolicy::Stop a
/// fused frame keeps a copy of the positions and velocities it started from (24 bytes a particle;
/// 36 for position Verlet, which reads the previous position, and velocity Verlet, which keeps
/// the acceleration): on finding a non-finite value it goes back and runs its ticks one by one,
/// which stop at the exact tick.
///
/// Checked ticks (NonfinitePolicy::Stop, Kill) read, and clear when raised, the invalid, overflow
/// and divide-by-zero floating-point exception flags of the threads they run on: the integrators
/// check the rows they step by them where they can (NonfiniteCheck::steppedRowsFinite()).
///
/// Not thread-safe: one thread drives a system. Inside a tick the system runs its loops in its
/// own TBB arena, or on the host's executor (setTaskExecutor()); it never changes TBB's
/// process-wide limits.
class ParticleSystem {
 public:
  /// Throws std::invalid_argument for invalid settings (unknown integrator, bad emitter, ...).
  ///
  /// `structures` (ropes, cloth, clusters) are born at their time and joined by springs: the
  /// system then uses the first SpringNetwork in `forces`, or appends one if there is none.
  ParticleSystem(const SystemSettings& settings, const std::vector<EmitterSettings>& emitters,
                 ForceSet forces, const std::vector<StructureSettings>& structures = {});
  /// As above, with `colliders` (fields/ColliderSet.h) run after each tick's step: particles
  /// never pass through them (see ColliderSet::collide). A system with colliders runs its frames
  /// tick by tick (no fused frames). When a collider records hits, the pool gets the hit
  /// columns (kHitColumns).
  ///
  /// Emitters with a parent are sub-emitters (EventEmission): a system with any runs its frames
  /// tick by tick. Emitters' attributes over life (LifeAttributeSet) add no column to the pool
  /// but kEmitterColumn where rows must be told apart.
  ParticleSystem(const SystemSettings& settings, const std::vector<EmitterSettings>& emitters,
                 ForceSet forces, const std::vector<StructureSettings>& structures,
                 ColliderSet colliders);
  ~ParticleSystem();
  ParticleSystem(const ParticleSystem&) = delete;
  ParticleSystem& operator=(const ParticleSystem&) = delete;

  /// Feeds one frame of `frame` flicks to the driver and runs the ticks it asks for. The render
  /// copies below then show the frame's time (see FrameTiming).
  AdvanceResult advance(Flicks frame);

  /// The most ticks a system runs (birth ticks are 32 bits: ParticlePool::kMaxBirthTick): 207
  /// days of simulated time at 240 ticks a second. advance(), step() and stepTicks() throw
  /// std::overflow_error rather than run past it, before running any tick of the call.
  static constexpr std::int64_t kMaxTicks = ParticlePool::kMaxBirthTick + 1;

  /// Runs exactly one tick, bypassing the driver's clock (tests, offline baking). Render copies
  /// then show the state after that tick.
  void step();
  /// Runs `ticks` ticks, as step() does.
  void stepTicks(std::int64_t ticks);

  /// Under NonfinitePolicy::Stop, the tick that left particles with a non-finite position or
  /// velocity. Once set, advance(), step() and stepTicks() run no more ticks: the state stays the
  /// one that tick made, for the host to look at (the render copies show it too).
  const std::optional<NonfiniteEvent>& nonfiniteStop() const { return nonfiniteStop_; }
  /// Under NonfinitePolicy::Kill, the particles removed for a non-finite position or velocity
  /// since the system was made (a restored system counts from its restore).
  std::uint64_t nonfiniteKilled() const { return nonfiniteKilled_; }
  /// What the ticks from now on do with non-finite state (SystemSettings::nonfinite): a host's
  /// debug switch, say. After ticks under Keep the first checked tick checks every value it
  /// writes, since nothing checked what they made. A stopped system stays stopped.
  void setNonfinitePolicy(NonfinitePolicy policy) { settings_.nonfinite = policy; }

  /// Ticks run in fused frames so far (see the class comment): for tests and benches.
  std::int64_t fusedTicks() const { return fusedTicks_; }
  /// Fused frames so far that copied their start under NonfinitePolicy::Stop, to go back to if
  /// they went non-finite; the others were proven finite before they ran (Integrator::boundTick):
  /// for tests and benches.
  std::int64_t framesCopied() const { return framesCopied_; }
  /// Ticks completed so far: the state is the state after tick tickCount() − 1 (or the initial
  /// state for 0), at time tickCount() / stepRate seconds.
  std::int64_t tickCount() const { return tick_; }
  double timeSeconds() const {
    return static_cast<double>(tick_) / static_cast<double>(settings_.stepRateHz);
  }
  /// α of the last advance(): where the frame lies between the previous and the current tick,
  /// in [0, 1]; 1 after step() and whenever the frame falls on the current tick.
  float alpha() const { return alpha_; }
  /// Seconds the render copies show: the last frame's time (or the current tick's after step()).
  double shownSeconds() const;

  /// Render copies of the shown time, rows [0, pool().size()) in id order. Between two ticks
  /// positions and velocities are interpolated by α and ages computed from integers; on a tick
  /// (α = 1) they are the tick's own values, bit for bit. A frame between ticks k and k + 1
  /// shows the particles alive after tick k + 1: those born in that tick move from their birth
  /// state, and those removed by it (they die or leave a kill region within it) are not shown.
  /// Other columns (mass, lifetime, attributes) are those of the current tick. A particle that
  /// touched a collider in the newest tick is shown on its path through the contacts
  /// (CollisionPath), not on the straight line from its start, which may cut through a collider.
  void renderPositions(Vec3Column& out) const;
  void renderVelocities(Vec3Column& out) const;
  void renderAges(FloatColumn& out) const;

  /// Positions interpolated by any `alpha` in [0, 1] between the previous and the current tick:
  /// previous + (current − previous) · α, exactly previous at 0 and current at 1. For α < 1 the
  /// newest tick must have kept its starting positions (previousPositionsKept()); throws
  /// std::logic_error otherwise.
  void interpolatedPositions(float alpha, Vec3Column& out) const;

  /// Whether the newest tick kept the positions it started from (ParticlePool::previousPosition()):
  /// a tick does when advance() shows a frame between it and the tick before, when colliders
  /// follow paths from them, when they are the scheme's state (position Verlet), or when a host
  /// asked (setKeepPreviousPositions()). Other ticks neither read nor write them.
  bool previousPositionsKept() const {
    return pool_.previousIsState() || (previousTick_ == tick_ && tick_ > 0);
  }
  /// Makes every tick keep its starting positions, for a host that interpolates with
  /// interpolatedPositions() after step() (Python's positions(alpha)). Off by default: it costs
  /// 24 bytes of memory traffic a particle-step. The state's bits do not depend on it.
  void setKeepPreviousPositions(bool keep) { keepPreviousAlways_ = keep; }

  /// The render copies above, written straight into a host's buffers (a vertex buffer, a
  /// renderer's point arrays) in any layout: the same bits as renderPositions() and the others,
  /// rows in id order. Nothing is written when the destination holds fewer rows than the pool
  /// (see CopyResult).
  CopyResult copyRenderPositions(const Vec3Destination& out) const;
  CopyResult copyRenderVelocities(const Vec3Destination& out) const;
  CopyResult copyRenderAges(const FloatDestination& out) const;
  /// Particle ids (unique per system, in increasing order of birth).
  CopyResult copyIds(const IdDestination& out) const;
  /// A float column by name: "lifetime" (seconds), "mass" (kg), an attribute of the pool (see
  /// ParticlePool::addAttribute) as of the current tick, or an attribute over life
  /// (lifeAttributes()) at the shown time. Empty for any other name.
  std::optional<CopyResult> copyColumn(std::string_view name, const FloatDestination& out) const;
  /// The attribute columns a frame shows, in order: the pool's attributes, then the attributes
  /// over life that no pool column holds (copyColumn() gives each).
  std::vector<std::string> attributeNames() const;
  /// The emitters' attributes over life, evaluated when a frame is shown, never in a tick.
  const LifeAttributeSet& lifeAttributes() const { return lifeAttributes_; }
  /// The sub-emitters (nullptr when the effect has none).
  const EventEmission* events() const { return events_.get(); }
  EventEmission* events() { return events_.get(); }

  /// Runs this system's parallel loops on a host's job system from the next tick on, or on the
  /// system's own TBB arena for nullptr (the default). Not owned: the executor must outlive the
  /// system or be replaced first. The state's bits do not depend on it.
  void setTaskExecutor(TaskExecutor* executor) { executor_ = executor; }
  TaskExecutor* taskExecutor() const { return executor_; }

  const ParticlePool& pool() const { return pool_; }
  /// The state to write between ticks (a restored checkpoint, a host's own edits). The next
  /// checked tick then checks every value it writes, as nothing says the state is still finite;
  /// after it, the check by floating-point exceptions resumes (NonfiniteCheck).
  ParticlePool& editPool() {
    nonfiniteCheck_.setSteppedRowsFinite(false);
    return pool_;
  }
  const ForceSet& forces() const { return *forces_; }
  const Integrator& integrator() const { return *integrator_; }
  const FixedStepDriver& driver() const { return driver_; }
  FixedStepDriver& driver() { return driver_; }
  const SystemSettings& settings() const { return settings_; }
  const std::vector<Emitter>& emitters() const { return emitters_; }
  /// The colliders (nullptr when the system has none).
  const ColliderSet* colliders() const { return colliders_.get(); }
  /// The spring network structures use (nullptr when the system has neither).
  const SpringNetwork* springs() const { return springs_; }
  SpringNetwork* springs() { return springs_; }
  /// Calls `observer` after every tick, with the state after that tick (a trace of per-tick
  /// hashes, a debugger's breakpoint). An empty function removes it. It runs on the driving thread.
  void setTickObserver(std::function<void(const ParticleSystem&)> observer) {
    tickObserver_ = std::move(observer);
  }
  /// Velocities at the start of the newest tick, rows matching the pool's, when advance() kept
  /// them for interpolating render copies; nullptr otherwise.
  const Vec3Column* tickStartVelocities() const {
    return velocitiesTick_ == tick_ ? &previousVelocity_ : nullptr;
  }
  /// Restores the tick counter and what tickStartVelocities() gave (null for none), after the
  /// pool and driver(): with them a saved state is complete, render copies included.
  void restoreClock(std::int64_t tick, const Vec3Column* tickStartVelocities);

  /// Makes this system simulate shard `shard` of the run only (particles/Shard.h): its rows, ids
  /// and bits are the whole run's rows of that shard, provided the whole run never reaches
  /// maxParticles (see particleBound()). Set before the first tick, or before a shard's
  /// checkpoint is restored. Throws std::invalid_argument for an invalid shard, or a sharded
  /// system with sub-emitters: a child's id counts the events of every shard before it.
  void setShard(const Shard& shard);
  const Shard& shard() const { return shard_; }
  /// At least as many particles as the whole run (every shard) holds at any tick from
  /// tickCount() to `ticks` − 1, from the emission schedule and the longest lifetimes alone (the
  /// rows alive now counted as never dying). A run whose bound is within maxParticles never
  /// refuses a spawn, which is what lets shards count each other's ids.
  std::uint64_t particleBound(std::int64_t ticks) const;

 private:
  struct PendingStructure;
  // `shown`: the frame of these ticks falls between the last two, so the last one keeps its
  // starting positions and velocities for the render copies.
  void runTicks(std::int64_t ticks, bool shown);
  void runTick(bool shown);
  // Whether a tick keeps its starting positions: `shown` (its frame interpolates across it), a
  // host's wish, or colliders (their paths start there). Position Verlet's are state, kept anyway.
  bool keepsPrevious(bool shown) const {
    // Colliders stepped block by block read each block's starts from a buffer of their own.
    return shown || keepPreviousAlways_ || (colliders_ != nullptr && !collidesBlocks());
  }
  bool collidesBlocks() const;
  // A tick's step and collisions block by block (colliders with local forces).
  void stepAndCollideBlocks(const StepTime& time, NonfiniteCheck* check, bool keepPrevious);
  bool fusesTicks(std::int64_t ticks) const;
  bool runFusedTicks(std::int64_t ticks, bool shown);
  bool provesFrameFinite(std::int64_t ticks, std::size_t fresh, bool& measures);
  // After the ticks up to `tick` (the count it sets): ages, the kept velocities' rows matched to
  // the deaths, the dead removed. Shared by a tick and a fused frame.
  void endTicks(std::int64_t tick, bool keepVelocities);
  void takeNonfinite();
  void spawnStructure(const StructureBuild& build);
  // The births of tick `tick`: every emitter's, then the sub-emitters' children.
  void emitTick(std::int64_t tick);

  SystemSettings settings_;
  ParticlePool pool_;
  std::vector<Emitter> emitters_;
  std::unique_ptr<ForceSet> forces_;  // never null
  std::unique_ptr<Integrator> integrator_;
  std::unique_ptr<ColliderSet> colliders_;  // null when none
  LifeAttributeSet lifeAttributes_;
  std::unique_ptr<EventEmission> events_;  // null when no emitter has a parent
  std::int64_t pathsTick_ = -1;            // the tick after which colliders_->paths() were found
  // Moves the rows of render positions `out` (rows [0, n)) that touched a collider in the newest
  // tick onto their paths at `alpha`.
  void followPaths(float alpha, const Vec3Destination& out) const;
  struct PendingStructure {
    StructureBuild build;  // built (so validated) once, by the constructor; born at `tick`
    std::int64_t tick;
    std::size_t particles;  // build.particles.size(), kept once the build is dropped
  };
  std::vector<PendingStructure> structures_;
  SpringNetwork* springs_ = nullptr;  // owned by *forces_
  FixedStepDriver driver_;
  class ThreadArena;  // the TBB arena, kept out of this header
  std::unique_ptr<ThreadArena> arena_;
  TaskExecutor* executor_ = nullptr;  // the host's, when given: used instead of arena_
  template <typename F>
  void runParallel(F&& f) const;
  std::function<void(const ParticleSystem&)> tickObserver_;
  Shard shard_;  // the whole run unless setShard()
  std::int64_t tick_ = 0;
  std::int64_t fusedTicks_ = 0;
  std::int64_t framesCopied_ = 0;
  // The tick count after the newest tick that kept its starting positions (-1: none).
  std::int64_t previousTick_ = -1;
  bool keepPreviousAlways_ = false;
  float alpha_ = 1.0f;
  // The shown time as the driver's frameOffset(): past tick tick_ − 1, kFlicksPerSecond = on
  // tick_.
  std::int64_t frameOffset_ = kFlicksPerSecond;
  // Velocities at the start of the newest tick (after its births), rows matching the pool's,
  // kept by advance() for interpolation; valid while velocitiesTick_ == tick_.
  Vec3Column previousVelocity_;
  std::int64_t velocitiesTick_ = -1;
  // Under NonfinitePolicy::Stop, the state a fused frame started from, to go back to.
  struct FrameStart;
  std::unique_ptr<FrameStart> frameStart_;
  // Under NonfinitePolicy::Stop, bounds of the state measured at the end of the newest fused frame
  // (particles/StateBound.h), from which the next proves itself finite. Valid while
  // endBoundsTick_ == tick_ and the check holds the stepped rows finite (editPool() voids that).
  std::unique_ptr<StateBound> endBounds_;
  std::int64_t endBoundsTick_ = -1;
  // Also holds whether the rows the next tick steps are finite: the ticks so far were checked
  // and editPool() has not been called since (set by endTicks()).
  NonfiniteCheck nonfiniteCheck_;
  std::optional<NonfiniteEvent> nonfiniteStop_;
  std::uint64_t nonfiniteKilled_ = 0;
};

}  // namespace tickfx
