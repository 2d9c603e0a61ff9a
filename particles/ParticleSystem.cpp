#include "particles/ParticleSystem.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "fields/ColliderSet.h"
#include "fields/ForceSet.h"
#include "fields/SpringNetwork.h"
#include "integrators/Integrator.h"
#include "particles/Assert.h"
#include "particles/Clock.h"
#include "particles/ExactTime.h"
#include "particles/Isa.h"
#include "particles/ParallelFor.h"
#include "particles/PhaseProfile.h"
#include "particles/StateBound.h"
#include "particles/TaskExecutor.h"

namespace tickfx {

class ParticleSystem::ThreadArena {
 public:
  // TBB keeps its workers to the process-wide limit (the core count unless the host raised it
  // with tbb::global_control, as `tickfx run --threads` does): a system never changes it.
  explicit ThreadArena(int threads) : arena_(threads > 0 ? threads : tbb::task_arena::automatic) {}
  template <typename F>
  void execute(F&& f) {
    arena_.execute(std::forward<F>(f));
  }

 private:
  tbb::task_arena arena_;
};

template <typename F>
void ParticleSystem::runParallel(F&& f) const {
  if (executor_ != nullptr) {
    const ExecutorScope scope(executor_);
    f();
  } else {
    arena_->execute(std::forward<F>(f));
  }
}

namespace {

std::vector<Emitter> makeEmitters(const std::vector<EmitterSettings>& settings, std::int64_t rate) {
  std::vector<Emitter> emitters;
  emitters.reserve(settings.size());
  for (std::size_t i = 0; i < settings.size(); ++i) {
    emitters.emplace_back(settings[i], static_cast<std::uint32_t>(i), rate);
  }
  return emitters;
}

}  // namespace

ParticleSystem::ParticleSystem(const SystemSettings& settings,
                               const std::vector<EmitterSettings>& emitters, ForceSet forces,
                               const std::vector<StructureSettings>& structures)
    : ParticleSystem(settings, emitters, std::move(forces), structures, ColliderSet{}) {}

ParticleSystem::ParticleSystem(const SystemSettings& settings,
                               const std::vector<EmitterSettings>& emitters, ForceSet forces,
                               const std::vector<StructureSettings>& structures,
                               ColliderSet colliders)
    : settings_(settings),
      pool_(settings.maxParticles),
      emitters_(makeEmitters(emitters, settings.stepRateHz)),
      forces_(std::make_unique<ForceSet>(std::move(forces))),
      integrator_(makeIntegrator(settings.integrator)),
      driver_(settings.stepRateHz, settings.maxTicksPerFrame, settings.overrunPolicy,
              settings.frameTiming),
      arena_(std::make_unique<ThreadArena>(settings.threads)) {
  nonfiniteCheck_.setSteppedRowsFinite(true);  // no rows yet: the first tick's are all spawned
  if (settings.threads < 0) throw std::invalid_argument("threads must be >= 0");
  pool_.setClock(0, settings.stepRateHz);  // the driver has refused a rate of 0 or less
  for (std::size_t i = 0; i < forces_->size() && springs_ == nullptr; ++i) {
    springs_ = dynamic_cast<SpringNetwork*>(&forces_->module(i));
  }
  if (!structures.empty() && springs_ == nullptr) {
    springs_ = static_cast<SpringNetwork*>(&forces_->add(std::make_unique<SpringNetwork>()));
  }
  for (std::size_t i = 0; i < structures.size(); ++i) {
    // Built now, not at the structure's birth tick: bad settings fail the construction, and the
    // build is kept for the birth.
    StructureBuild build =
        buildStructure(structures[i], settings.seed, static_cast<std::uint32_t>(i));
    const std::int64_t tick = exact::tickAtOrAfter(structures[i].time, settings.stepRateHz);
    const std::size_t particles = build.particles.size();
    structures_.push_back(PendingStructure{std::move(build), tick, particles});
  }
  // Position Verlet's history is state; colliders follow each tick's paths from the start.
  if (integrator_->readsPreviousPosition()) pool_.keepPrevious(/*asState=*/true);
  if (!colliders.empty()) {
    pool_.keepPrevious();
    colliders.addHitColumns(pool_);
    colliders_ = std::make_unique<ColliderSet>(std::move(colliders));
  }
  lifeAttributes_ = LifeAttributeSet(emitters, settings.seed, !structures.empty());
  if (lifeAttributes_.needsEmitterColumn()) pool_.addAttribute(kEmitterColumn, -1.0f);
  bool subEmitters = false;
  for (const Emitter& e : emitters_) subEmitters |= e.isSubEmitter();
  if (subEmitters) {
    events_ = std::make_unique<EventEmission>(emitters_, &lifeAttributes_, settings.seed, pool_);
    if (colliders_ && events_->listensTo(EmitterEvent::Collision)) {
      colliders_->recordContacts(kContactsColumn);
    }
  }
}

ParticleSystem::~ParticleSystem() = default;

AdvanceResult ParticleSystem::advance(Flicks frame) {
  const AdvanceResult result = driver_.advance(frame);
  // Only a frame between two ticks interpolates: its last tick keeps what it started from.
  runTicks(result.ticks, /*shown=*/driver_.frameOffset() != kFlicksPerSecond);
  alpha_ = result.alpha;
  frameOffset_ = driver_.frameOffset();
  return result;
}

void ParticleSystem::step() { stepTicks(1); }

void ParticleSystem::stepTicks(std::int64_t ticks) {
  runTicks(ticks, /*shown=*/false);
  if (ticks > 0) {
    alpha_ = 1.0f;
    frameOffset_ = kFlicksPerSecond;
  }
}

void ParticleSystem::runTicks(std::int64_t ticks, bool shown) {
  if (ticks <= 0 || nonfiniteStop_) return;
  if (ticks > kMaxTicks - tick_) {
    throw std::overflow_error("tick " + std::to_string(tick_ + ticks - 1) +
                              " is past the last tick a run can have, " +
                              std::to_string(kMaxTicks - 1) + " (birth ticks are 32 bits)");
  }
  runParallel([&] {
    if (fusesTicks(ticks) && runFusedTicks(ticks, shown)) return;
    for (std::int64_t i = 0; i < ticks && !nonfiniteStop_; ++i) {
      // Only the last tick of a frame is interpolated across.
      runTick(shown && i == ticks - 1);
      if (tickObserver_) tickObserver_(*this);
    }
  });
}

// The rows of a fused frame's first tick, saved under NonfinitePolicy::Stop.
struct ParticleSystem::FrameStart {
  // Rows past which the copy is written around the caches: 2^18 rows of 24 bytes are 6 MiB, past
  // a core's L2 cache.
  static constexpr std::size_t kStreamedRows = std::size_t{1} << 18;

  Vec3Column position, velocity, extra;

  void reserve(const ParticlePool& pool, bool previousRead) {
    readsPrevious = previousRead;
    streamed = pool.size() >= kStreamedRows;
#if defined(__SSE2__)
    streamRows = &streamRowsSse2;
#ifdef TICKFX_AVX2_CLONES
    if (activeIsa() != Isa::Baseline) streamRows = &streamRowsAvx2;
#endif
#endif
    const auto need = static_cast<Eigen::Index>(pool.storageRows());
    const auto grow = [need](Vec3Column& c) {
      if (c.x.size() < need) c.resize(need);
    };
    grow(position);
    grow(velocity);
    if (extraColumnOf(pool, readsPrevious)) grow(extra);
  }
  // Vec3Column::copyRows with stores that bypass the cache where the machine has them, for a pool
  // larger than the caches: the copy is read back only when a frame goes non-finite, so caching it
  // would first read the lines it overwrites (a third more memory traffic for the frame's first
  // tick) and evict the rows being stepped. A smaller pool and its copy stay in cache, where plain
  // stores are cheaper than a trip to memory.
  bool streamed = false;

  void store(const Vec3Column& from, Vec3Column& to, std::size_t b, std::size_t e) {
#if defined(__SSE2__)
    if (streamed) {
      for (int c = 0; c < 3; ++c) streamRows(from[c].data(), to[c].data(), b, e);
      return;
    }
#endif
    to.copyRows(from, b, e);
  }
#if defined(__SSE2__)
  // Rows [b, e) of `in` into `out` by streaming stores (plain ones up to the first aligned row
  // and after the last whole register); set by reserve() for the active path.
  void (*streamRows)(const float* in, float* out, std::size_t b, std::size_t e) = nullptr;

  static void streamRowsSse2(const float* in, float* out, std::size_t b, std::size_t e) {
    std::size_t i = b;
    for (; i < e && reinterpret_cast<std::uintptr_t>(out + i) % 16 != 0; ++i) out[i] = in[i];
    for (; i + 4 <= e; i += 4) _mm_stream_ps(out + i, _mm_loadu_ps(in + i));
    for (; i < e; ++i) out[i] = in[i];
  }
#ifdef TICKFX_AVX2_CLONES
  // The same with 32-byte stores (the intrinsics need the target's own function): in a frame of
  // 10⁷ rows on the processor measured, the copy took about a fifth less time than with 16-byte
  // ones, and more with 64-byte ones than with either (docs/performance.md).
  [[gnu::target("avx2")]] static void streamRowsAvx2(const float* in, float* out, std::size_t b,
                                                     std::size_t e) {
    std::size_t i = b;
    for (; i < e && reinterpret_cast<std::uintptr_t>(out + i) % 32 != 0; ++i) out[i] = in[i];
    for (; i + 8 <= e; i += 8) _mm256_stream_ps(out + i, _mm256_loadu_ps(in + i));
    for (; i < e; ++i) out[i] = in[i];
  }
#endif
#endif
  // The state a tick reads: the position, the velocity and the scheme's third column, the one its
  // proof bounds too (extraColumnOf: the previous position only for a scheme that reads it, as
  // the others write it afresh each tick).
  bool readsPrevious = false;

  void save(const ParticlePool& pool, std::size_t b, std::size_t e) {
    store(pool.position(), position, b, e);
    store(pool.velocity(), velocity, b, e);
    if (const Vec3Column* third = extraColumnOf(pool, readsPrevious)) store(*third, extra, b, e);
#if defined(__SSE2__)
    if (streamed) _mm_sfence();  // ordered before the frame's end, like any other store
#endif
  }
  void restore(ParticlePool& pool, std::size_t b, std::size_t e) const {
    pool.position().copyRows(position, b, e);
    pool.velocity().copyRows(velocity, b, e);
    if (Vec3Column* third = extraColumnOf(pool, readsPrevious)) third->copyRows(extra, b, e);
  }
};

bool ParticleSystem::fusesTicks(std::int64_t ticks) const {
  if (ticks < 2 || tickObserver_ || settings_.nonfinite == NonfinitePolicy::Kill ||
      !forces_->interleavesTicks() || colliders_ || events_) {
    return false;
  }
  for (const PendingStructure& p : structures_) {
    if (p.tick >= tick_ && p.tick < tick_ + ticks) return false;
  }
  // Every birth of the frame must fit with every particle alive at its start: deaths come at the
  // frame's end, and no spawn may be refused that the ticks one by one would have made.
  std::uint64_t births = 0;
  for (const Emitter& e : emitters_)
    births += e.serialBefore(tick_ + ticks) - e.serialBefore(tick_);
  return births <= pool_.maxParticles() - pool_.size();
}

bool ParticleSystem::runFusedTicks(std::int64_t ticks, bool shown) {
  const bool keepVelocities = shown;
  const bool keepPrevious = keepsPrevious(shown);
  const std::int64_t first = tick_;
  const std::size_t startRows = pool_.size();
  const std::size_t stepped = pool_.firstUnstepped();
  const std::uint64_t startId = pool_.nextId();
  // Rows born at tick first + j end at bornBy[j]; rows before bornBy[0] step from the first tick.
  std::vector<std::size_t> bornBy(static_cast<std::size_t>(ticks));
  for (std::int64_t j = 0; j < ticks; ++j) {
    emitTick(first + j);
    bornBy[static_cast<std::size_t>(j)] = pool_.size();
  }
  const std::size_t rows = pool_.size();
  std::optional<profile::PhaseScope> phase(std::in_place, profile::Phase::Step);
  integrator_->prepare(pool_, *forces_);
  forces_->beginTick(pool_, first);  // no module's own tables; whether any particle is pinned
  const bool stop = settings_.nonfinite == NonfinitePolicy::Stop;
  // Under Stop a frame goes back to its start if it goes non-finite, from a copy made as it runs,
  // unless it is proven finite before it runs; its end is then measured for the next one's proof.
  bool measures = false;
  const bool copies = stop && !provesFrameFinite(ticks, std::min(stepped, startRows), measures);
  if (copies) {
    if (!frameStart_) frameStart_ = std::make_unique<FrameStart>();
    frameStart_->reserve(pool_, integrator_->readsPreviousPosition());
    ++framesCopied_;
  }
  // Every row is copied in the frame's last tick: none kept (keeping them would move them all to
  // the storage's front once the rows dropped there by deaths fill it).
  if (keepVelocities) previousVelocity_.setRows(rows, 0);
  if (keepPrevious) pool_.keepPrevious();

  // Blocks never straddle a birth tick: block i starts at tick first + firstTick[i].
  struct Block {
    std::size_t begin, end;
    std::int64_t firstTick;
  };
  std::vector<Block> blocks;
  std::size_t begin = 0;
  for (std::int64_t j = 0; j < ticks; ++j) {
    const std::size_t end = bornBy[static_cast<std::size_t>(j)];
    for (std::size_t b = begin; b < end; b += kParallelBlockRows) {
      blocks.push_back({b, std::min(end, b + kParallelBlockRows), j});
    }
    begin = end;
  }
  // A frame proven finite is not checked, but where asserts are on: one that went non-finite all
  // the same would be a wrong proof, found below.
  NonfiniteCheck* const check = copies || (stop && kAssertsEnabled) ? &nonfiniteCheck_ : nullptr;
  // The bounds of the frame's end, each block's taken while it is in cache.
  LargestMagnitudes end;
  const Vec3Column* const extra = extraColumnOf(pool_, integrator_->readsPreviousPosition());
  parallelForTasks(blocks.size(), [&](std::size_t i) {
    const Block& block = blocks[i];
    if (copies && block.begin < startRows) {
      frameStart_->save(pool_, block.begin, std::min(block.end, startRows));
    }
    for (std::int64_t j = block.firstTick; j < ticks; ++j) {
      if (keepVelocities && j == ticks - 1) {
        previousVelocity_.copyRows(pool_.velocity(), block.begin, block.end);
      }
      // A block is fresh from the row the pool had stepped (the first tick) or whole (a birth
      // tick), then stepped.
      const std::size_t fresh = j != block.firstTick ? block.end
                                : j == 0             ? std::max(block.begin, stepped)
                                                     : block.begin;
      const StepRows blockRows{RowRange{block.begin, block.end}, std::min(fresh, block.end), true,
                               keepPrevious && j == ticks - 1};
      integrator_->stepRows(pool_, *forces_, StepTime{first + j, settings_.stepRateHz}, blockRows,
                            check);
    }
    if (measures) end.add(pool_, extra, block.begin, block.end);
  });
  if (stop && nonfiniteCheck_.found()) {
    TICKFX_ASSERT(copies, "a frame proven finite made a non-finite value (Integrator::boundTick)");
    // Back to the frame's start: its ticks one by one then stop at the one that went non-finite.
    nonfiniteCheck_.clear();
    pool_.dropNewest(startRows, startId);
    parallelForRows(startRows,
                    [&](std::size_t b, std::size_t e) { frameStart_->restore(pool_, b, e); });
    return false;
  }
  pool_.markAllStepped();
  phase.reset();
  endTicks(first + ticks, keepVelocities);
  if (measures) {
    if (!endBounds_) endBounds_ = std::make_unique<StateBound>();
    *endBounds_ = end.bound();
    endBoundsTick_ = tick_;
  }
  if (keepPrevious) previousTick_ = tick_;
  fusedTicks_ += ticks;
  return true;
}

// Whether the frame of `ticks` from tick_ (its births spawned: rows [fresh, size) have not been
// stepped) is proven finite before it runs: bounds of its start state, carried through every
// tick by Integrator::boundTick, stay within StateBound::kLimit. The bounds of the rows stepped
// before come from the frame before (measured at its end) or, the first time, from a scan;
// those of the fresh rows' positions and velocities from a scan (they are few, and in cache),
// and of the third column a scheme starts them with (Integrator::boundSpawned) from those.
// `measures`: whether the scheme and forces can be bounded at all (false only where a bound
// failed to be made), so that the frame's end is worth measuring.
bool ParticleSystem::provesFrameFinite(std::int64_t ticks, std::size_t fresh, bool& measures) {
  const std::int64_t rate = settings_.stepRateHz;
  measures = true;
  const auto boundTick = [&](std::int64_t j, StateBound& b) {
    // The forms are those of every tick (ForceSet::uniformAndDrag): one failure is all of them.
    measures = measures && integrator_->boundTick(pool_, *forces_, StepTime{tick_ + j, rate}, b);
    return measures;
  };
  // Rows [b, e)'s bound into `out`. A scan is a pass over rows: before the first, the first
  // tick's bound is asked for once more (its forms: a wind's sine), to learn whether the scheme
  // and forces can be bounded at all. Without a scan, the loop below learns it from that very
  // bound.
  bool probed = false;
  const auto scan = [&](const Vec3Column* extra, std::size_t b, std::size_t e, StateBound& out) {
    StateBound probe;
    if (!probed && !boundTick(0, probe)) return false;
    probed = true;
    LargestMagnitudes largest;
    parallelForRows(
        e - b, [&](std::size_t rb, std::size_t re) { largest.add(pool_, extra, b + rb, b + re); });
    out = largest.bound();
    return true;
  };
  StateBound bound;  // no rows stepped before: nothing to bound
  if (fresh > 0) {
    if (endBounds_ && endBoundsTick_ == tick_ && nonfiniteCheck_.steppedRowsFinite()) {
      bound = *endBounds_;
    } else if (!scan(extraColumnOf(pool_, integrator_->readsPreviousPosition()), 0, fresh, bound)) {
      return false;
    }
  }
  if (fresh < pool_.size()) {
    StateBound born;  // their third column is not set yet
    if (!scan(nullptr, fresh, pool_.size(), born)) return false;
    for (std::int64_t j = 0; j < ticks; ++j) {
      if (!integrator_->boundSpawned(pool_, *forces_, StepTime{tick_ + j, rate}, born))
        return false;
    }
    bound = wider(bound, born);
  }
  for (std::int64_t j = 0; j < ticks; ++j) {
    if (!bound.provesFinite() || !boundTick(j, bound)) return false;
  }
  return bound.provesFinite();
}

void ParticleSystem::emitTick(std::int64_t tick) {
  const profile::PhaseScope phase(profile::Phase::Emission);
  const std::size_t firstNew = pool_.size();
  const std::size_t tag = pool_.findAttribute(kEmitterColumn);
  for (const Emitter& e : emitters_) {
    const std::size_t before = pool_.size();
    e.emit(pool_, settings_.seed, tick, shard_);
    if (tag != ParticlePool::npos && pool_.size() > before) {
      pool_.attribute(tag)
          .segment(static_cast<Eigen::Index>(before),
                   static_cast<Eigen::Index>(pool_.size() - before))
          .setConstant(static_cast<float>(e.index()));
    }
  }
  if (events_) events_->spawn(pool_, tick, firstNew);
}

void ParticleSystem::runTick(bool shown) {
  const bool keepVelocities = shown;
  const bool keepPrevious = keepsPrevious(shown);
  // The column the tick writes, before any path reads it: the pool may have been replaced since
  // the last tick (editPool()) by one that never kept it.
  if (keepPrevious) pool_.keepPrevious();
  emitTick(tick_);
  for (std::size_t k = 0; k < structures_.size(); ++k) {
    PendingStructure& p = structures_[k];
    if (p.tick == tick_) {
      // Another shard's structure takes its ids all the same (the cap never binds a shard).
      if (shard_.ownerOfStructure(k) == shard_.index)
        spawnStructure(p.build);
      else
        pool_.skipIds(p.particles);
    }
    if (p.tick <= tick_) p.build = {};  // born (or before a restored tick): not needed again
  }
  std::optional<profile::PhaseScope> phase(std::in_place, profile::Phase::Step);
  if (keepVelocities) {
    previousVelocity_.setRows(pool_.size(), 0);  // all copied below: none kept (see above)
    parallelForRows(pool_.size(), [&](std::size_t b, std::size_t e) {
      previousVelocity_.copyRows(pool_.velocity(), b, e);
    });
  }
  forces_->beginTick(pool_, tick_);
  const StepTime time{tick_, settings_.stepRateHz};
  NonfiniteCheck* const check =
      settings_.nonfinite != NonfinitePolicy::Keep ? &nonfiniteCheck_ : nullptr;
  if (collidesBlocks()) {
    stepAndCollideBlocks(time, check, keepPrevious);
  } else {
    integrator_->step(pool_, *forces_, time, check, keepPrevious);
    if (colliders_) {
      colliders_->collide(pool_, tick_, settings_.stepRateHz, integrator_->readsPreviousPosition());
    }
  }
  // (A non-finite row is flagged with NonfiniteCheck::kFlag, which collisions neither read nor
  // write: the same rows whether they ran first or not.)
  if (nonfiniteCheck_.found()) takeNonfinite();
  if (colliders_) pathsTick_ = tick_ + 1;
  pool_.markAllStepped();
  forces_->endTick(pool_, time.stage(2));
  phase.reset();
  endTicks(tick_ + 1, keepVelocities);
  if (keepPrevious) previousTick_ = tick_;
}

bool ParticleSystem::collidesBlocks() const { return colliders_ && forces_->isLocal(); }

void ParticleSystem::stepAndCollideBlocks(const StepTime& time, NonfiniteCheck* check,
                                          bool keepPrevious) {
  // Each block is stepped and then collided on one thread, its rows still in that core's cache:
  // the collision pass is not a second trip through memory. Local forces give a block the bits
  // of a whole step (Integrator::stepRows), and collisions are per row.
  integrator_->prepare(pool_, *forces_);
  colliders_->beginTick(pool_, tick_, settings_.stepRateHz, integrator_->readsPreviousPosition());
  // Paths start where the block's rows started. Unless the pool's column holds that (a frame
  // interpolates across the tick, or the scheme reads it as state), the step writes the starts
  // to a buffer of the thread's (3 × 32 KiB, in L2) that the block's collisions read next.
  const bool buffered = !keepPrevious && !pool_.previousIsState();
  const std::size_t n = pool_.size(), stepped = pool_.firstUnstepped();
  parallelForTasks((n + kParallelBlockRows - 1) / kParallelBlockRows, [&](std::size_t i) {
    const std::size_t begin = i * kParallelBlockRows, end = std::min(n, begin + kParallelBlockRows);
    StepRows rows{RowRange{begin, end}, std::clamp(stepped, begin, end), true, keepPrevious};
    // Groups of rows whose starts the step wrote on every axis: all, unless it skips those that
    // the colliders' span rules out.
    std::uint64_t written = ~std::uint64_t{0};
    if (buffered) {
      thread_local std::vector<float> buffer;
      buffer.resize(3 * kParallelBlockRows);
      for (std::size_t c = 0; c < 3; ++c) rows.starts[c] = buffer.data() + c * kParallelBlockRows;
      rows.span = colliders_->startsSpan();
      rows.written = &written;
      rows.writtenFrom = begin;
    }
    integrator_->stepRows(pool_, *forces_, time, rows, check);
    colliders_->collideRows(pool_, begin, end, {rows.starts[0], rows.starts[1], rows.starts[2]},
                            written);
  });
  colliders_->endTick();
}

void ParticleSystem::endTicks(std::int64_t tick, bool keepVelocities) {
  const profile::PhaseScope phase(profile::Phase::Deaths);
  tick_ = tick;
  // Checked and not stopped, the rows left are finite: a kill removes the rows found below.
  nonfiniteCheck_.setSteppedRowsFinite(settings_.nonfinite != NonfinitePolicy::Keep &&
                                       !nonfiniteStop_);
  pool_.advanceClock(tick_, settings_.stepRateHz);
  if (events_) {
    events_->gather(pool_, colliders_ ? colliders_->contactBlocks()
                                      : std::span<const std::vector<ContactRecord>>{});
  }
  if (keepVelocities) {
    pool_.applyRemovalTo(previousVelocity_);
    velocitiesTick_ = tick_;
  }
  pool_.removeDead();
}

// Rare (the run is broken): a plain scan in row order, so the count and the ids do not depend on
// how the check's tiles were spread over threads.
void ParticleSystem::takeNonfinite() {
  nonfiniteCheck_.clear();
  const bool kill = settings_.nonfinite == NonfinitePolicy::Kill;
  NonfiniteEvent event;
  event.tick = tick_ + 1;
  event.stepRateHz = settings_.stepRateHz;
  std::uint8_t* dead = pool_.dead().data();
  for (std::size_t i = 0; i < pool_.size(); ++i) {
    if ((dead[i] & NonfiniteCheck::kFlag) == 0) continue;
    ++event.particles;
    if (event.firstIds.size() < NonfiniteEvent::kIdsKept) event.firstIds.push_back(pool_.id()[i]);
    // Killed rows keep the flag: removeDead() takes them with the tick's other deaths.
    if (!kill) dead[i] = static_cast<std::uint8_t>(dead[i] & ~NonfiniteCheck::kFlag);
  }
  if (kill) {
    nonfiniteKilled_ += event.particles;
  } else {
    nonfiniteStop_ = std::move(event);
  }
}

void ParticleSystem::restoreClock(std::int64_t tick, const Vec3Column* tickStartVelocities) {
  tick_ = tick;
  pool_.setClock(tick, settings_.stepRateHz);
  previousTick_ = pool_.keepsPrevious() ? tick : -1;  // a restored state brings its own
  pathsTick_ = -1;  // a restored state has no collision paths: frames follow straight lines
  alpha_ = driver_.alpha();
  frameOffset_ = driver_.frameOffset();
  velocitiesTick_ = tickStartVelocities != nullptr ? tick : -1;
  if (tickStartVelocities != nullptr) previousVelocity_ = *tickStartVelocities;
}

void ParticleSystem::setShard(const Shard& shard) {
  if (const std::optional<std::string> p = shard.problem())
    throw std::invalid_argument("shard " + shard.text() + ": " + *p);
  if (!shard.whole() && events_) {
    throw std::invalid_argument("shard " + shard.text() +
                                ": a system with sub-emitters cannot be sharded");
  }
  shard_ = shard;
}

std::uint64_t ParticleSystem::particleBound(std::int64_t ticks) const {
  // At tick k's births, a particle of emitter e born at tick b is alive only if b > k − L_e:
  // L_e ticks cover its longest lifetime, with one to spare for the tick its age reaches it.
  std::vector<std::int64_t> window;
  for (const Emitter& e : emitters_) {
    const EmitterSettings& es = e.settings();
    const double longest = es.lifetime * (1.0 + es.lifetimeJitter);
    const double span = std::ceil(longest * static_cast<double>(settings_.stepRateHz)) + 2.0;
    window.push_back(std::isfinite(span) && span < 9.0e18 ? static_cast<std::int64_t>(span)
                                                          : INT64_MAX);
  }
  std::uint64_t peak = pool_.size(), structures = 0;
  std::size_t nextStructure = 0;
  std::vector<std::size_t> byTick(structures_.size());
  for (std::size_t k = 0; k < byTick.size(); ++k) byTick[k] = k;
  // Structures born before tickCount() are among the rows already.
  std::erase_if(byTick, [&](std::size_t k) { return structures_[k].tick < tick_; });
  std::sort(byTick.begin(), byTick.end(), [&](std::size_t a, std::size_t b) {
    return structures_[a].tick < structures_[b].tick;
  });
  for (std::int64_t k = tick_; k < ticks; ++k) {
    while (nextStructure < byTick.size() && structures_[byTick[nextStructure]].tick <= k)
      structures += structures_[byTick[nextStructure++]].particles;
    std::uint64_t alive = pool_.size() + structures;
    for (std::size_t i = 0; i < emitters_.size(); ++i) {
      const std::int64_t from = window[i] > k - tick_ ? tick_ : k + 1 - window[i];
      alive += emitters_[i].serialBefore(k + 1) - emitters_[i].serialBefore(from);
    }
    peak = std::max(peak, alive);
  }
  return peak;
}

void ParticleSystem::spawnStructure(const StructureBuild& build) {
  std::vector<std::uint64_t> ids(build.particles.size());
  std::vector<bool> spawned(build.particles.size(), false);
  for (std::size_t i = 0; i < build.particles.size(); ++i) {
    const std::size_t row = pool_.spawn(build.particles[i], tick_);
    if (row == ParticlePool::npos) continue;  // refused by max_particles, counted by the pool
    ids[i] = pool_.id()[row];
    spawned[i] = true;
  }
  for (Spring s : build.springs) {
    if (!spawned[s.a] || !spawned[s.b]) continue;
    s.a = ids[s.a];
    s.b = ids[s.b];
    springs_->add(s);
  }
}

namespace {

// Row i of a host buffer whose rows are `stride` bytes apart.
template <typename T>
T& rowOf(T* base, std::size_t stride, std::size_t i) {
  return *reinterpret_cast<T*>(reinterpret_cast<unsigned char*>(base) + i * stride);
}

// previous + (current − previous) · α over rows [0, n), exactly `current` at α = 1 and
// `previous` at α = 0 (the arithmetic would turn −0 into +0). Element by element in float, as an
// Eigen expression would compute it: the bits do not depend on the destination's layout.
void interpolate(const Vec3Column& previous, const Vec3Column& current, float alpha, std::size_t n,
                 const Vec3Destination& out) {
  float* const dst[3] = {out.x, out.y, out.z};
  parallelForRows(n, [&](std::size_t b, std::size_t e) {
    for (int c = 0; c < 3; ++c) {
      const float* p = previous[c].data();
      const float* q = current[c].data();
      float* d = dst[c];
      if (alpha == 1.0f) {
        for (std::size_t i = b; i < e; ++i) rowOf(d, out.rowStride, i) = q[i];
      } else if (alpha == 0.0f) {
        for (std::size_t i = b; i < e; ++i) rowOf(d, out.rowStride, i) = p[i];
      } else {
        for (std::size_t i = b; i < e; ++i)
          rowOf(d, out.rowStride, i) = p[i] + (q[i] - p[i]) * alpha;
      }
    }
  });
}

Vec3Destination columnsOf(Vec3Column& out, std::size_t n) {
  out.resize(static_cast<Eigen::Index>(n));
  return Vec3Destination::columns(out.x.data(), out.y.data(), out.z.data(), n);
}

}  // namespace

double ParticleSystem::shownSeconds() const {
  const __int128 units = static_cast<__int128>(tick_ - 1) * kFlicksPerSecond + frameOffset_;
  return static_cast<double>(units) /
         (static_cast<double>(kFlicksPerSecond) * static_cast<double>(settings_.stepRateHz));
}

void ParticleSystem::interpolatedPositions(float alpha, Vec3Column& out) const {
  if (alpha != 1.0f && !previousPositionsKept()) {
    throw std::logic_error(
        "interpolatedPositions: the newest tick did not keep the positions it started from "
        "(ParticleSystem::setKeepPreviousPositions)");
  }
  const Vec3Destination to = columnsOf(out, pool_.size());
  runParallel(
      [&] { interpolate(pool_.previousPosition(), pool_.position(), alpha, pool_.size(), to); });
  followPaths(alpha, to);
}

void ParticleSystem::followPaths(float alpha, const Vec3Destination& out) const {
  if (!colliders_ || pathsTick_ != tick_ || alpha == 1.0f) return;
  const auto& ids = pool_.id();
  const std::size_t n = pool_.size();
  float* const dst[3] = {out.x, out.y, out.z};
  for (const std::vector<CollisionPath>& block : colliders_->pathBlocks()) {
    for (const CollisionPath& path : block) {
      // Rows are in id order; a particle the tick removed (a kill contact) is not shown.
      const auto it =
          std::lower_bound(ids.begin(), ids.begin() + static_cast<std::ptrdiff_t>(n), path.id);
      if (it == ids.begin() + static_cast<std::ptrdiff_t>(n) || *it != path.id) continue;
      const auto row = static_cast<std::size_t>(it - ids.begin());
      const auto r = static_cast<Eigen::Index>(row);
      const Eigen::Vector3f end(pool_.position().x[r], pool_.position().y[r],
                                pool_.position().z[r]);
      const Eigen::Vector3f p = path.at(alpha, end);
      for (int c = 0; c < 3; ++c) rowOf(dst[c], out.rowStride, row) = p[c];
    }
  }
}

void ParticleSystem::renderPositions(Vec3Column& out) const {
  copyRenderPositions(columnsOf(out, pool_.size()));
}

void ParticleSystem::renderVelocities(Vec3Column& out) const {
  copyRenderVelocities(columnsOf(out, pool_.size()));
}

void ParticleSystem::renderAges(FloatColumn& out) const {
  out.resize(static_cast<Eigen::Index>(pool_.size()));
  copyRenderAges(FloatDestination{out.data(), sizeof(float), pool_.size()});
}

CopyResult ParticleSystem::copyRenderPositions(const Vec3Destination& out) const {
  const std::size_t n = pool_.size();
  if (out.capacity < n) return {n, false};
  const float alpha = frameOffset_ == kFlicksPerSecond ? 1.0f : alpha_;
  runParallel([&] { interpolate(pool_.previousPosition(), pool_.position(), alpha, n, out); });
  followPaths(alpha, out);
  return {n, true};
}

CopyResult ParticleSystem::copyRenderVelocities(const Vec3Destination& out) const {
  const std::size_t n = pool_.size();
  if (out.capacity < n) return {n, false};
  const bool onTick = frameOffset_ == kFlicksPerSecond || velocitiesTick_ != tick_;
  const Vec3Column& previous = onTick ? pool_.velocity() : previousVelocity_;
  runParallel([&] { interpolate(previous, pool_.velocity(), onTick ? 1.0f : alpha_, n, out); });
  return {n, true};
}

CopyResult ParticleSystem::copyRenderAges(const FloatDestination& out) const {
  const std::size_t n = pool_.size();
  if (out.capacity < n) return {n, false};
  if (frameOffset_ == kFlicksPerSecond) {
    runParallel([&] {
      parallelForRows(n, [&](std::size_t b, std::size_t e) {
        if (out.rowStride == sizeof(float)) {
          pool_.ages(b, e, out.data + b);
          return;
        }
        for (std::size_t i = b; i < e; ++i) rowOf(out.data, out.rowStride, i) = pool_.age(i);
      });
    });
    return {n, true};
  }
  // age = ((tick − 1 − birth) · F + offset) / (F · H) seconds: an exact integer numerator, one
  // division in double, one rounding to float. No float time is read back.
  const std::uint32_t* birth = pool_.birthTick().data();
  const double unitsPerSecond =
      static_cast<double>(kFlicksPerSecond) * static_cast<double>(settings_.stepRateHz);
  const std::int64_t last = tick_ - 1, offset = frameOffset_;
  runParallel([&] {
    parallelForRows(n, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        const __int128 units = static_cast<__int128>(last - birth[i]) * kFlicksPerSecond + offset;
        rowOf(out.data, out.rowStride, i) =
            static_cast<float>(static_cast<double>(units) / unitsPerSecond);
      }
    });
  });
  return {n, true};
}

CopyResult ParticleSystem::copyIds(const IdDestination& out) const {
  const std::size_t n = pool_.size();
  if (out.capacity < n) return {n, false};
  const std::uint64_t* id = pool_.id().data();
  for (std::size_t i = 0; i < n; ++i) rowOf(out.data, out.rowStride, i) = id[i];
  return {n, true};
}

std::optional<CopyResult> ParticleSystem::copyColumn(std::string_view name,
                                                     const FloatDestination& out) const {
  const FloatColumn* column = nullptr;
  if (name == "lifetime") {
    column = &pool_.lifetime();
  } else if (name == "mass") {
    column = &pool_.mass();
  } else if (const int life = lifeAttributes_.find(std::string(name)); life >= 0) {
    const std::size_t n = pool_.size();
    if (out.capacity < n) return CopyResult{n, false};
    // The shown ages, worked out once here.
    FloatColumn shown;
    renderAges(shown);
    runParallel([&] { lifeAttributes_.evaluate(life, pool_, shown.data(), out); });
    return CopyResult{n, true};
  } else {
    const std::size_t a = pool_.findAttribute(std::string(name));
    if (a == ParticlePool::npos) return std::nullopt;
    column = &pool_.attribute(a);
  }
  const std::size_t n = pool_.size();
  if (out.capacity < n) return CopyResult{n, false};
  const float* values = column->data();
  for (std::size_t i = 0; i < n; ++i) rowOf(out.data, out.rowStride, i) = values[i];
  return CopyResult{n, true};
}

std::vector<std::string> ParticleSystem::attributeNames() const {
  std::vector<std::string> names;
  for (std::size_t a = 0; a < pool_.attributeCount(); ++a) names.push_back(pool_.attributeName(a));
  for (const std::string& c : lifeAttributes_.columns()) {
    if (pool_.findAttribute(c) == ParticlePool::npos) names.push_back(c);
  }
  return names;
}

}  // namespace tickfx
