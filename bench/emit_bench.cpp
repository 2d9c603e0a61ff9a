// Emission in bulk (issue 13, item 3): how fast an emitter spawns a burst, against the loop a user
// would write by hand, and what a steady rate emitter costs a tick.
//
//   emit_bench                    bursts of 10⁶ and 10⁷, steady population 10⁶ (1 to 2 minutes)
//   emit_bench --quick            smoke run: bursts of 10⁴ and 10⁵, population 10⁵, short timings
//   emit_bench --sizes=1e6        only these burst sizes
//   emit_bench --steady=1e5       the steady part's population (0: skip that part)
//   emit_bench --min-time=0.5 --reps=9
//
// Bursts: one Emitter with a burst of N particles at t = 0 (box, sphere volume or disc, each with
// a 30° spread, speed jitter and lifetime jitter); each repetition times Emitter::emit() of that
// tick alone, on 1 thread and on all threads (a tbb::task_arena each), into
//   a fresh pool    ParticlePool(N) made and reserved before the clock starts: the timed part
//                   writes memory nobody has touched yet, as the first burst of a run does
//                   (the kernel's page faults and zeroing included; reserve() has already
//                   zero-filled the id, birth tick and dead flag columns, 17 of a row's 81 bytes);
//   a reused pool   one pool per size whose rows were written before and emptied untimed: the
//                   emission alone, as in a running system whose storage is already there.
// Baseline: what a user writes by hand, std::mt19937 and std::uniform_real_distribution filling a
// box with a cone of directions into a std::vector of {float p[3], v[3], life} (reserved untimed,
// fresh or reused as the pool), 1 thread: every tickfx figure is also given as a ratio to it.
// The cases of one size take turns repetition by repetition (a burst of outside load hits them
// all alike) until each has at least `reps` repetitions and `min-time` seconds; a figure is the
// median. Untimed first: a small burst of every shape in each arena (TBB's workers, the code), and
// one repetition of each case that first writes the reused storage.
//
// Steady emission: a system at 60 Hz, gravity and drag, 1 thread, with a rate emitter of P
// particles/s and lifetime 1 s (a population of about P once warm), against the same system with
// the same population born in one burst at t = 0 that never dies (no emission, no deaths), and a
// copy of that one (the A/A spread). The cost of emission is the difference between the two ticks
// (BenchHarness.h's turn-taking timing); Emitter::emit() of one tick's births into a pool of P
// rows, timed on its own, splits it into the emission and the rest (the deaths the births make).
//
// Output: a header, detail lines (indented), then one line per figure, `name: value unit (...)`.
#include <sys/resource.h>
#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#ifdef __GLIBC__
#include <malloc.h>
#endif

#include "BenchHarness.h"
#include "fields/ForceSet.h"
#include "fields/Gravity.h"
#include "fields/LinearDrag.h"
#include "particles/Emitter.h"
#include "particles/ParticlePool.h"
#include "particles/ParticleSystem.h"

namespace {

namespace bench = tickfx::bench;
using bench::threadsLabel;

// ---- the emitters ---------------------------------------------------------------------------

constexpr std::uint64_t kSeed = 20261125;
constexpr std::int64_t kStepRateHz = 60;
constexpr double kTargetSpawnsPerSecond = 5e7;  // issue 13: on 1 thread
constexpr double kSpreadDegrees = 30.0;
constexpr double kSpeed = 5.0;  // m/s
constexpr double kSpeedJitter = 0.2;
constexpr double kLifetime = 2.0;  // s, bursts
constexpr double kLifetimeJitter = 0.25;
const Eigen::Vector3d kEmitterPosition(1.0, 2.0, 3.0);
const Eigen::Vector3d kBoxSize(2.0, 1.0, 2.0);
constexpr double kRadius = 1.0;

struct Shape {
  const char* name;
  tickfx::EmitterShape shape;
};

std::vector<Shape> burstShapes() {
  return {{"box", tickfx::BoxShape{kBoxSize}},
          {"sphere", tickfx::SphereShape{kRadius, /*surface=*/false}},
          {"disc", tickfx::DiscShape{kRadius, Eigen::Vector3d::UnitY()}}};
}

tickfx::EmitterSettings emitterSettings(const tickfx::EmitterShape& shape) {
  tickfx::EmitterSettings s;
  s.name = "bench";
  s.position = kEmitterPosition;
  s.shape = shape;
  s.direction = Eigen::Vector3d::UnitY();
  s.speed = kSpeed;
  s.speedJitter = kSpeedJitter;
  s.spreadDegrees = kSpreadDegrees;
  s.lifetime = kLifetime;
  s.lifetimeJitter = kLifetimeJitter;
  return s;
}

tickfx::Emitter burstEmitter(const tickfx::EmitterShape& shape, std::size_t n) {
  tickfx::EmitterSettings s = emitterSettings(shape);
  s.bursts.push_back({0.0, n});
  return tickfx::Emitter(s, 0, kStepRateHz);
}

// ---- the hand-written baseline ---------------------------------------------------------------

struct HandParticle {
  float p[3], v[3], life;
};

// The loop a user writes: one std::mt19937, float uniforms, the box, a cone of half-angle
// `spread` around the direction (uniform over the spherical cap, as tickfx samples it), speed and
// lifetime jitter. The direction's basis is computed once, outside the loop.
void handFill(std::vector<HandParticle>& out, std::size_t n) {
  std::mt19937 rng(static_cast<std::uint32_t>(kSeed));
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  constexpr float kTwoPi = 6.28318530717958647692f;
  const float cx = static_cast<float>(kEmitterPosition.x());
  const float cy = static_cast<float>(kEmitterPosition.y());
  const float cz = static_cast<float>(kEmitterPosition.z());
  const float sx = static_cast<float>(kBoxSize.x()), sy = static_cast<float>(kBoxSize.y()),
              sz = static_cast<float>(kBoxSize.z());
  const float cosMax =
      std::cos(static_cast<float>(kSpreadDegrees * 3.14159265358979323846 / 180.0));
  // Direction +y: the cap's basis is +x and +z.
  const float b1[3] = {1.0f, 0.0f, 0.0f}, b2[3] = {0.0f, 0.0f, 1.0f}, d[3] = {0.0f, 1.0f, 0.0f};
  const auto speed = static_cast<float>(kSpeed), speedJitter = static_cast<float>(kSpeedJitter);
  const auto life = static_cast<float>(kLifetime), lifeJitter = static_cast<float>(kLifetimeJitter);
  for (std::size_t i = 0; i < n; ++i) {
    HandParticle q;
    q.p[0] = cx + sx * (unit(rng) - 0.5f);
    q.p[1] = cy + sy * (unit(rng) - 0.5f);
    q.p[2] = cz + sz * (unit(rng) - 0.5f);
    const float cosT = 1.0f - unit(rng) * (1.0f - cosMax);
    const float sinT = std::sqrt(std::max(0.0f, 1.0f - cosT * cosT));
    const float phi = kTwoPi * unit(rng);
    const float c = sinT * std::cos(phi), s = sinT * std::sin(phi);
    const float v = speed * (1.0f + speedJitter * (2.0f * unit(rng) - 1.0f));
    for (int k = 0; k < 3; ++k) q.v[k] = v * (c * b1[k] + s * b2[k] + cosT * d[k]);
    q.life = life * (1.0f + lifeJitter * (2.0f * unit(rng) - 1.0f));
    out.push_back(q);
  }
  bench::escape(out.data());
}

double positionSum(const std::vector<HandParticle>& ps) {
  double sum = 0.0;
  for (const HandParticle& q : ps) sum += double{q.p[0]} + double{q.p[1]} + double{q.p[2]};
  return sum;
}

// ---- timing bursts ---------------------------------------------------------------------------

long minorFaults() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt;
}

// One burst measurement, a case of a single repetition a batch (BenchHarness.h): `before`
// prepares it (untimed), `run` is timed, `after` checks the count and adds to the checksum
// (untimed; false on a wrong count). The page faults of each repetition are counted.
bench::Case burstCase(std::string name, std::function<void()> run) {
  bench::Case c(std::move(name), [run = std::move(run)](std::int64_t) { run(); });
  c.calibrated = false;
  c.counter = [] { return static_cast<double>(minorFaults()); };
  return c;
}

// At most 3 significant digits, as 3.14e7 or 5e7: short, and read back by any float parser.
std::string sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2e", v);
  std::string out(buf);
  const std::size_t e = out.find('e');
  if (e == std::string::npos) return out;
  std::string mantissa = out.substr(0, e), exponent = out.substr(e + 1);
  mantissa.erase(mantissa.find_last_not_of('0') + 1);  // 5.00 → 5., 1.20 → 1.2
  if (mantissa.back() == '.') mantissa.pop_back();
  const bool negative = exponent[0] == '-';
  exponent.erase(0, exponent.find_first_not_of("+-0"));
  if (exponent.empty()) return mantissa;
  return mantissa + "e" + (negative ? "-" : "") + exponent;
}

struct Figure {
  std::string line;
};

// The arena of 1 thread and that of all threads, kept for the whole run.
struct Arenas {
  explicit Arenas(int all) : one(1), every(all), allThreads(all) {}
  tbb::task_arena one, every;
  int allThreads;
  tbb::task_arena& of(int threads) { return threads == 1 ? one : every; }
};

// Before any timing: TBB's workers started and every emitter's code run once in each arena.
void warmUpThreads(Arenas& arenas) {
  constexpr std::size_t kRows = 100'000;
  for (const Shape& s : burstShapes()) {
    const tickfx::Emitter emitter = burstEmitter(s.shape, kRows);
    for (const int threads : {1, arenas.allThreads}) {
      tickfx::ParticlePool pool(kRows);
      arenas.of(threads).execute([&] { emitter.emit(pool, kSeed, 0); });
      bench::escape(pool.position().x.data());
    }
  }
}

// Every burst case of one size; appends its figure lines to `figures`. False on a wrong count.
bool runBursts(std::size_t n, const bench::Timing& timing, Arenas& arenas,
               std::vector<Figure>& figures, double& checksum) {
  std::printf("\nburst of N = %zu\n", n);
  std::fflush(stdout);
  const std::string label = bench::sizeLabel(n);
  const std::vector<int> threadCounts = bench::oneAndAll(arenas.allThreads);

  const auto countError = [n](const std::string& name, std::size_t size, std::uint64_t dropped) {
    std::fprintf(stderr, "error: %s: %zu particles after the burst (%llu dropped), expected %zu\n",
                 name.c_str(), size, static_cast<unsigned long long>(dropped), n);
    return false;
  };

  // State the cases keep between their untimed parts. The reused storage is shared by every
  // reused case of this size (one at a time), so it costs one pool and one vector.
  std::unique_ptr<tickfx::ParticlePool> freshPool;
  tickfx::ParticlePool reusedPool(n);
  std::vector<HandParticle> freshHand, reusedHand;
  reusedHand.reserve(n);

  std::vector<tickfx::Emitter> emitters;
  const std::vector<Shape> shapes = burstShapes();
  for (const Shape& s : shapes) emitters.push_back(burstEmitter(s.shape, n));

  std::vector<bench::Case> cases;
  for (const bool reuse : {false, true}) {
    const std::string mode = reuse ? ", reused pool" : "";
    {
      std::vector<HandParticle>* out = reuse ? &reusedHand : &freshHand;
      bench::Case c = burstCase(
          "hand mt19937 box loop " + label + " 1 thread" + (reuse ? ", reused vector" : ""),
          [out, n] { handFill(*out, n); });
      c.warmUp = reuse;
      c.before = [out, reuse, n] {
        if (reuse) {
          out->clear();
        } else {
          // Frees the storage (`*out = {}` would assign an empty list and keep the capacity).
          std::vector<HandParticle>().swap(*out);
          out->reserve(n);
        }
      };
      c.after = [out, reuse, n, &checksum, name = c.name, countError] {
        if (out->size() != n) return countError(name, out->size(), 0);
        checksum += positionSum(*out);
        if (!reuse) std::vector<HandParticle>().swap(*out);
        return true;
      };
      cases.push_back(std::move(c));
    }
    for (std::size_t s = 0; s < shapes.size(); ++s) {
      for (const int threads : threadCounts) {
        tbb::task_arena* arena = &arenas.of(threads);
        const tickfx::Emitter* emitter = &emitters[s];
        const std::string name = std::string("emit ") + shapes[s].name + " " + label + " " +
                                 threadsLabel(threads) + mode;
        if (reuse) {
          bench::Case c = burstCase(name, [&reusedPool, arena, emitter] {
            arena->execute([&] { emitter->emit(reusedPool, kSeed, 0); });
            bench::escape(reusedPool.position().x.data());
          });
          // The first reused case writes the shared pool's pages before the others are timed.
          c.warmUp = s == 0 && threads == 1;
          c.before = [&reusedPool] { reusedPool.resizeForRestore(0, 0, 0); };
          c.after = [&reusedPool, n, &checksum, name, countError] {
            if (reusedPool.size() != n || reusedPool.droppedSpawns() != 0)
              return countError(name, reusedPool.size(), reusedPool.droppedSpawns());
            checksum += bench::positionSum(reusedPool);
            return true;
          };
          cases.push_back(std::move(c));
        } else {
          bench::Case c = burstCase(name, [&freshPool, arena, emitter] {
            arena->execute([&] { emitter->emit(*freshPool, kSeed, 0); });
            bench::escape(freshPool->position().x.data());
          });
          c.before = [&freshPool, n] {
            freshPool.reset();
            freshPool = std::make_unique<tickfx::ParticlePool>(n);
            freshPool->reserve(n);  // the allocation, untimed; the pages are touched by emit()
          };
          c.after = [&freshPool, n, &checksum, name, countError] {
            if (freshPool->size() != n || freshPool->droppedSpawns() != 0)
              return countError(name, freshPool->size(), freshPool->droppedSpawns());
            checksum += bench::positionSum(*freshPool);
            freshPool.reset();  // unmapping the storage, untimed
            return true;
          };
          cases.push_back(std::move(c));
        }
      }
    }
  }

  if (!bench::timeCases(cases, timing)) return false;

  const auto spawnsPerSecond = [n](const bench::Case& c) {
    return static_cast<double>(n) / c.seconds();
  };
  std::printf("  %-52s %9s  %-30s %7s %s\n", "case", "median ms", "(repetitions; fastest, slowest)",
              "cores", "page faults/1000 spawns");
  for (const bench::Case& c : cases) {
    char reps[64];
    std::snprintf(reps, sizeof reps, "(%zu; %.3f, %.3f)", c.secondsPerTick.size(),
                  1e3 * c.fastest(), 1e3 * c.slowest());
    std::printf("  %-52s %9.3f  %-30s %7.2f %.3f\n", c.name.c_str(), 1e3 * c.seconds(), reps,
                c.cores(), 1e3 * bench::median(c.counts) / static_cast<double>(n));
  }
  std::fflush(stdout);

  // Lines of one mode: the hand loop first, then per shape 1 thread and all threads.
  const std::size_t perMode = 1 + shapes.size() * threadCounts.size();
  char buf[512];
  for (std::size_t m = 0; m < 2; ++m) {
    const bench::Case& hand = cases[m * perMode];
    const double handRate = spawnsPerSecond(hand);
    std::snprintf(buf, sizeof buf, "%s: %s spawns/s (%.2fx target %s)", hand.name.c_str(),
                  sci(handRate).c_str(), handRate / kTargetSpawnsPerSecond,
                  sci(kTargetSpawnsPerSecond).c_str());
    figures.push_back({buf});
    for (std::size_t s = 0; s < shapes.size(); ++s) {
      const std::size_t first = m * perMode + 1 + s * threadCounts.size();
      const double oneRate = spawnsPerSecond(cases[first]);
      for (std::size_t t = 0; t < threadCounts.size(); ++t) {
        const bench::Case& c = cases[first + t];
        const double rate = spawnsPerSecond(c);
        if (t == 0) {
          std::snprintf(buf, sizeof buf, "%s: %s spawns/s (%.2fx target %s; %.2fx hand %s)",
                        c.name.c_str(), sci(rate).c_str(), rate / kTargetSpawnsPerSecond,
                        sci(kTargetSpawnsPerSecond).c_str(), rate / handRate, "mt19937 loop");
        } else {
          // The cores the process kept busy: well under the thread count means outside load
          // took the others, and the figure says little about scaling.
          std::snprintf(buf, sizeof buf,
                        "%s: %s spawns/s (%.2fx 1 thread; %.2fx hand %s; %.2f of %d cores busy)",
                        c.name.c_str(), sci(rate).c_str(), rate / oneRate, rate / handRate,
                        "mt19937 loop", c.cores(), threadCounts[t]);
        }
        figures.push_back({buf});
      }
    }
  }
  return true;
}

// ---- steady emission -------------------------------------------------------------------------

constexpr double kSteadyLifetime = 1.0;  // s
const Eigen::Vector3f kGravity(0.0f, -9.81f, 0.0f);
constexpr float kDragRate = 0.5f;  // 1/s
const Eigen::Vector3f kAirVelocity(2.0f, 0.0f, -1.0f);

// A fountain: a disc with the bursts' spread and speed jitter, no lifetime jitter (so the
// population is steady to a particle). `rate` > 0: a rate emitter with lifetime 1 s; else a burst
// of `burst` particles at t = 0 that never die.
tickfx::EmitterSettings steadyEmitter(double rate, std::uint64_t burst) {
  tickfx::EmitterSettings s = emitterSettings(tickfx::DiscShape{kRadius, Eigen::Vector3d::UnitY()});
  s.lifetimeJitter = 0.0;
  if (rate > 0.0) {
    s.rate = rate;
    s.lifetime = kSteadyLifetime;
  } else {
    s.bursts.push_back({0.0, burst});
    s.lifetime = std::numeric_limits<double>::infinity();
  }
  return s;
}

std::unique_ptr<tickfx::ParticleSystem> makeSystem(const tickfx::EmitterSettings& emitter,
                                                   std::size_t maxParticles) {
  tickfx::SystemSettings settings;
  settings.stepRateHz = kStepRateHz;
  settings.seed = kSeed;
  settings.maxParticles = maxParticles;
  settings.threads = 1;
  tickfx::ForceSet forces;
  forces.add(std::make_unique<tickfx::Gravity>(kGravity));
  forces.add(std::make_unique<tickfx::LinearDrag>(kDragRate, kAirVelocity));
  return std::make_unique<tickfx::ParticleSystem>(
      settings, std::vector<tickfx::EmitterSettings>{emitter}, std::move(forces));
}

// Ticks a frame in the steady cases that run fused frames.
constexpr std::int64_t kFusedTicks = 4;

// False when a population is not what it should be.
bool runSteady(std::size_t population, const bench::Timing& timing, std::vector<Figure>& figures,
               double& checksum) {
  const double rate = static_cast<double>(population) / kSteadyLifetime;
  std::printf(
      "\nsteady emission: %s particles/s, lifetime %g s, %lld Hz, gravity + drag, 1 thread\n",
      sci(rate).c_str(), kSteadyLifetime, static_cast<long long>(kStepRateHz));
  std::fflush(stdout);
  // Births come before the tick's deaths: room for one tick's births above the population.
  const std::size_t maxParticles = 2 * population + 1024;
  auto emitting = makeSystem(steadyEmitter(rate, 0), maxParticles);
  // One second fills the population, a second one is the warm-up of the steady state.
  emitting->stepTicks(2 * kStepRateHz);
  const std::size_t alive = emitting->pool().size();
  // Particles born in the last 59 ticks: those of the 60th tick back reach 1 s at its end.
  const double expected = rate * (kSteadyLifetime - 1.0 / static_cast<double>(kStepRateHz));
  auto still = makeSystem(steadyEmitter(0.0, alive), maxParticles);
  auto control = makeSystem(steadyEmitter(0.0, alive), maxParticles);
  still->stepTicks(2 * kStepRateHz);
  control->stepTicks(2 * kStepRateHz);
  std::printf("  alive after %lld ticks: %zu with the emitter (%.0f expected), %zu without\n",
              static_cast<long long>(2 * kStepRateHz), alive, expected, still->pool().size());

  // The same two populations advanced in frames of kFusedTicks ticks: fused frames, whose deaths
  // are removed once a frame (ParticleSystem's class comment).
  auto emittingFused = makeSystem(steadyEmitter(rate, 0), maxParticles);
  auto stillFused = makeSystem(steadyEmitter(0.0, alive), maxParticles);
  emittingFused->stepTicks(2 * kStepRateHz);
  stillFused->stepTicks(2 * kStepRateHz);

  // step() tick by tick: stepTicks(batch) would fuse the whole batch into one frame.
  const auto ticksOf = [](tickfx::ParticleSystem& system) {
    return [&system](std::int64_t ticks) {
      for (std::int64_t i = 0; i < ticks; ++i) system.step();
    };
  };
  const auto framesOf = [](tickfx::ParticleSystem& system) {
    return [&system](std::int64_t ticks) {
      for (; ticks > 0; ticks -= kFusedTicks) system.stepTicks(kFusedTicks);
    };
  };
  std::vector<bench::Case> cases;
  cases.emplace_back("tick with the rate emitter", ticksOf(*emitting));
  cases.emplace_back("tick without emission", ticksOf(*still));
  cases.emplace_back("tick without emission, copy", ticksOf(*control));
  cases.emplace_back("frames of 4 ticks with the rate emitter", framesOf(*emittingFused));
  cases.back().ticksPerFrame = kFusedTicks;
  cases.emplace_back("frames of 4 ticks without emission", framesOf(*stillFused));
  cases.back().ticksPerFrame = kFusedTicks;
  // Batches of one second of ticks for every case: the cases take turns, so each batch's first
  // tick finds the others' rows in the cache, and the shares compare batches of one length; a
  // second also holds the emitter's periodic move of the live rows to the freed front, as a run
  // does.
  for (bench::Case& c : cases) c.minimumBatch = kStepRateHz;
  // Shares are differences of two tick times, each moved by the machine's load: more rounds
  // than the other parts take, paired round by round (bench::pairedShare).
  bench::Timing steadyTiming = timing;
  steadyTiming.reps = std::max(timing.reps, 15);
  bench::timeCases(cases, steadyTiming);

  const auto populationOk = [](const tickfx::ParticleSystem& s, double lo, double hi) {
    const auto size = static_cast<double>(s.pool().size());
    return size >= lo && size <= hi && s.pool().droppedSpawns() == 0 && !s.nonfiniteStop();
  };
  bool ok = true;
  if (!populationOk(*emitting, expected - 2.0, expected + 2.0)) {
    std::fprintf(stderr,
                 "error: %zu particles alive with the emitter (%llu dropped), expected %.0f\n",
                 emitting->pool().size(),
                 static_cast<unsigned long long>(emitting->pool().droppedSpawns()), expected);
    ok = false;
  }
  for (const auto* s : {still.get(), control.get(), stillFused.get()}) {
    const auto a = static_cast<double>(alive);
    if (!populationOk(*s, a, a)) {
      std::fprintf(stderr, "error: %zu particles alive without emission, expected %zu\n",
                   s->pool().size(), alive);
      ok = false;
    }
  }

  // Emitter::emit() alone: one tick's births appended to a pool of `alive` rows, truncated back
  // untimed, on 1 thread.
  const tickfx::Emitter rateEmitter(steadyEmitter(rate, 0), 0, kStepRateHz);
  tickfx::ParticlePool pool(maxParticles);
  tickfx::Emitter(steadyEmitter(0.0, alive), 0, kStepRateHz).emit(pool, kSeed, 0);
  tbb::task_arena arenaOne(1);
  std::vector<double> emitSeconds;
  double emitTimed = 0.0;
  std::uint64_t spawned = 0;
  const int minSamples = std::max(timing.reps, 20);
  for (std::int64_t tick = 4 * kStepRateHz;
       static_cast<int>(emitSeconds.size()) < minSamples + 1 || emitTimed < timing.minTime;
       ++tick) {
    const std::uint64_t nextId = pool.nextId();
    const bench::Clock::time_point start = bench::Clock::now();
    std::uint64_t made = 0;
    arenaOne.execute([&] { made = rateEmitter.emit(pool, kSeed, tick); });
    const double s = std::chrono::duration<double>(bench::Clock::now() - start).count();
    if (pool.size() != alive + made) {
      std::fprintf(stderr, "error: %zu rows after emitting %llu into %zu\n", pool.size(),
                   static_cast<unsigned long long>(made), alive);
      return false;
    }
    checksum += static_cast<double>(pool.position().y[static_cast<Eigen::Index>(alive)]);
    pool.resizeForRestore(alive, nextId, 0);
    if (tick == 4 * kStepRateHz) continue;  // the first touches the rows above `alive`: warm-up
    emitSeconds.push_back(s);
    emitTimed += s;
    spawned += made;
  }

  for (const bench::Case& c : cases) {
    std::printf(
        "  %-44s %9.4f ms/tick  (median of %zu batches of %lld ticks; %.4f to %.4f; %.2f cores)\n",
        c.name.c_str(), 1e3 * c.seconds(), c.secondsPerTick.size(), static_cast<long long>(c.batch),
        1e3 * c.fastest(), 1e3 * c.slowest(), c.cores());
  }
  const double with = cases[0].seconds();
  const double without = cases[1].seconds();
  const double copy = cases[2].seconds();
  const double emitAlone = bench::median(emitSeconds);
  const double perTick = static_cast<double>(spawned) / static_cast<double>(emitSeconds.size());
  std::printf("  %-44s %9.4f ms/tick  (median of %zu ticks of %.0f births)\n",
              "Emitter::emit() alone", 1e3 * emitAlone, emitSeconds.size(), perTick);
  std::fflush(stdout);

  const std::string pop = bench::sizeLabel(population);
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "steady %s tick with emitter 1 thread: %.4g ms (%.4g ms without emission; A/A "
                "spread %+.1f %%)",
                pop.c_str(), 1e3 * with, 1e3 * without, 100.0 * (copy / without - 1.0));
  figures.push_back({buf});
  const double share = bench::pairedShare(cases[0], cases[1]);
  const double shareAA = bench::pairedShare(cases[2], cases[1]);
  std::snprintf(buf, sizeof buf,
                "steady %s emission cost: %.1f %% of the tick (target < 10 %%; median of %zu "
                "rounds paired; the medians' difference %.1f %%; the A/A pair %+.1f %%)",
                pop.c_str(), 100.0 * share, cases[0].secondsPerTick.size(),
                100.0 * (with - without) / with, 100.0 * shareAA);
  figures.push_back({buf});
  std::snprintf(buf, sizeof buf,
                "steady %s Emitter::emit alone: %.1f %% of the tick (%.4g ms, %s spawns/s; the "
                "rest of the paired cost, %.4g ms, is the deaths)",
                pop.c_str(), 100.0 * emitAlone / with, 1e3 * emitAlone,
                sci(perTick / emitAlone).c_str(), 1e3 * (share * with - emitAlone));
  figures.push_back({buf});
  const double withFused = cases[3].seconds();
  const double withoutFused = cases[4].seconds();
  std::snprintf(buf, sizeof buf,
                "steady %s emission cost, frames of %lld ticks: %.1f %% of the tick (paired; "
                "%.4g ms a tick, %.4g ms without emission; fused frames remove the dead once a "
                "frame)",
                pop.c_str(), static_cast<long long>(kFusedTicks),
                100.0 * bench::pairedShare(cases[3], cases[4]), 1e3 * withFused,
                1e3 * withoutFused);
  figures.push_back({buf});
  checksum += bench::positionSum(emitting->pool()) + bench::positionSum(still->pool()) +
              bench::positionSum(control->pool()) + bench::positionSum(emittingFused->pool()) +
              bench::positionSum(stillFused->pool());
  return ok;
}

// ---- the run ----------------------------------------------------------------------------------

std::string transparentHugePages() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string line;
  if (!std::getline(in, line)) return "unknown";
  const std::size_t open = line.find('['), close = line.find(']');
  if (open == std::string::npos || close == std::string::npos || close < open) return line;
  return line.substr(open + 1, close - open - 1);
}

void usage(const char* argv0) {
  std::printf(
      "usage: %s [--quick] [--sizes=N[,N...]] [--steady=N] [--min-time=SECONDS] [--reps=COUNT]\n"
      "  --quick            smoke run: sizes 1e4,1e5, population 1e5 and --min-time=0.02\n"
      "  --sizes=1e6,1e7    burst sizes (default 1e6,1e7)\n"
      "  --steady=1e6       population of the steady emission part (0: skip it)\n"
      "  --min-time=0.3     seconds each case is timed, per size\n"
      "  --reps=5           minimum number of timed repetitions per case (the median is "
      "reported)\n",
      argv0);
}

}  // namespace

int main(int argc, char** argv) {
  std::optional<std::vector<std::size_t>> sizes;
  std::optional<std::size_t> steady;
  bench::CommandLine cl(usage);
  cl.sizes("--sizes", sizes)
      .count(
          "--steady", steady, [](std::size_t n) { return n == 0 || n >= 60; },
          " (0, or at least 60 particles)");
  if (const std::optional<int> exitCode = cl.parse(argc, argv)) return *exitCode;
  std::vector<std::size_t> burstSizes{1'000'000, 10'000'000};
  std::size_t population = 1'000'000;
  if (cl.quick) {
    burstSizes = {10'000, 100'000};
    population = 100'000;
  }
  if (sizes) burstSizes = *sizes;
  if (steady) population = *steady;

#ifdef __GLIBC__
  // Every column of 64 KiB or more (of a fresh pool, and the fresh vector) gets a mapping of its
  // own, returned to the kernel when freed: each fresh repetition then writes untouched pages,
  // rather than heap memory an earlier repetition left behind (glibc's threshold would otherwise
  // move up to 32 MiB after the first free, so 10⁶ and 10⁷ would be timed differently). Bursts
  // under about 10⁴ stay in the heap: their fresh and reused figures are alike.
  mallopt(M_MMAP_THRESHOLD, 64 << 10);
#endif

  const int allThreads = tbb::info::default_concurrency();
  std::printf(
      "emit_bench: bursts (box, sphere volume, disc; %g° spread, speed and lifetime jitter) "
      "and a steady rate emitter\n",
      kSpreadDegrees);
  bench::printMachine(" (TBB uses " + std::to_string(allThreads) +
                      "), transparent huge pages: " + transparentHugePages());
  bench::printBuild();

  std::vector<Figure> figures;
  double checksum = 0.0;
  Arenas arenas(allThreads);
  warmUpThreads(arenas);
  for (const std::size_t n : burstSizes) {
    if (!runBursts(n, cl.timing, arenas, figures, checksum)) return 1;
  }
  bool ok = true;
  if (population > 0) ok = runSteady(population, cl.timing, figures, checksum);

  std::printf("\nchecksum of the particles made (keeps every case's work observable): %.9g\n",
              checksum);
  std::printf("\n");
  for (const Figure& f : figures) std::printf("%s\n", f.line.c_str());
  return ok ? 0 : 1;
}
