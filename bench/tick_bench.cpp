// One tick of gravity + periodic wind + linear drag with semi-implicit Euler: tickfx against the
// array-of-structs loop a user would write by hand, measured in the same run so that the ratio
// holds even on a machine whose absolute speed drifts.
//
//   tick_bench                    sizes 10⁴, 10⁶ and 10⁷ (under a minute on 2 cores)
//   tick_bench --quick            smoke run: sizes 10⁴ and 10⁵, short timings
//   tick_bench --sizes=1e4,1e6    only these particle counts
//   tick_bench --min-time=0.5 --reps=9
//   tick_bench --check-cost       what the per-tick non-finite check ([simulation] nonfinite =
//                                 "stop" or "kill") costs each integrator's step(), 1 thread
//
// Cases, each starting from the same N particles (varied positions and velocities, infinite
// lifetime, so the count never changes):
//   AoS loop          std::vector<{Vector3f position, velocity}>, one thread: what a user writes.
//   hand SoA loop     six float arrays through __restrict pointers, 1 thread and all threads:
//                     the best hand loop (48 bytes moved a particle-step), the same bits as AoS;
//                     where the processor has AVX2 (AVX-512), also compiled for it (1 thread),
//                     since tickfx's update loops take their clones there (particles/Isa.h).
//   tickfx integrate  SemiImplicitEuler::step on the pool: force evaluation and state update
//                     only, the part of a tick that does the physics.
//   tickfx step()     ParticleSystem::step(): the above plus emitters, ForceSet::beginTick, age
//                     recomputation and removal of the dead, i.e. what a tick costs a user.
//   tickfx step() SSE2  step() with the loops forced to their baseline path (where AVX2 or
//                     AVX-512 is the default): what the clones gain; with AVX-512 the default,
//                     also `step() AVX2`, forced to the AVX2 clones.
//   tickfx fused x4   stepTicks(4): frames of four ticks, each block of rows taken through all
//                     four while in cache (fused frames), the same bits as four step() calls.
//                     Under nonfinite = "stop" (the default) a frame is first proven finite
//                     from bounds of its state (particles/StateBound.h; where it cannot be, it
//                     copies its rows' state, to replay the frame tick by tick if it goes
//                     non-finite); `keep` runs without either, as the hand loops do.
// Each tickfx case runs with 1 thread and with all threads, so the table separates the gain of
// the layout from the gain of threading.
//
// Timing (BenchHarness.h): batches of ticks sized to min-time/reps seconds, the cases of one size
// taking turns batch by batch; a case's figure is the median over its batches of the time per tick.
//
// Output: the tables, then one line a figure, `name: value unit (ratios, targets)`.
#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "BenchHarness.h"
#include "fields/AnchorSpring.h"
#include "fields/ForceSet.h"
#include "fields/Gravity.h"
#include "fields/LinearDrag.h"
#include "fields/PeriodicWind.h"
#include "fields/SpringNetwork.h"
#include "integrators/SemiImplicitEuler.h"
#include "particles/Column.h"
#include "particles/Isa.h"
#include "particles/ParticleSystem.h"
#include "particles/Random.h"

namespace {

namespace bench = tickfx::bench;
using bench::threadsLabel;

// ---- the scene, shared by both sides ----------------------------------------------------------

constexpr std::int64_t kStepRateHz = 60;
const Eigen::Vector3f kGravity(0.0f, -9.81f, 0.0f);
// Not unit length on purpose: the baseline then has to normalise it the way PeriodicWind does,
// and the check below shows that it did.
const Eigen::Vector3f kWindDirection(1.0f, 0.0f, 0.5f);
constexpr float kWindAmplitude = 3.0f;    // m/s²
constexpr double kWindFrequencyHz = 4.0;  // well below the 30 Hz Nyquist limit of 60 Hz steps
constexpr float kDragRate = 0.5f;         // 1/s
const Eigen::Vector3f kAirVelocity(2.0f, 0.0f, -1.0f);

tickfx::PeriodicWind::Settings windSettings() {
  tickfx::PeriodicWind::Settings s;
  s.direction = kWindDirection;
  s.amplitude = kWindAmplitude;
  s.frequency = kWindFrequencyHz;
  return s;
}

// The order matters for the check: the sum gravity + wind + drag is rounded in this order on
// both sides.
tickfx::ForceSet makeForces() {
  tickfx::ForceSet forces;
  forces.add(std::make_unique<tickfx::Gravity>(kGravity));
  forces.add(std::make_unique<tickfx::PeriodicWind>(windSettings()));
  forces.add(std::make_unique<tickfx::LinearDrag>(kDragRate, kAirVelocity));
  return forces;
}

// Uniform in [-1, 1), from the top 24 bits so that every value is an exact float.
float symmetricUnit(std::uint64_t key) {
  return static_cast<float>(tickfx::splitmix64(key) >> 40) * 0x1p-23f - 1.0f;
}

struct Particle {
  Eigen::Vector3f position, velocity;
};

// A pure function of the index, so both sides get the same state without a shared copy of it
// (which at 10⁷ particles would be another 240 MB).
Particle initialParticle(std::size_t i) {
  const std::uint64_t k = 6 * static_cast<std::uint64_t>(i);
  return {Eigen::Vector3f(10.0f * symmetricUnit(k), 10.0f * symmetricUnit(k + 1),
                          10.0f * symmetricUnit(k + 2)),
          Eigen::Vector3f(5.0f * symmetricUnit(k + 3), 5.0f * symmetricUnit(k + 4),
                          5.0f * symmetricUnit(k + 5))};
}

// ---- the hand-written baseline ---------------------------------------------------------------

class HandWrittenLoop {
 public:
  explicit HandWrittenLoop(std::size_t n) : wind_(windSettings()) {
    particles_.reserve(n);
    for (std::size_t i = 0; i < n; ++i) particles_.push_back(initialParticle(i));
    windDirection_ = kWindDirection;
    windDirection_ /= windDirection_.norm();
  }

  void tick() {
    const float dt = static_cast<float>(1.0 / static_cast<double>(kStepRateHz));
    const double t = static_cast<double>(tick_) / static_cast<double>(kStepRateHz);
    // The strength goes through PeriodicWind rather than std::sin so that both sides use the
    // same bits of the sine: the check can then expect agreement to the last bit. It is one call
    // per tick, nothing next to the particle loop.
    const Eigen::Vector3f wind = windDirection_ * wind_.strength(t);
    const Eigen::Vector3f g = kGravity, air = kAirVelocity;
    const float k = kDragRate;
    for (Particle& q : particles_) {
      const Eigen::Vector3f a = g + wind + k * (air - q.velocity);
      q.velocity += a * dt;
      q.position += q.velocity * dt;
    }
    ++tick_;
    bench::escape(particles_.data());
  }

  const std::vector<Particle>& particles() const { return particles_; }

 private:
  std::vector<Particle> particles_;
  tickfx::PeriodicWind wind_;
  Eigen::Vector3f windDirection_;
  std::int64_t tick_ = 0;
};

// A hand loop's column: n floats in the pool's own storage (allocateColumnStorage: cache-line
// aligned, huge pages from 2 MiB on), so that the loops compared differ in their loops, not in
// their pages. With std::vector's 4 KiB pages the hand loop's batches at 10⁷ ranged from 10 to
// 57 ms a tick on a KVM guest, where the pool's ranged from 9 to 17.
class HandColumn {
 public:
  explicit HandColumn(std::size_t n)
      : n_(n),
        data_(static_cast<float*>(tickfx::allocateColumnStorage(
            std::max<std::size_t>(64, (n * sizeof(float) + 63) / 64 * 64)))) {}
  HandColumn(const HandColumn&) = delete;
  HandColumn& operator=(const HandColumn&) = delete;
  ~HandColumn() { std::free(data_); }
  std::size_t size() const { return n_; }
  float* data() { return data_; }
  float& operator[](std::size_t i) { return data_[i]; }
  float operator[](std::size_t i) const { return data_[i]; }
  const float* begin() const { return data_; }
  const float* end() const { return data_ + n_; }

 private:
  std::size_t n_;
  float* data_;
};

// The best loop a user could write: one float array a component (structure of arrays), raw
// `__restrict` pointers so the compiler vectorises without alias checks, blocks of rows shared
// among threads. The same sums in the same order as the AoS loop, so the two agree bit for bit.
// 24 bytes read and 24 written a particle-step.
class HandSoaLoop {
 public:
  /// With `isa` AVX2 or AVX-512, the same loop compiled for it (the compiler vectorises it eight
  /// or sixteen floats wide): what tickfx's own clones are measured against too.
  explicit HandSoaLoop(std::size_t n, tickfx::Isa isa = tickfx::Isa::Baseline)
      : isa_(isa), px_(n), py_(n), pz_(n), vx_(n), vy_(n), vz_(n), wind_(windSettings()) {
    for (std::size_t i = 0; i < n; ++i) {
      const Particle p = initialParticle(i);
      px_[i] = p.position.x();
      py_[i] = p.position.y();
      pz_[i] = p.position.z();
      vx_[i] = p.velocity.x();
      vy_[i] = p.velocity.y();
      vz_[i] = p.velocity.z();
    }
    windDirection_ = kWindDirection;
    windDirection_ /= windDirection_.norm();
  }

  /// One tick, its rows split among the threads of `arena`.
  void tick(tbb::task_arena& arena) {
    const float dt = static_cast<float>(1.0 / static_cast<double>(kStepRateHz));
    const double t = static_cast<double>(tick_) / static_cast<double>(kStepRateHz);
    const Eigen::Vector3f wind = windDirection_ * wind_.strength(t);
    // g + wind first, as Eigen's AoS expression rounds it.
    const float ax = kGravity.x() + wind.x(), ay = kGravity.y() + wind.y(),
                az = kGravity.z() + wind.z();
    const float k = kDragRate, airX = kAirVelocity.x(), airY = kAirVelocity.y(),
                airZ = kAirVelocity.z();
    const Accel acc{ax, ay, az, k, airX, airY, airZ, dt};
    if (arena.max_concurrency() == 1) {
      rows(acc, 0, px_.size());
    } else {
      arena.execute([&] {
        tbb::parallel_for(
            tbb::blocked_range<std::size_t>(0, px_.size(), 16384),
            [&](const tbb::blocked_range<std::size_t>& r) { rows(acc, r.begin(), r.end()); });
      });
    }
    ++tick_;
    bench::escape(px_.data());
  }

  /// True when every coordinate has the bits of the AoS loop's.
  bool sameBitsAs(const HandWrittenLoop& aos) const {
    const std::vector<Particle>& ps = aos.particles();
    if (ps.size() != px_.size()) return false;
    for (std::size_t i = 0; i < ps.size(); ++i) {
      const std::array<float, 6> mine{px_[i], py_[i], pz_[i], vx_[i], vy_[i], vz_[i]};
      const std::array<float, 6> theirs{ps[i].position.x(), ps[i].position.y(), ps[i].position.z(),
                                        ps[i].velocity.x(), ps[i].velocity.y(), ps[i].velocity.z()};
      if (std::memcmp(mine.data(), theirs.data(), sizeof mine) != 0) return false;
    }
    return true;
  }

  double positionSum() const {
    double sum = 0.0;
    for (const auto* c : {&px_, &py_, &pz_})
      for (const float x : *c) sum += static_cast<double>(x);
    return sum;
  }

 private:
  struct Accel {
    float ax, ay, az, k, airX, airY, airZ, dt;
  };
  void rows(const Accel& a, std::size_t begin, std::size_t end) {
#ifdef TICKFX_AVX2_CLONES
    if (isa_ == tickfx::Isa::Avx512) {
      rowsOfAvx512(px_.data(), py_.data(), pz_.data(), vx_.data(), vy_.data(), vz_.data(), a, begin,
                   end);
      return;
    }
    if (isa_ == tickfx::Isa::Avx2) {
      rowsOfAvx2(px_.data(), py_.data(), pz_.data(), vx_.data(), vy_.data(), vz_.data(), a, begin,
                 end);
      return;
    }
#endif
    rowsOf(px_.data(), py_.data(), pz_.data(), vx_.data(), vy_.data(), vz_.data(), a, begin, end);
  }
#ifdef TICKFX_AVX2_CLONES
  [[gnu::target("avx2"), gnu::flatten]] static void rowsOfAvx2(
      float* __restrict px, float* __restrict py, float* __restrict pz, float* __restrict vx,
      float* __restrict vy, float* __restrict vz, const Accel a, std::size_t begin,
      std::size_t end) {
    rowsOf(px, py, pz, vx, vy, vz, a, begin, end);
  }
  // The flags of tickfx's AVX-512 clones (integrators/CheckedRows.h).
  [[gnu::target("avx2,avx512f"), gnu::flatten]] static void rowsOfAvx512(
      float* __restrict px, float* __restrict py, float* __restrict pz, float* __restrict vx,
      float* __restrict vy, float* __restrict vz, const Accel a, std::size_t begin,
      std::size_t end) {
    rowsOf(px, py, pz, vx, vy, vz, a, begin, end);
  }
#endif
  // A function of its own: `__restrict` holds for parameters, not for a lambda's captures.
  [[gnu::always_inline]] static inline void rowsOf(float* __restrict px, float* __restrict py,
                                                   float* __restrict pz, float* __restrict vx,
                                                   float* __restrict vy, float* __restrict vz,
                                                   const Accel a, std::size_t begin,
                                                   std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      vx[i] += (a.ax + a.k * (a.airX - vx[i])) * a.dt;
      vy[i] += (a.ay + a.k * (a.airY - vy[i])) * a.dt;
      vz[i] += (a.az + a.k * (a.airZ - vz[i])) * a.dt;
      px[i] += vx[i] * a.dt;
      py[i] += vy[i] * a.dt;
      pz[i] += vz[i] * a.dt;
    }
  }

  tickfx::Isa isa_;
  HandColumn px_, py_, pz_, vx_, vy_, vz_;
  tickfx::PeriodicWind wind_;
  Eigen::Vector3f windDirection_;
  std::int64_t tick_ = 0;
};

// ---- tickfx side -----------------------------------------------------------------------------

// Forces after the tick's own (gravity, wind, drag), which every scheme forms in its one update
// loop (ForceSet::uniformAndDrag): with kTether an anchor spring (local: the force passes, tile
// by tile), with kNetwork an empty spring network (not local: the force passes, each over all
// rows in turn).
enum Extra { kNone, kTether, kNetwork };

std::unique_ptr<tickfx::ParticleSystem> makeSystem(
    std::size_t n, int threads, tickfx::NonfinitePolicy nonfinite = tickfx::NonfinitePolicy::Stop,
    const std::string& integrator = "semi_implicit_euler", Extra extra = kNone) {
  tickfx::SystemSettings settings;
  settings.nonfinite = nonfinite;
  settings.stepRateHz = kStepRateHz;
  settings.integrator = integrator;
  settings.maxParticles = n;
  settings.threads = threads;
  tickfx::ForceSet forces = makeForces();
  if (extra == kTether) {
    forces.add(std::make_unique<tickfx::AnchorSpring>(Eigen::Vector3f::Zero(), 0.5f));
  }
  if (extra == kNetwork) forces.add(std::make_unique<tickfx::SpringNetwork>());
  auto system = std::make_unique<tickfx::ParticleSystem>(
      settings, std::vector<tickfx::EmitterSettings>{}, std::move(forces));
  tickfx::ParticlePool& pool = system->editPool();
  pool.reserve(n);  // one allocation instead of the doubling growth
  for (std::size_t i = 0; i < n; ++i) {
    const Particle p = initialParticle(i);
    tickfx::ParticleInit init;
    init.position = p.position;
    init.velocity = p.velocity;
    pool.spawn(init, 0);
  }
  return system;
}

struct Difference {
  double position = 0.0, velocity = 0.0;  // largest absolute difference, m and m/s
  bool withinRoundOff = true;
};

Difference compare(const HandWrittenLoop& aos, const tickfx::ParticlePool& pool,
                   Difference d = {}) {
  // A few float ulps of the larger magnitude: what reordering one sum could cost.
  constexpr double kRelative = 8.0 * std::numeric_limits<float>::epsilon();
  const std::vector<Particle>& ps = aos.particles();
  if (pool.size() != ps.size()) {
    d.withinRoundOff = false;
    return d;
  }
  for (std::size_t i = 0; i < ps.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    for (int c = 0; c < 3; ++c) {
      const double p0 = ps[i].position[c], p1 = pool.position()[c][r];
      const double v0 = ps[i].velocity[c], v1 = pool.velocity()[c][r];
      d.position = std::max(d.position, std::abs(p0 - p1));
      d.velocity = std::max(d.velocity, std::abs(v0 - v1));
      if (!(std::abs(p0 - p1) <= kRelative * std::max(1.0, std::abs(p0))) ||
          !(std::abs(v0 - v1) <= kRelative * std::max(1.0, std::abs(v0)))) {
        d.withinRoundOff = false;
      }
    }
  }
  return d;
}

double positionSum(const HandWrittenLoop& aos) {
  double sum = 0.0;
  for (const Particle& p : aos.particles()) sum += p.position.cast<double>().sum();
  return sum;
}

using bench::positionSum;  // one overload set, so the checksum line reads alike for every side

// ---- the run ----------------------------------------------------------------------------------

struct Options {
  std::vector<std::size_t> sizes{10'000, 1'000'000, 10'000'000};
  bench::Timing timing;
};

struct Row {
  std::size_t n;
  std::string name;
  double stepsPerSecond;
  double ratio;
  double cores;  // CPU over wall time while the case ran
  // bench::pairedSpeedup() over the hand SoA loop on 1 thread, and over the case's own 1-thread
  // form (0 for a case on 1 thread): the figures the targets are read from.
  double pairedHand = 0.0;
  double pairedOneThread = 0.0;
};

// Ticks a frame in the fused cases (issue 13's target: 4).
constexpr std::int64_t kFusedTicks = 4;

std::string fusedLabel(int threads) {
  return "tickfx fused x" + std::to_string(kFusedTicks) + ", " + threadsLabel(threads);
}

// Runs every case for `n` particles; returns false when the two sides disagree.
bool runSize(std::size_t n, const Options& o, int allThreads, std::vector<Row>& rows,
             double& checksum) {
  std::printf("\nN = %zu\n", n);
  std::fflush(stdout);
  HandWrittenLoop aos(n);
  HandSoaLoop soaOne(n), soaAll(n);
  // The hand loop and step() on the other paths of the processor: the hand loop compiled for
  // AVX2 and AVX-512 where the processor has them; tickfx forced to the baseline (SSE2) and,
  // where AVX-512 is its default, to AVX2.
  const bool avx2 = tickfx::isaAvailable(tickfx::Isa::Avx2);
  const bool avx512 = tickfx::isaAvailable(tickfx::Isa::Avx512);
  std::optional<HandSoaLoop> soaAvx2, soaAvx512;
  if (avx2) soaAvx2.emplace(n, tickfx::Isa::Avx2);
  if (avx512) soaAvx512.emplace(n, tickfx::Isa::Avx512);
  std::unique_ptr<tickfx::ParticleSystem> one = makeSystem(n, 1);
  std::unique_ptr<tickfx::ParticleSystem> baselineOne = avx2 ? makeSystem(n, 1) : nullptr;
  std::unique_ptr<tickfx::ParticleSystem> avx2One = avx512 ? makeSystem(n, 1) : nullptr;
  std::unique_ptr<tickfx::ParticleSystem> all = allThreads > 1 ? makeSystem(n, 0) : nullptr;
  // The same system without the per-tick non-finite check: what the check costs a tick.
  std::unique_ptr<tickfx::ParticleSystem> unchecked =
      makeSystem(n, 1, tickfx::NonfinitePolicy::Keep);
  // Systems advanced kFusedTicks ticks a frame: fused frames (ParticleSystem's class comment).
  std::unique_ptr<tickfx::ParticleSystem> fusedOne = makeSystem(n, 1);
  std::unique_ptr<tickfx::ParticleSystem> fusedAll = allThreads > 1 ? makeSystem(n, 0) : nullptr;
  // Fused frames under "keep", as the hand loop runs (the header says what "stop" adds).
  std::unique_ptr<tickfx::ParticleSystem> fusedUnchecked =
      makeSystem(n, 1, tickfx::NonfinitePolicy::Keep);

  // Tick 0 from the identical initial state on every side.
  tbb::task_arena arenaOne(1), arenaAll(allThreads);
  aos.tick();
  soaOne.tick(arenaOne);
  soaAll.tick(arenaAll);
  if (soaAvx2) soaAvx2->tick(arenaOne);
  if (soaAvx512) soaAvx512->tick(arenaOne);
  const bool soaSame = soaOne.sameBitsAs(aos) && soaAll.sameBitsAs(aos) &&
                       (!soaAvx2 || soaAvx2->sameBitsAs(aos)) &&
                       (!soaAvx512 || soaAvx512->sameBitsAs(aos));
  std::printf("  check after one tick, hand SoA vs AoS: %s\n",
              soaSame ? "the same bits" : "MISMATCH");
  one->step();
  unchecked->step();
  if (baselineOne) {
    const tickfx::ForcedIsa forced(tickfx::Isa::Baseline);
    baselineOne->step();
  }
  if (avx2One) {
    const tickfx::ForcedIsa forced(tickfx::Isa::Avx2);
    avx2One->step();
  }
  Difference d = compare(aos, one->pool());
  if (all) {
    all->step();
    d = compare(aos, all->pool(), d);
  }
  std::printf("  check after one tick, AoS vs tickfx: max |dp| = %.3g m, max |dv| = %.3g m/s: %s\n",
              d.position, d.velocity, d.withinRoundOff ? "ok" : "MISMATCH");

  // The integrate cases get their own integrators (own scratch), on the systems' pools.
  tickfx::SemiImplicitEuler integrateOne, integrateAll;
  std::int64_t tickOne = one->tickCount(), tickAll = tickOne;
  const auto integrate = [](tbb::task_arena& arena, tickfx::SemiImplicitEuler& integrator,
                            tickfx::ParticleSystem& system, std::int64_t& tick,
                            std::int64_t ticks) {
    arena.execute([&] {
      for (std::int64_t i = 0; i < ticks; ++i) {
        integrator.step(system.editPool(), system.forces(), tickfx::StepTime{tick++, kStepRateHz});
      }
    });
  };

  std::vector<bench::Case> cases;
  cases.emplace_back("AoS loop, 1 thread", [&](std::int64_t ticks) {
    for (std::int64_t i = 0; i < ticks; ++i) aos.tick();
  });
  cases.emplace_back("hand SoA loop, " + threadsLabel(1), [&](std::int64_t ticks) {
    for (std::int64_t i = 0; i < ticks; ++i) soaOne.tick(arenaOne);
  });
  if (all) {
    cases.emplace_back("hand SoA loop, " + threadsLabel(allThreads), [&](std::int64_t ticks) {
      for (std::int64_t i = 0; i < ticks; ++i) soaAll.tick(arenaAll);
    });
  }
  if (soaAvx2) {
    cases.emplace_back("hand SoA loop AVX2, " + threadsLabel(1), [&](std::int64_t ticks) {
      for (std::int64_t i = 0; i < ticks; ++i) soaAvx2->tick(arenaOne);
    });
  }
  if (soaAvx512) {
    cases.emplace_back("hand SoA loop AVX-512, " + threadsLabel(1), [&](std::int64_t ticks) {
      for (std::int64_t i = 0; i < ticks; ++i) soaAvx512->tick(arenaOne);
    });
  }
  cases.emplace_back("tickfx integrate, " + threadsLabel(1), [&](std::int64_t ticks) {
    integrate(arenaOne, integrateOne, *one, tickOne, ticks);
  });
  if (all) {
    cases.emplace_back("tickfx integrate, " + threadsLabel(allThreads), [&](std::int64_t ticks) {
      integrate(arenaAll, integrateAll, *all, tickAll, ticks);
    });
  }
  // step() per tick, not stepTicks(): a frame usually runs one or two ticks, and the arena
  // entry of each call is part of what a tick costs.
  cases.emplace_back("tickfx step(), " + threadsLabel(1), [&](std::int64_t ticks) {
    for (std::int64_t i = 0; i < ticks; ++i) one->step();
  });
  cases.emplace_back("tickfx step(), 1 t., no check", [&](std::int64_t ticks) {
    for (std::int64_t i = 0; i < ticks; ++i) unchecked->step();
  });
  if (baselineOne) {
    cases.emplace_back("tickfx step(), 1 t., SSE2", [&](std::int64_t ticks) {
      const tickfx::ForcedIsa forced(tickfx::Isa::Baseline);
      for (std::int64_t i = 0; i < ticks; ++i) baselineOne->step();
    });
  }
  if (avx2One) {
    cases.emplace_back("tickfx step(), 1 t., AVX2", [&](std::int64_t ticks) {
      const tickfx::ForcedIsa forced(tickfx::Isa::Avx2);
      for (std::int64_t i = 0; i < ticks; ++i) avx2One->step();
    });
  }
  if (all) {
    cases.emplace_back("tickfx step(), " + threadsLabel(allThreads), [&](std::int64_t ticks) {
      for (std::int64_t i = 0; i < ticks; ++i) all->step();
    });
  }

  // Frames of kFusedTicks ticks (batches are whole frames).
  const auto frames = [](tickfx::ParticleSystem& system, std::int64_t ticks) {
    for (; ticks > 0; ticks -= kFusedTicks) system.stepTicks(kFusedTicks);
  };
  cases.emplace_back(fusedLabel(1), [&](std::int64_t ticks) { frames(*fusedOne, ticks); });
  cases.back().ticksPerFrame = kFusedTicks;
  cases.emplace_back(fusedLabel(1) + ", keep",
                     [&](std::int64_t ticks) { frames(*fusedUnchecked, ticks); });
  cases.back().ticksPerFrame = kFusedTicks;
  if (fusedAll) {
    cases.emplace_back(fusedLabel(allThreads),
                       [&](std::int64_t ticks) { frames(*fusedAll, ticks); });
    cases.back().ticksPerFrame = kFusedTicks;
  }

  bench::timeCases(cases, o.timing);

  // The AoS loop is the baseline every ratio of the table is to.
  const bench::Case& aosCase = cases.front();
  const auto named = [&](const std::string& name) -> const bench::Case* {
    for (const bench::Case& c : cases) {
      if (c.name == name) return &c;
    }
    return nullptr;
  };
  const bench::Case& handCase = *named("hand SoA loop, " + threadsLabel(1));
  const std::string allLabel = threadsLabel(allThreads);
  for (const bench::Case& c : cases) {
    const double s = c.seconds();
    std::printf("  %-30s %10.4f ms/tick  (median of %zu batches of %lld ticks; %.4f to %.4f)\n",
                c.name.c_str(), 1e3 * s, c.secondsPerTick.size(), static_cast<long long>(c.batch),
                1e3 * c.fastest(), 1e3 * c.slowest());
    Row r{n, c.name, static_cast<double>(n) / s, bench::speedup(c, aosCase), c.cores()};
    r.pairedHand = bench::pairedSpeedup(c, handCase);
    const std::size_t at = c.name.rfind(allLabel);
    if (allThreads > 1 && at != std::string::npos && at + allLabel.size() == c.name.size()) {
      if (const bench::Case* single = named(c.name.substr(0, at) + threadsLabel(1)))
        r.pairedOneThread = bench::pairedSpeedup(c, *single);
    }
    rows.push_back(r);
  }
  std::fflush(stdout);

  checksum += (soaAvx2 ? soaAvx2->positionSum() : 0.0) +
              (soaAvx512 ? soaAvx512->positionSum() : 0.0) +
              (baselineOne ? positionSum(baselineOne->pool()) : 0.0) +
              (avx2One ? positionSum(avx2One->pool()) : 0.0);
  checksum += positionSum(aos) + soaOne.positionSum() + soaAll.positionSum() +
              positionSum(one->pool()) + positionSum(unchecked->pool()) +
              (all ? positionSum(all->pool()) : 0.0) + positionSum(fusedOne->pool()) +
              positionSum(fusedUnchecked->pool()) +
              (fusedAll ? positionSum(fusedAll->pool()) : 0.0);
  return d.withinRoundOff && soaSame;
}

// Per integrator, step() on 1 thread with the non-finite check (NonfinitePolicy::Stop) and
// without (Keep): under the tick's own forces, which every scheme forms in its one update loop
// (checked by exceptions), with an anchor spring added ("+spring": the force passes tile by tile,
// by exceptions) and with an empty spring network ("+network": the force passes over all rows,
// by sums).
// Two identical systems measured up to 3 % apart at 10⁴ and 13 % at 10⁶ with where their columns
// sat, so each of kCheckCopies systems is timed both ways, switching its policy before each batch
// (and running one untimed tick, so that a checked batch starts as a run's checked ticks do:
// after unchecked ones, the first checked tick checks every value), all taking turns batch by
// batch in the order below; a side's figure is the median of all its batches. The A/A spread
// sets half the systems' unchecked batches against the other half's: what placement alone does,
// and what comparing sides on different systems would mistake for the check.
void runCheckCosts(const std::vector<std::size_t>& sizes, const bench::Timing& timing) {
  constexpr int kCheckCopies = 4;
  struct Cost {
    std::size_t n;
    std::string integrator;
    double cost, spread;  // %
  };
  std::vector<Cost> costs;
  std::printf(
      "\nnon-finite check, step() on 1 thread: checked against unchecked (%d systems, both ways)\n",
      kCheckCopies);
  std::printf("%10s  %-30s %14s %14s %10s %12s\n", "N", "integrator", "checked ms", "unchecked ms",
              "cost", "A/A spread");
  // Case k times system k % kCheckCopies, checked in the first round of systems and unchecked in
  // the second, then the other way round: each batch follows a batch of another system (a batch
  // after its own system's measured faster at 10⁶, whose state fits in this machine's L3), and
  // each side follows each system equally often.
  constexpr int kCases = 4 * kCheckCopies;
  const auto checkedCase = [](int k) { return (k / kCheckCopies) % 3 == 0; };
  // The median of the batches of one side (checked or not) of systems [first, first + count).
  const auto pooledMedian = [&](const std::vector<bench::Case>& cases, bool checked, int first,
                                int count) {
    std::vector<double> all;
    for (int k = 0; k < kCases; ++k) {
      const int system = k % kCheckCopies;
      if (checkedCase(k) != checked || system < first || system >= first + count) continue;
      const std::vector<double>& s = cases[static_cast<std::size_t>(k)].secondsPerTick;
      all.insert(all.end(), s.begin(), s.end());
    }
    return bench::median(all);
  };
  for (const std::size_t n : sizes) {
    for (const Extra extra : {kNone, kTether, kNetwork}) {
      for (const std::string& name : tickfx::integratorNames()) {
        const std::string label = name + (extra == kTether    ? " +spring"
                                          : extra == kNetwork ? " +network"
                                                              : "");
        std::vector<std::unique_ptr<tickfx::ParticleSystem>> systems;
        for (int i = 0; i < kCheckCopies; ++i) {
          systems.push_back(makeSystem(n, 1, tickfx::NonfinitePolicy::Stop, name, extra));
        }
        std::vector<bench::Case> cases;
        for (int k = 0; k < kCases; ++k) {
          tickfx::ParticleSystem* const s =
              systems[static_cast<std::size_t>(k % kCheckCopies)].get();
          const auto policy =
              checkedCase(k) ? tickfx::NonfinitePolicy::Stop : tickfx::NonfinitePolicy::Keep;
          cases.emplace_back(checkedCase(k) ? "checked" : "unchecked", [s](std::int64_t ticks) {
            for (std::int64_t t = 0; t < ticks; ++t) s->step();
          });
          cases.back().before = [s, policy] {
            s->setNonfinitePolicy(policy);
            s->step();
          };
        }
        bench::timeCases(cases, timing);
        const double with = pooledMedian(cases, true, 0, kCheckCopies);
        const double without = pooledMedian(cases, false, 0, kCheckCopies);
        const double halfA = pooledMedian(cases, false, 0, kCheckCopies / 2);
        const double halfB = pooledMedian(cases, false, kCheckCopies / 2, kCheckCopies / 2);
        costs.push_back({n, label, 100.0 * (with / without - 1.0), 100.0 * (halfB / halfA - 1.0)});
        std::printf("%10zu  %-30s %14.4f %14.4f %+9.1f %% %+10.1f %%\n", n, label.c_str(),
                    1e3 * with, 1e3 * without, costs.back().cost, costs.back().spread);
        std::fflush(stdout);
      }
    }
  }
  std::printf("\n");
  for (const Cost& c : costs) {
    std::printf("check cost %s %s: %+.1f %% of the tick (target < 2 %%; A/A spread %+.1f %%)\n",
                c.integrator.c_str(), bench::sizeLabel(c.n).c_str(), c.cost, c.spread);
  }
}

// The summary, one line a figure (BenchHarness.h), from the rows of the table.
void printFigures(const std::vector<Row>& rows, const std::vector<std::size_t>& sizes,
                  int allThreads) {
  const std::string all = threadsLabel(allThreads);
  const char* t = all.c_str();
  std::printf("\n");
  for (const std::size_t n : sizes) {
    const auto row = [&](const std::string& name) {
      for (const Row& r : rows) {
        if (r.n == n && r.name == name) return r;
      }
      return Row{n, name, 0.0, 0.0, 0.0, 0.0, 0.0};
    };
    const std::string size = bench::sizeLabel(n);
    const char* z = size.c_str();
    const auto rate = [](const Row& r) { return bench::g3(r.stepsPerSecond); };
    const Row aos = row("AoS loop, 1 thread"), soa = row("hand SoA loop, 1 thread"),
              integrate = row("tickfx integrate, 1 thread"), step = row("tickfx step(), 1 thread");
    const double a = aos.stepsPerSecond, h = soa.stepsPerSecond;
    std::printf("tick AoS loop 1 thread %s: %s particle-steps/s (%.2fx hand SoA 1 thread)\n", z,
                rate(aos).c_str(), a / h);
    std::printf("tick hand SoA 1 thread %s: %s particle-steps/s (%.2fx AoS)\n", z,
                rate(soa).c_str(), h / a);
    std::printf(
        "tick integrate 1 thread %s: %s particle-steps/s (%.2fx hand SoA 1 thread; %.2fx AoS)\n", z,
        rate(integrate).c_str(), integrate.stepsPerSecond / h, integrate.stepsPerSecond / a);
    std::printf(
        "tick step 1 thread %s: %s particle-steps/s (%.2fx hand SoA 1 thread paired round by "
        "round, target >= 0.9x; %.2fx by the medians; %.2fx AoS)\n",
        z, rate(step).c_str(), step.pairedHand, step.stepsPerSecond / h, step.stepsPerSecond / a);
    // The wider paths, where the processor has them: each hand loop against the baseline one
    // and step() on its widest path; step() forced to each narrower path of its own.
    const char* widest = tickfx::isaName(tickfx::activeIsa());
    for (const char* isa : {"AVX2", "AVX-512"}) {
      const Row wide = row(std::string("hand SoA loop ") + isa + ", 1 thread");
      if (wide.stepsPerSecond <= 0.0) continue;
      std::printf(
          "tick hand SoA %s 1 thread %s: %s particle-steps/s (%.2fx hand SoA; tickfx step() on %s "
          "%.2fx it)\n",
          isa, z, rate(wide).c_str(), wide.stepsPerSecond / h, widest,
          step.stepsPerSecond / wide.stepsPerSecond);
    }
    for (const char* isa : {"SSE2", "AVX2"}) {
      const Row forced = row(std::string("tickfx step(), 1 t., ") + isa);
      if (forced.stepsPerSecond <= 0.0) continue;
      std::printf(
          "tick step %s 1 thread %s: %s particle-steps/s (%.2fx hand SoA 1 thread; %.2fx step() "
          "on %s)\n",
          isa, z, rate(forced).c_str(), forced.stepsPerSecond / h,
          forced.stepsPerSecond / step.stepsPerSecond, widest);
    }
    const Row fused = row(fusedLabel(1)), fusedKeep = row(fusedLabel(1) + ", keep");
    std::printf(
        "tick fused %lld ticks a frame 1 thread %s: %s particle-steps/s (%.2fx hand SoA 1 thread "
        "paired, target >= 1.5x at 1e7; %.2fx by the medians; %.2fx tickfx step())\n",
        static_cast<long long>(kFusedTicks), z, rate(fused).c_str(), fused.pairedHand,
        fused.stepsPerSecond / h, fused.stepsPerSecond / step.stepsPerSecond);
    std::printf(
        "tick fused %lld ticks a frame 1 thread keep %s: %s particle-steps/s (%.2fx hand SoA 1 "
        "thread paired, target >= 1.5x at 1e7, like for like: no non-finite check, as the hand "
        "loop; %.2fx by the medians)\n",
        static_cast<long long>(kFusedTicks), z, rate(fusedKeep).c_str(), fusedKeep.pairedHand,
        fusedKeep.stepsPerSecond / h);
    if (allThreads == 1) continue;
    const Row fusedAll = row(fusedLabel(allThreads));
    std::printf(
        "tick fused %lld ticks a frame %s %s: %s particle-steps/s (%.2fx tickfx fused 1 thread; "
        "%.2fx hand SoA %s)\n",
        static_cast<long long>(kFusedTicks), t, z, rate(fusedAll).c_str(),
        fusedAll.stepsPerSecond / fused.stepsPerSecond,
        fusedAll.stepsPerSecond / row("hand SoA loop, " + all).stepsPerSecond, t);
    const Row soaAll = row("hand SoA loop, " + all), integrateAll = row("tickfx integrate, " + all),
              stepAll = row("tickfx step(), " + all);
    const double hAll = soaAll.stepsPerSecond;
    std::printf("tick hand SoA %s %s: %s particle-steps/s (%.2fx hand SoA 1 thread; %.2fx AoS)\n",
                t, z, rate(soaAll).c_str(), hAll / h, hAll / a);
    std::printf(
        "tick integrate %s %s: %s particle-steps/s (%.2fx tickfx 1 thread; %.2fx hand SoA %s)\n", t,
        z, rate(integrateAll).c_str(), integrateAll.stepsPerSecond / integrate.stepsPerSecond,
        integrateAll.stepsPerSecond / hAll, t);
    std::printf(
        "tick step %s %s: %s particle-steps/s (%.2fx tickfx 1 thread paired, target >= 1.8x at "
        "1e7; %.2fx by the medians; %.2fx hand SoA %s, which gains %.2fx paired; %.2f of %d cores "
        "busy)\n",
        t, z, rate(stepAll).c_str(), stepAll.pairedOneThread,
        stepAll.stepsPerSecond / step.stepsPerSecond, stepAll.stepsPerSecond / hAll, t,
        soaAll.pairedOneThread, stepAll.cores, allThreads);
  }
}

void usage(const char* argv0) {
  std::printf(
      "usage: %s [--quick] [--sizes=N[,N...]] [--min-time=SECONDS] [--reps=COUNT] [--check-cost]\n"
      "  --quick            smoke run: sizes 1e4,1e5 and --min-time=0.02\n"
      "  --sizes=1e4,1e6    particle counts (default 1e4,1e6,1e7)\n"
      "  --min-time=0.3     seconds each case is timed, per size\n"
      "  --reps=5           minimum number of timed batches per case (the median is reported)\n"
      "  --check-cost       only the non-finite check's cost, per integrator (sizes 1e4,1e6)\n",
      argv0);
}

}  // namespace

int main(int argc, char** argv) {
  std::optional<std::vector<std::size_t>> sizes;
  bool checkCost = false;
  bench::CommandLine cl(usage);
  cl.flag("--check-cost", checkCost).sizes("--sizes", sizes);
  if (const std::optional<int> exitCode = cl.parse(argc, argv)) return *exitCode;
  Options o;
  o.timing = cl.timing;
  if (cl.quick) o.sizes = {10'000, 100'000};
  if (sizes) o.sizes = *sizes;

  if (checkCost) {
    runCheckCosts(sizes ? *sizes : std::vector<std::size_t>{10'000, 1'000'000}, o.timing);
    return 0;
  }
  const int allThreads = tbb::info::default_concurrency();
  std::printf("tick_bench: one tick of gravity + wind + drag, semi-implicit Euler, %lld Hz\n",
              static_cast<long long>(kStepRateHz));
  bench::printMachine(" (TBB uses " + std::to_string(allThreads) + ")");
  bench::printBuild();

  std::vector<Row> rows;
  double checksum = 0.0;
  bool ok = true;
  for (std::size_t n : o.sizes) ok = runSize(n, o, allThreads, rows, checksum) && ok;

  std::printf("\nchecksum of final positions (keeps every case's work observable): %.9g\n",
              checksum);
  if (!ok) std::printf("CHECK FAILED: tickfx and the AoS loop disagree beyond round-off\n");
  std::printf("\n%10s  %-30s %18s %14s\n", "N", "case", "particle-steps/s", "ratio vs AoS");
  for (const Row& r : rows) {
    std::printf("%10zu  %-30s %18.4g %14.2f\n", r.n, r.name.c_str(), r.stepsPerSecond, r.ratio);
  }
  printFigures(rows, o.sizes, allThreads);
  return ok ? 0 : 1;
}
