#include "particles/ParticleSystem.h"

#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/task_arena.h>
#include <stdexcept>

#include "particles/Clock.h"
#include "particles/ParallelFor.h"

namespace tickfx {

class ParticleSystem::ThreadArena {
 public:
  explicit ThreadArena(int threads) : arena_(threads > 0 ? threads : tbb::task_arena::automatic) {
    // TBB keeps its workers to the core count unless told otherwise; a determinism test that
    // asks for 8 threads on 2 cores must really get 8. Only ever raised, never lowered: the
    // smallest active limit wins process-wide, and lowering it would starve other systems.
    if (threads > tbb::info::default_concurrency()) {
      limit_ = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                     static_cast<std::size_t>(threads));
    }
  }
  template <typename F>
  void execute(F&& f) {
    arena_.execute(std::forward<F>(f));
  }

 private:
  std::unique_ptr<tbb::global_control> limit_;  // before the arena: it must outlive it
  tbb::task_arena arena_;
};

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
    : settings_(settings),
      pool_(settings.maxParticles),
      emitters_(makeEmitters(emitters, settings.stepRateHz)),
      forces_(std::move(forces)),
      integrator_(makeIntegrator(settings.integrator)),
      driver_(settings.stepRateHz, settings.maxTicksPerFrame, settings.overrunPolicy),
      arena_(std::make_unique<ThreadArena>(settings.threads)) {
  if (settings.threads < 0) throw std::invalid_argument("threads must be >= 0");
  for (std::size_t i = 0; i < forces_.size() && springs_ == nullptr; ++i) {
    springs_ = dynamic_cast<SpringNetwork*>(&forces_.module(i));
  }
  if (!structures.empty() && springs_ == nullptr) {
    springs_ = static_cast<SpringNetwork*>(&forces_.add(std::make_unique<SpringNetwork>()));
  }
  for (std::size_t i = 0; i < structures.size(); ++i) {
    // Built now, not at the structure's birth tick: bad settings fail the construction, and the
    // build is kept for the birth.
    StructureBuild build =
        buildStructure(structures[i], settings.seed, static_cast<std::uint32_t>(i));
    const Flicks at = flicksFromSeconds(structures[i].time);
    const auto tick = static_cast<std::int64_t>(
        (static_cast<__int128>(at) * settings.stepRateHz + kFlicksPerSecond - 1) /
        kFlicksPerSecond);
    structures_.push_back(PendingStructure{std::move(build), tick});
  }
}

ParticleSystem::~ParticleSystem() = default;

AdvanceResult ParticleSystem::advance(Flicks frame) {
  const AdvanceResult result = driver_.advance(frame);
  stepTicks(result.ticks);
  alpha_ = result.alpha;
  return result;
}

void ParticleSystem::step() { stepTicks(1); }

void ParticleSystem::stepTicks(std::int64_t ticks) {
  if (ticks <= 0) return;
  arena_->execute([&] {
    for (std::int64_t i = 0; i < ticks; ++i) {
      runTick();
      if (tickObserver_) tickObserver_(*this);
    }
  });
}

void ParticleSystem::runTick() {
  for (const Emitter& e : emitters_) e.emit(pool_, settings_.seed, tick_);
  for (PendingStructure& p : structures_) {
    if (p.tick == tick_) spawnStructure(p.build);
    if (p.tick <= tick_) p.build = {};  // born (or before a restored tick): not needed again
  }
  forces_.beginTick(pool_, tick_);
  const StepTime time{tick_, settings_.stepRateHz};
  integrator_->step(pool_, forces_, time);
  pool_.markAllStepped();
  forces_.endTick(pool_, tick_, time.at(1.0));
  ++tick_;
  pool_.updateAges(tick_, settings_.stepRateHz);
  pool_.removeDead();
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

void ParticleSystem::interpolatedPositions(float alpha, Vec3Column& out) const {
  const std::size_t n = pool_.size();
  out.resize(static_cast<Eigen::Index>(n));
  const Vec3Column& p = pool_.position();
  const Vec3Column& prev = pool_.previousPosition();
  parallelForRows(n, [&](std::size_t b, std::size_t e) {
    const auto i = static_cast<Eigen::Index>(b), m = static_cast<Eigen::Index>(e - b);
    for (int c = 0; c < 3; ++c) {
      out[c].segment(i, m) =
          prev[c].segment(i, m) + (p[c].segment(i, m) - prev[c].segment(i, m)) * alpha;
    }
  });
}

}  // namespace tickfx
