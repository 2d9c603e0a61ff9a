// The phases of a frame that run in parallel blocks (a burst's rows written by the threads that
// fill them, the state hash block by block, the copy a shown frame keeps of its velocities) give
// the bits of their serial forms on 1, 2, 3 and 8 threads; and the profile that `tickfx run
// --profile` prints partitions the recording thread's time.
#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <thread>
#include <vector>

#include "CoreTestSupport.h"
#include "particles/Clock.h"
#include "particles/ParallelFor.h"
#include "particles/ParticlePool.h"
#include "particles/ParticleSystem.h"
#include "particles/PhaseProfile.h"
#include "particles/StateHash.h"

namespace tickfx {
namespace {

constexpr int kThreadCounts[] = {1, 2, 3, 8};

// Runs f() in an arena of `threads` threads (TBB's loops inside it take at most that many), as
// many as asked even on fewer cores (TBB keeps to the core count unless told otherwise).
template <typename F>
auto inArena(int threads, F&& f) {
  const tbb::global_control workers(tbb::global_control::max_allowed_parallelism,
                                    static_cast<std::size_t>(threads));
  tbb::task_arena arena(threads);
  return arena.execute(std::forward<F>(f));
}

// The state hash's definition, written out serially: each column hashed in blocks of 65536 rows
// (the block's words dealt in turn to four chains, the block's hash the chain over the four), a
// column's hash the chain over the row count and its blocks' hashes, the state's the chain over
// the counters and the columns' hashes.
struct Chain {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  void add(std::uint64_t word) {
    h = (h ^ word) * 0x100000001b3ULL;
    h ^= h >> 29;
    h *= 0xbf58476d1ce4e5b9ULL;
    h ^= h >> 32;
  }
};

std::uint64_t referenceHash(const ParticlePool& pool) {
  constexpr std::size_t kBlock = 65536;
  const std::size_t n = pool.size();
  std::vector<std::vector<std::uint64_t>> columns(2);
  for (std::size_t i = 0; i < n; ++i) columns[0].push_back(pool.id()[i]);
  for (std::size_t i = 0; i < n; ++i) columns[1].push_back(pool.birthTick()[i]);
  const auto floats = [&](const float* v) {
    std::vector<std::uint64_t> words;
    for (std::size_t i = 0; i < n; ++i) {
      std::uint32_t bits = 0;
      std::memcpy(&bits, v + i, sizeof bits);
      words.push_back(bits);
    }
    columns.push_back(std::move(words));
  };
  for (const Vec3Column* v : {&pool.position(), &pool.velocity()})
    for (int k = 0; k < 3; ++k) floats((*v)[k].data());
  const std::vector<float> zeros(n, 0.0f);
  for (int k = 0; k < 6; ++k) floats(zeros.data());  // previous position, acceleration: not kept
  std::vector<float> ages(n), inverseMasses(n);
  pool.ages(0, n, ages.data());
  for (std::size_t i = 0; i < n; ++i)
    inverseMasses[i] = inverseMassOf(pool.mass()[static_cast<Eigen::Index>(i)]);
  floats(ages.data());
  floats(pool.lifetime().data());
  floats(pool.mass().data());
  floats(inverseMasses.data());
  Chain state;
  state.add(n);
  state.add(pool.nextId());
  state.add(pool.droppedSpawns());
  for (const std::vector<std::uint64_t>& words : columns) {
    Chain column;
    column.add(n);
    for (std::size_t b = 0; b < n; b += kBlock) {
      Chain lanes[4];
      for (std::size_t i = b; i < std::min(n, b + kBlock); ++i) lanes[(i - b) % 4].add(words[i]);
      Chain block;
      for (const Chain& lane : lanes) block.add(lane.h);
      column.add(block.h);
    }
    state.add(column.h);
  }
  return state.h;
}

// A burst of `count` particles at tick 0 and a stream after it, under gravity and wind.
std::unique_ptr<ParticleSystem> burstSystem(int threads, std::uint64_t count) {
  SystemSettings settings;
  settings.stepRateHz = 60;
  settings.seed = 5;
  settings.threads = threads;
  settings.maxParticles = 2 * count;
  EmitterSettings e = test::crowdEmitter();
  e.bursts = {{0.0, count}};
  e.lifetime = 0.5;
  e.lifetimeJitter = 0.5;
  return std::make_unique<ParticleSystem>(settings, std::vector{e}, test::gravityAndWind());
}

TEST(ParallelPhases, TheStateHashIsItsBlockDefinitionOnAnyThreadCount) {
  // 200 001 rows: three whole blocks and a short one.
  auto system = burstSystem(2, 200'000);
  system->stepTicks(3);
  ASSERT_GT(system->pool().size(), 3 * 65536u);
  const std::uint64_t expected = referenceHash(system->pool());
  for (const int threads : kThreadCounts) {
    EXPECT_EQ(inArena(threads, [&] { return stateHash(system->pool()); }), expected) << threads;
  }
  // A pool of one block, and an empty one, follow the same definition.
  auto small = burstSystem(1, 1000);
  small->stepTicks(2);
  EXPECT_EQ(stateHash(small->pool()), referenceHash(small->pool()));
  const ParticlePool empty(10);
  EXPECT_EQ(stateHash(empty), referenceHash(empty));
}

TEST(ParallelPhases, AFlippedBitInAnyBlockChangesTheHash) {
  ParticlePool pool(300'000);
  pool.appendRows(200'001, 0);
  for (std::size_t i = 0; i < pool.size(); ++i) {
    ParticleInit init;
    init.position = Eigen::Vector3f(0.5f * static_cast<float>(i), 1.0f, 2.0f);
    init.velocity = Eigen::Vector3f(1.0f, -static_cast<float>(i % 7), 0.25f);
    pool.setRow(i, init);
  }
  EXPECT_EQ(stateHash(pool), referenceHash(pool));
  const std::uint64_t before = stateHash(pool);
  for (const std::size_t row : {std::size_t{0}, std::size_t{65535}, std::size_t{65536},
                                std::size_t{131072}, pool.size() - 1}) {
    float& v = pool.velocity().y[static_cast<Eigen::Index>(row)];
    const float kept = v;
    v = std::nextafter(v, 1e9f);
    EXPECT_NE(stateHash(pool), before) << row;
    v = kept;
    EXPECT_EQ(stateHash(pool), before) << row;
  }
}

TEST(ParallelPhases, ABurstsRowsAndItsFramesAreTheSameOnAnyThreadCount) {
  // 100 000 rows born at tick 0 (13 blocks written in parallel), shown between ticks (the copy of
  // the velocities), then deaths.
  std::vector<std::uint64_t> hashes;
  std::vector<std::uint64_t> shownVelocities;
  const tbb::global_control workers(tbb::global_control::max_allowed_parallelism, 8);
  for (const int threads : kThreadCounts) {
    auto system = burstSystem(threads, 100'000);
    system->advance(kFlicksPerSecond / 24);  // 2.5 ticks: a frame between two ticks
    const ParticlePool& pool = system->pool();
    ASSERT_EQ(pool.size(), pool.nextId());
    ASSERT_GT(pool.size(), 100'000u);
    for (std::size_t i = 0; i < pool.size(); ++i) {
      ASSERT_EQ(pool.id()[i], i);
      ASSERT_EQ(pool.birthTick()[i], i < 100'000 ? 0u : pool.birthTick()[i]);
      if (i > 0) {
        ASSERT_LE(pool.birthTick()[i - 1], pool.birthTick()[i]);
      }
    }
    Vec3Column velocities;
    system->renderVelocities(velocities);
    Chain shown;
    for (int k = 0; k < 3; ++k) {
      for (std::size_t i = 0; i < pool.size(); ++i) {
        std::uint32_t bits = 0;
        std::memcpy(&bits, &velocities[k][static_cast<Eigen::Index>(i)], sizeof bits);
        shown.add(bits);
      }
    }
    shownVelocities.push_back(shown.h);
    system->advance(kFlicksPerSecond);  // past the shortest lives
    hashes.push_back(stateHash(*system));
  }
  for (std::size_t t = 1; t < hashes.size(); ++t) {
    EXPECT_EQ(hashes[t], hashes[0]) << kThreadCounts[t] << " threads";
    EXPECT_EQ(shownVelocities[t], shownVelocities[0]) << kThreadCounts[t] << " threads";
  }
}

// ---- the profile -------------------------------------------------------------------------------

void sleepFor(double seconds) {
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
}

TEST(PhaseProfile, NestedPhasesTakeTheirOwnTimeAndTheWholeIsPartitioned) {
  using profile::Phase;
  profile::start();
  {
    const profile::PhaseScope emission(Phase::Emission);
    sleepFor(0.02);
    {
      const profile::PhaseScope step(Phase::Step);
      sleepFor(0.03);
    }
    sleepFor(0.01);
  }
  {
    const profile::PhaseScope hash(Phase::Hash);
    // A loop on other threads: its time is the phase's, and parallel; a scope opened inside a
    // parallel loop, on any thread, changes nothing.
    parallelForTasks(2, [](std::size_t) {
      const profile::PhaseScope inside(Phase::Release);
      sleepFor(0.02);
    });
  }
  // Another thread's scopes are not recorded.
  std::thread([] {
    const profile::PhaseScope other(Phase::Checkpoint);
    sleepFor(0.01);
  }).join();
  const profile::Report r = profile::stop();
  EXPECT_GE(r[Phase::Emission].wallSeconds, 0.03);
  EXPECT_GE(r[Phase::Step].wallSeconds, 0.03);
  EXPECT_EQ(r[Phase::Emission].parallelSeconds, 0.0);
  EXPECT_GE(r[Phase::Hash].wallSeconds, 0.02);
  EXPECT_GT(r[Phase::Hash].parallelSeconds, 0.9 * r[Phase::Hash].wallSeconds - 1e-3);
  EXPECT_EQ(r[Phase::Release].wallSeconds, 0.0);
  EXPECT_EQ(r[Phase::Checkpoint].wallSeconds, 0.0);
  EXPECT_GE(r[Phase::Other].wallSeconds, 0.01);  // the wait for the other thread
  double sum = 0.0;
  for (const profile::PhaseTime& p : r.phases) sum += p.wallSeconds;
  EXPECT_NEAR(sum, r.wallSeconds, 1e-9 * r.wallSeconds);
  EXPECT_GE(r.wallSeconds, 0.09);  // 30 + 30 + 20 + 10 ms of sleeps at least
  // Nothing records after stop().
  EXPECT_EQ(profile::stop().wallSeconds, 0.0);
}

TEST(PhaseProfile, TheReportNamesEveryPhaseThatTookTimeAndAmdahlsBound) {
  profile::Report r;
  r.wallSeconds = 10.0;
  r.phases[static_cast<std::size_t>(profile::Phase::Step)] = {6.0, 6.0};
  r.phases[static_cast<std::size_t>(profile::Phase::Emission)] = {4.0, 2.0};
  EXPECT_DOUBLE_EQ(r.serialShare(), 0.2);
  const std::string text = r.format(2);
  EXPECT_NE(text.find("profile: 10.000 s wall on 2 threads\n"), std::string::npos) << text;
  EXPECT_NE(text.find("  emission        4.000   40.0 %     2.000   50.0 %\n"), std::string::npos)
      << text;
  EXPECT_NE(text.find("  step            6.000   60.0 %     0.000    0.0 %\n"), std::string::npos)
      << text;
  EXPECT_EQ(text.find("  load "), std::string::npos) << text;
  // Serial 2 s, parallel 8 s on 2 threads = 16 s of work: 18 s on one thread; 16 threads take
  // 2 + 1 = 3 s at best.
  EXPECT_NE(text.find("2: 1.8x, 4: 3.0x, 8: 4.5x, 16: 6.0x"), std::string::npos) << text;
}

}  // namespace
}  // namespace tickfx
