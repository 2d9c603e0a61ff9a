// The particle pool: the hard cap, stable deaths, exact ages, custom attributes.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "CoreTestSupport.h"
#include "particles/StateHash.h"

namespace tickfx {
namespace {

constexpr float kForever = std::numeric_limits<float>::infinity();

ParticleInit tagged(float x, float lifetime = kForever) {
  ParticleInit init;
  init.position = Eigen::Vector3f(x, 2.0f * x, -x);
  init.velocity = Eigen::Vector3f(0.5f * x, 1.0f, 0.0f);
  init.lifetime = lifetime;
  init.mass = 1.0f + x;
  return init;
}

TEST(ParticlePool, SpawnsPastTheCapAreDroppedAndCounted) {
  ParticlePool pool(3);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_EQ(pool.spawn(tagged(static_cast<float>(i), 0.5f), 0), i);
  EXPECT_EQ(pool.spawn(tagged(3.0f), 0), ParticlePool::npos);
  EXPECT_EQ(pool.spawn(tagged(4.0f), 1), ParticlePool::npos);
  EXPECT_EQ(pool.size(), 3u);
  EXPECT_EQ(pool.droppedSpawns(), 2u);
  EXPECT_EQ(pool.nextId(), 3u);  // a refused spawn takes no id
  EXPECT_LE(pool.storageRows(), 3u);
  // Room again once particles die; the count of refusals is kept.
  pool.advanceClock(30, 60);  // age 0.5 s = lifetime
  EXPECT_EQ(pool.removeDead(), 3u);
  EXPECT_EQ(pool.spawn(tagged(5.0f), 30), 0u);
  EXPECT_EQ(pool.id()[0], 3u);
  EXPECT_EQ(pool.droppedSpawns(), 2u);
}

TEST(ParticlePool, CapHoldsAcrossStorageGrowth) {
  ParticlePool pool(1500);  // storage grows 1024 → 1500, never past the cap
  pool.keepPrevious();
  std::size_t refused = 0;
  for (int i = 0; i < 2000; ++i) {
    if (pool.spawn(tagged(static_cast<float>(i)), i) == ParticlePool::npos) ++refused;
  }
  EXPECT_EQ(refused, 500u);
  EXPECT_EQ(pool.size(), 1500u);
  EXPECT_EQ(pool.droppedSpawns(), 500u);
  EXPECT_EQ(pool.storageRows(), 1500u);
  for (std::size_t i = 0; i < pool.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    ASSERT_EQ(pool.id()[i], i);
    ASSERT_EQ(pool.birthTick()[i], static_cast<std::uint32_t>(i));
    ASSERT_EQ(pool.position().x[r],
              static_cast<float>(i));  // rows written before growth survive it
    ASSERT_EQ(pool.previousPosition().y[r], 2.0f * static_cast<float>(i));
    ASSERT_EQ(inverseMassOf(pool.mass()[r]), 1.0f / (1.0f + static_cast<float>(i)));
  }
}

// Rows are 32-bit indices in the compaction and the spring tables: a capacity of 2^32 or more
// is held to 2^32 − 1, and one below is kept as asked (nothing is allocated until spawns).
TEST(ParticlePool, CapacityIsHeldBelowTwoToThe32) {
  constexpr std::size_t kRows32 = std::size_t{1} << 32;
  EXPECT_EQ(ParticlePool(kRows32 - 1).maxParticles(), kRows32 - 1);
  EXPECT_EQ(ParticlePool(kRows32).maxParticles(), kRows32 - 1);
  EXPECT_EQ(ParticlePool(kRows32 + 5).maxParticles(), kRows32 - 1);
}

TEST(ParticlePool, ZeroCapacityRefusesEverything) {
  ParticlePool pool(0);
  EXPECT_EQ(pool.spawn(tagged(1.0f), 0), ParticlePool::npos);
  EXPECT_EQ(pool.size(), 0u);
  EXPECT_EQ(pool.droppedSpawns(), 1u);
}

TEST(ParticlePool, SystemCountsTheSpawnsOfABurstPastTheCap) {
  SystemSettings settings = test::referenceSettings();
  settings.maxParticles = 100;
  EmitterSettings e;
  e.bursts = {Burst{0.0, 250}};
  ParticleSystem system(settings, {e}, ForceSet{});
  system.step();
  EXPECT_EQ(system.pool().size(), 100u);
  EXPECT_EQ(system.pool().droppedSpawns(), 150u);
  EXPECT_EQ(system.pool().nextId(), 100u);
}

TEST(ParticlePool, InfiniteMassIsPinned) {
  ParticlePool pool(2);
  ParticleInit init;
  init.mass = kForever;
  pool.spawn(init, 0);
  EXPECT_EQ(inverseMassOf(pool.mass()[0]), 0.0f);
  EXPECT_TRUE(pool.anyPinned());
}

// Deaths at the end of a tick remove rows by a stable compaction: the survivors keep id order and
// every column (and custom attribute) moves with its particle.
TEST(ParticlePool, DeathsKeepIdOrderAndMoveEveryColumn) {
  ParticlePool pool(64);
  pool.keepPrevious();
  const std::size_t tag = pool.addAttribute("tag", -1.0f);
  for (int i = 0; i < 20; ++i) {
    // Odd ids live 0.5 s (30 ticks at 60 Hz), even ids forever.
    pool.spawn(tagged(static_cast<float>(i), i % 2 == 1 ? 0.5f : kForever), 0);
    pool.attribute(tag)[i] = 10.0f * static_cast<float>(i);
  }
  pool.advanceClock(29, 60);
  EXPECT_EQ(pool.removeDead(), 0u);  // age 29/60 < 0.5
  pool.advanceClock(30, 60);
  EXPECT_EQ(pool.removeDead(), 10u);
  ASSERT_EQ(pool.size(), 10u);

  // A module kills ids 4 and 14 by flag; ids 20 and 21 are born meanwhile.
  pool.spawn(tagged(20.0f), 30);
  pool.spawn(tagged(21.0f), 30);
  pool.dead()[2] = 1;  // id 4
  pool.dead()[7] = 1;  // id 14
  pool.advanceClock(31, 60);
  EXPECT_EQ(pool.removeDead(), 2u);

  const std::vector<std::uint64_t> expected{0, 2, 6, 8, 10, 12, 16, 18, 20, 21};
  ASSERT_EQ(pool.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    const float x = static_cast<float>(expected[i]);
    EXPECT_EQ(pool.id()[i], expected[i]);
    EXPECT_EQ(pool.position().x[r], x);
    EXPECT_EQ(pool.position().y[r], 2.0f * x);
    EXPECT_EQ(pool.previousPosition().z[r], -x);
    EXPECT_EQ(pool.velocity().x[r], 0.5f * x);
    EXPECT_EQ(pool.mass()[r], 1.0f + x);
    EXPECT_EQ(pool.lifetime()[r], kForever);
    EXPECT_EQ(pool.birthTick()[i], expected[i] < 20 ? 0u : 30u);
    EXPECT_EQ(pool.attribute(tag)[r], expected[i] < 20 ? 10.0f * x : -1.0f);
    EXPECT_EQ(pool.dead()[i], 0);
  }
}

// removeDead() finds a flagged row wherever it sits: first, last, and on either side of every
// boundary of the eight-flags-at-a-time search.
TEST(ParticlePool, ADeadRowIsFoundWhereverItSits) {
  constexpr int kRows = 21;
  for (int d = 0; d < kRows; ++d) {
    ParticlePool pool(kRows);
    for (int i = 0; i < kRows; ++i) pool.spawn(tagged(static_cast<float>(i)), 0);
    pool.dead()[static_cast<std::size_t>(d)] = 1;
    ASSERT_EQ(pool.removeDead(), 1u) << "dead row " << d;
    ASSERT_EQ(pool.size(), static_cast<std::size_t>(kRows - 1));
    for (int i = 0; i < kRows - 1; ++i)
      ASSERT_EQ(pool.id()[static_cast<std::size_t>(i)],
                static_cast<std::uint64_t>(i < d ? i : i + 1));
  }
}

// What the pool's memory is made of: two vectors (position, velocity), two floats (lifetime,
// mass), the 64-bit id, the 32-bit birth tick, the dead flag, a float for each named attribute,
// and the previous position and the acceleration (vectors) once something keeps them. Ages and
// inverse masses are worked out where they are read.
TEST(ParticlePool, BytesPerRowCountEveryColumn) {
  ParticlePool pool(8);
  EXPECT_EQ(pool.bytesPerRow(), 2u * 12u + 2u * 4u + 8u + 4u + 1u);
  pool.addAttribute("temperature");
  pool.addAttribute("temperature");  // the same attribute: no new column
  pool.addAttribute("Cd_r");
  EXPECT_EQ(pool.bytesPerRow(), 45u + 2u * 4u);
  pool.keepPrevious();
  EXPECT_EQ(pool.bytesPerRow(), 57u + 2u * 4u);
  pool.keepAcceleration();
  EXPECT_EQ(pool.bytesPerRow(), 69u + 2u * 4u);
}

// The acceleration column exists once kept, zero for the rows already there and the rows spawned
// after; it grows and moves with the others. Before, the state hash counts it as zeros.
TEST(ParticlePool, AKeptAccelerationIsZeroForEveryRowAndMovesWithIt) {
  ParticlePool pool(5000);
  for (int i = 0; i < 3; ++i) pool.spawn(tagged(static_cast<float>(i)), 0);
  const std::uint64_t before = stateHash(pool);
  EXPECT_FALSE(pool.keepsAcceleration());
  EXPECT_EQ(pool.acceleration().x.size(), 0);
  pool.keepAcceleration();
  ASSERT_TRUE(pool.keepsAcceleration());
  EXPECT_EQ(stateHash(pool), before);                                           // zeros either way
  for (int i = 3; i < 4000; ++i) pool.spawn(tagged(static_cast<float>(i)), 0);  // grows
  ASSERT_GE(pool.acceleration().y.size(), 4000);
  for (Eigen::Index r = 0; r < 4000; ++r) {
    ASSERT_EQ(pool.acceleration().y[r], 0.0f) << r;
    pool.acceleration().y[r] = static_cast<float>(r);
  }
  pool.dead()[1] = 1;
  pool.removeDead();
  EXPECT_EQ(pool.acceleration().y[0], 0.0f);
  EXPECT_EQ(pool.acceleration().y[1], 2.0f);
  EXPECT_EQ(pool.acceleration().y[3998], 3999.0f);
}

// Removal moves runs of kept rows: one long run when the oldest die together (a rate emitter
// with a fixed lifetime), many short ones when deaths are scattered. Each pattern keeps the
// survivors in id order with every column, on 1 and 2 threads, and leaves no flag set.
TEST(ParticlePool, EveryPatternOfDeathsKeepsTheSurvivorsWithTheirColumns) {
  constexpr int kRows = 3000;
  const std::vector<std::pair<const char*, std::function<bool(int)>>> patterns{
      {"the oldest 1000", [](int i) { return i < 1000; }},
      {"the oldest 999 and every 13th after", [](int i) { return i < 999 || i % 13 == 0; }},
      {"the youngest 7", [](int i) { return i >= kRows - 7; }},
      {"every other", [](int i) { return i % 2 == 1; }},
      {"runs of 5 every 37", [](int i) { return i % 37 < 5; }},
      {"scattered", [](int i) { return (i * 7919) % 101 == 3; }},
      {"all", [](int) { return true; }},
  };
  for (const auto& [name, dies] : patterns) {
    for (int threads : {1, 2}) {
      ParticlePool pool(kRows);
      pool.keepPrevious();
      const std::size_t tag = pool.addAttribute("tag", -1.0f);
      std::vector<std::uint64_t> expected;
      for (int i = 0; i < kRows; ++i) {
        pool.spawn(tagged(static_cast<float>(i)), i / 100);
        pool.attribute(tag)[i] = 10.0f * static_cast<float>(i);
        if (dies(i)) {
          pool.dead()[static_cast<std::size_t>(i)] = 1;
        } else {
          expected.push_back(static_cast<std::uint64_t>(i));
        }
      }
      Vec3Column follower = pool.velocity();  // a caller's copy, as the system keeps one
      pool.applyRemovalTo(follower);
      tbb::task_arena arena(threads);
      const std::size_t removed = arena.execute([&] { return pool.removeDead(); });
      ASSERT_EQ(removed, kRows - expected.size()) << name;
      ASSERT_EQ(pool.size(), expected.size()) << name;
      for (std::size_t i = 0; i < expected.size(); ++i) {
        const auto r = static_cast<Eigen::Index>(i);
        const float x = static_cast<float>(expected[i]);
        ASSERT_EQ(pool.id()[i], expected[i]) << name << ", row " << i;
        ASSERT_EQ(pool.birthTick()[i], static_cast<std::uint32_t>(expected[i] / 100)) << name;
        ASSERT_EQ(pool.position().y[r], 2.0f * x) << name << ", row " << i;
        ASSERT_EQ(pool.previousPosition().z[r], -x) << name << ", row " << i;
        ASSERT_EQ(pool.velocity().x[r], 0.5f * x) << name << ", row " << i;
        ASSERT_EQ(follower.x[r], 0.5f * x) << name << ", row " << i;
        ASSERT_EQ(pool.mass()[r], 1.0f + x) << name << ", row " << i;
        ASSERT_EQ(inverseMassOf(pool.mass()[r]), 1.0f / (1.0f + x)) << name << ", row " << i;
        ASSERT_EQ(pool.attribute(tag)[r], 10.0f * x) << name << ", row " << i;
      }
      for (std::size_t i = 0; i < pool.storageRows(); ++i) ASSERT_EQ(pool.dead()[i], 0) << name;
    }
  }
}

// advanceClock() tests only the rows old enough to reach the smallest lifetime (births never fall
// from row to row, so those are a prefix), and removeDead() reads the flags only where they may
// be. Against the rule itself, tick by tick: a row goes when its age reaches its lifetime, and
// at no other time, through jittered lifetimes, a lifetime lowered from outside, births written
// out of order (as a restore may) and a flag raised by a module past the rows that expire.
TEST(ParticlePool, ExpiryTestsOnlyTheRowsThatMayExpireAndMissesNone) {
  constexpr std::int64_t kRate = 60;
  ParticlePool pool(100'000);
  std::vector<std::uint64_t> alive;    // ids, in order
  std::vector<float> lifeOf, birthOf;  // by id
  const auto lifeFor = [](std::uint64_t id) {
    return 0.05f + 0.01f * static_cast<float>((id * 2654435761U) % 97);  // 0.05 to 1.01 s
  };
  for (std::int64_t tick = 0; tick < 240; ++tick) {
    for (int k = 0; k < 37; ++k) {
      const std::uint64_t id = pool.nextId();
      pool.spawn(tagged(static_cast<float>(id), lifeFor(id)), tick);
      alive.push_back(id);
      lifeOf.push_back(lifeFor(id));
      birthOf.push_back(static_cast<float>(tick));
    }
    if (tick == 100) {
      // The newest row may now die young: the floor must go.
      pool.lifetime()[static_cast<Eigen::Index>(pool.size() - 1)] = 0.001f;
      lifeOf[alive.back()] = 0.001f;
    }
    if (tick == 150) {
      // A module kills the newest row (past every row old enough to expire).
      pool.dead()[pool.size() - 1] = 1;
    }
    pool.advanceClock(tick + 1, kRate);
    std::vector<std::uint64_t> kept;
    for (std::uint64_t id : alive) {
      const auto lived =
          static_cast<std::int64_t>(tick + 1 - static_cast<std::int64_t>(birthOf[id]));
      const bool expires = ParticlePool::ageSeconds(lived, 1.0 / kRate) >= lifeOf[id];
      const bool killed = tick == 150 && id == alive.back();
      if (!expires && !killed) kept.push_back(id);
    }
    pool.removeDead();
    alive = kept;
    ASSERT_EQ(pool.size(), alive.size()) << "tick " << tick;
    for (std::size_t i = 0; i < alive.size(); ++i)
      ASSERT_EQ(pool.id()[i], alive[i]) << "tick " << tick << ", row " << i;
  }
  // Births written out of order (by hand, as a saved state's may be): every row is tested.
  ParticlePool restored(8);
  for (int i = 0; i < 4; ++i) restored.spawn(tagged(1.0f, 0.5f), 0);
  restored.birthTick()[0] = 30;  // young, first
  restored.birthTick()[3] = 0;   // old, last
  restored.advanceClock(31, kRate);
  restored.removeDead();
  ASSERT_EQ(restored.size(), 1u);
  EXPECT_EQ(restored.id()[0], 0u);
}

// Deaths in place: the rows dead at the front are dropped by moving the columns' start, so the
// survivors stay where they were in memory, and the storage they free is reused, not grown.
TEST(ParticlePool, TheDeadAtTheFrontCostNoMove) {
  ParticlePool pool(10'000);
  pool.keepPrevious();
  const std::size_t tag = pool.addAttribute("tag");
  for (int i = 0; i < 2000; ++i) pool.spawn(tagged(static_cast<float>(i)), 0);
  for (std::size_t i = 0; i < 300; ++i) pool.dead()[i] = 1;
  const float* survivorX = &pool.position().x[300];
  const std::uint64_t* survivorId = &pool.id()[300];
  const float* survivorTag = &pool.attribute(tag)[300];
  EXPECT_EQ(pool.removeDead(), 300u);
  EXPECT_EQ(pool.position().x.data(), survivorX);
  EXPECT_EQ(pool.id().data(), survivorId);
  EXPECT_EQ(pool.attribute(tag).data(), survivorTag);
  EXPECT_EQ(pool.id()[0], 300u);
  EXPECT_EQ(pool.size(), 1700u);
  EXPECT_EQ(pool.storageRows() + 300, pool.allocatedRows());
}

// Storage of 2 MiB or more starts on a 2 MiB boundary (where Linux can back it with huge pages:
// first touching a large pool was 25 times faster so), less on a cache line; a column that grows
// into a large storage keeps its values.
TEST(ParticlePool, LargeStorageStartsOnAHugePage) {
  constexpr std::uintptr_t kHugePage = std::uintptr_t{2} << 20;
  FloatColumn small(1000);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(small.data()) % 64, 0u);
  for (Eigen::Index i = 0; i < small.size(); ++i) small[i] = static_cast<float>(i) * 0.5f;
  small.setRows(3'000'000, 1000);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(small.data()) % kHugePage, 0u);
  ASSERT_EQ(small.size(), 3'000'000);
  for (Eigen::Index i = 0; i < 1000; ++i) ASSERT_EQ(small[i], static_cast<float>(i) * 0.5f);
  ParticlePool pool(1'000'000);
  pool.reserve(1'000'000);
  for (int i = 0; i < 10; ++i) pool.spawn(tagged(static_cast<float>(i)), 0);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(pool.position().y.data()) % kHugePage, 0u);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(pool.id().data()) % kHugePage, 0u);
  EXPECT_EQ(pool.position().y[9], 18.0f);
}

// A steady emitter's life: each round spawns a batch at the back and kills the oldest batch (and
// a scattered few), for many times the storage. The rows are always the survivors in id order
// with their own values, and the storage stops growing: the freed front is reused.
TEST(ParticlePool, SteadyDeathsAtTheFrontReuseTheStorage) {
  constexpr std::size_t kBatch = 97, kAlive = 40 * kBatch;
  ParticlePool pool(10 * kAlive);
  pool.keepPrevious();
  const std::size_t tag = pool.addAttribute("tag", -1.0f);
  std::vector<std::uint64_t> expected;  // ids alive, in order
  std::size_t allocatedAfterFill = 0;
  for (int round = 0; round < 400; ++round) {
    for (std::size_t k = 0; k < kBatch; ++k) {
      const std::uint64_t id = pool.nextId();
      const std::size_t row = pool.spawn(tagged(static_cast<float>(id)), round);
      pool.attribute(tag)[static_cast<Eigen::Index>(row)] = 3.0f * static_cast<float>(id);
      expected.push_back(id);
    }
    if (pool.size() > kAlive) {
      std::vector<std::uint64_t> kept;
      for (std::size_t i = 0; i < pool.size(); ++i) {
        const std::uint64_t id = pool.id()[i];
        if (i < kBatch || id % 89 == static_cast<std::uint64_t>(round % 89)) {
          pool.dead()[i] = 1;
        } else {
          kept.push_back(id);
        }
      }
      pool.removeDead();
      expected = kept;
    }
    ASSERT_EQ(pool.size(), expected.size()) << "round " << round;
    for (std::size_t i = 0; i < expected.size(); ++i) {
      const auto r = static_cast<Eigen::Index>(i);
      const float x = static_cast<float>(expected[i]);
      ASSERT_EQ(pool.id()[i], expected[i]) << "round " << round << ", row " << i;
      ASSERT_EQ(pool.position().y[r], 2.0f * x) << "round " << round << ", row " << i;
      ASSERT_EQ(pool.previousPosition().z[r], -x) << "round " << round << ", row " << i;
      ASSERT_EQ(pool.mass()[r], 1.0f + x) << "round " << round << ", row " << i;
      ASSERT_EQ(pool.attribute(tag)[r], 3.0f * x) << "round " << round << ", row " << i;
    }
    if (round == 100) allocatedAfterFill = pool.allocatedRows();
  }
  EXPECT_GT(allocatedAfterFill, 0u);
  EXPECT_EQ(pool.allocatedRows(), allocatedAfterFill);
  EXPECT_LE(pool.allocatedRows(), 4 * kAlive);
}

// dead() is "nonzero marks a particle for removal" (ParticlePool.h): a module may write any
// nonzero byte, and flags other than 1 must not be skipped, nor cleared without a removal.
TEST(ParticlePool, AnyNonzeroDeadFlagRemovesTheParticle) {
  ParticlePool pool(16);
  for (int i = 0; i < 6; ++i) pool.spawn(tagged(static_cast<float>(i)), 0);
  pool.dead()[1] = 2;
  pool.dead()[3] = 1;
  pool.dead()[4] = 0xff;
  pool.advanceClock(1, 60);
  EXPECT_EQ(pool.removeDead(), 3u);
  const std::vector<std::uint64_t> expected{0, 2, 5};
  ASSERT_EQ(pool.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(pool.id()[i], expected[i]);
    EXPECT_EQ(pool.position().x[static_cast<Eigen::Index>(i)], static_cast<float>(expected[i]));
  }
}

// The last tick of a lifetime L is the one after which (tick − birth)/rate ≥ L: a particle with
// 0.5 s at 60 Hz is alive after 29 ticks and gone after 30.
TEST(ParticlePool, ALifetimeEndsOnItsTick) {
  SystemSettings settings = test::referenceSettings();
  EmitterSettings e;
  e.bursts = {Burst{0.0, 3}};
  e.lifetime = 0.5;
  ParticleSystem system(settings, {e}, ForceSet{});
  system.stepTicks(29);
  EXPECT_EQ(system.pool().size(), 3u);
  EXPECT_EQ(system.pool().age(0), static_cast<float>(29.0 / 60.0));
  system.step();
  EXPECT_EQ(system.pool().size(), 0u);
}

// age = (tick − birth)/rate, rounded to float once from the exact double quotient: never
// accumulated, so it does not drift, and the same bits whatever happened in between.
TEST(ParticlePool, AgesAreExactQuotientsOfTickCounts) {
  for (std::int64_t rate : {7, 24, 60, 90, 144, 1000, 1'000'000}) {
    ParticlePool pool(1000);
    for (std::int64_t b = 0; b < 1000; ++b) pool.spawn(ParticleInit{}, b);
    for (std::int64_t tick : {std::int64_t{1000}, std::int64_t{4321}, std::int64_t{100'003},
                              std::int64_t{7'654'321}, std::int64_t{1} << 40}) {
      pool.advanceClock(tick, rate);
      for (std::size_t i = 0; i < pool.size(); ++i) {
        const double lived = static_cast<double>(tick - pool.birthTick()[i]);
        const float exact = static_cast<float>(lived / static_cast<double>(rate));
        ASSERT_EQ(test::bitsOf(pool.age(i)), test::bitsOf(exact))
            << "lived " << lived << " ticks at " << rate << " Hz";
      }
    }
  }
}

TEST(ParticlePool, CustomAttributesStartAtTheirInitialValue) {
  ParticlePool pool(5000);
  for (int i = 0; i < 5; ++i) pool.spawn(tagged(static_cast<float>(i)), 0);
  const std::size_t temp = pool.addAttribute("temperature", 300.0f);
  EXPECT_EQ(pool.findAttribute("temperature"), temp);
  EXPECT_EQ(pool.findAttribute("colour"), ParticlePool::npos);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(pool.attribute(temp)[i], 300.0f);  // existing rows too
  pool.attribute(temp)[2] = 17.0f;
  // Adding it again returns the same column and resets nothing.
  EXPECT_EQ(pool.addAttribute("temperature", 5.0f), temp);
  EXPECT_EQ(pool.attribute(temp)[2], 17.0f);
  const std::size_t charge = pool.addAttribute("charge", -2.5f);
  EXPECT_NE(charge, temp);
  EXPECT_EQ(pool.attributeCount(), 2u);
  EXPECT_EQ(pool.attributeName(charge), "charge");
  // New particles, across a storage growth, get the initial values.
  for (int i = 5; i < 3000; ++i) pool.spawn(tagged(static_cast<float>(i)), 1);
  for (int i = 5; i < 3000; ++i) {
    ASSERT_EQ(pool.attribute(temp)[i], 300.0f) << "row " << i;
    ASSERT_EQ(pool.attribute(charge)[i], -2.5f) << "row " << i;
  }
  EXPECT_EQ(pool.attribute(temp)[2], 17.0f);
}

// The state hash covers custom attributes: changing one changes the hash.
TEST(ParticlePool, AttributesAreInTheStateHash) {
  ParticlePool pool(8);
  const std::size_t a = pool.addAttribute("a", 1.0f);
  pool.spawn(tagged(1.0f), 0);
  const std::uint64_t before = stateHash(pool);
  pool.attribute(a)[0] = 2.0f;
  EXPECT_NE(stateHash(pool), before);
  pool.attribute(a)[0] = 1.0f;
  EXPECT_EQ(stateHash(pool), before);
}

// The scans a tick may skip: for expired rows only while a row may have a finite lifetime, for
// pinned rows only while one may be pinned, for flagged rows only once something may have flagged
// one. A spawn raises what it brings, a scan that finds nothing lowers its flag, and so does the
// removal of the flagged rows.
TEST(ParticlePool, ScansRunOnlyWhenARowMayNeedThem) {
  ParticlePool pool(16);
  EXPECT_FALSE(pool.mayHaveFiniteLifetimes());
  EXPECT_FALSE(pool.mayHavePinned());
  EXPECT_FALSE(pool.mayHaveDead());
  for (int i = 0; i < 4; ++i) pool.spawn(tagged(static_cast<float>(i)), 0);  // immortal, mass 1+i
  EXPECT_FALSE(pool.mayHaveFiniteLifetimes());
  EXPECT_FALSE(pool.mayHavePinned());
  EXPECT_FALSE(pool.anyPinned());
  pool.advanceClock(100, 60);
  EXPECT_FALSE(pool.mayHaveDead()) << "nothing expired, nothing flagged";
  EXPECT_EQ(pool.removeDead(), 0u);

  pool.spawn(tagged(4.0f, 0.5f), 100);  // dies after 30 ticks
  EXPECT_TRUE(pool.mayHaveFiniteLifetimes());
  pool.advanceClock(129, 60);
  EXPECT_FALSE(pool.mayHaveDead());
  EXPECT_TRUE(pool.mayHaveFiniteLifetimes()) << "the finite lifetime is still in the pool";
  pool.advanceClock(130, 60);
  EXPECT_TRUE(pool.mayHaveDead());
  EXPECT_EQ(pool.removeDead(), 1u);
  EXPECT_FALSE(pool.mayHaveDead());
  pool.advanceClock(131, 60);
  EXPECT_FALSE(pool.mayHaveFiniteLifetimes()) << "the scan found only infinite lifetimes";

  ParticleInit pinned = tagged(5.0f);
  pinned.mass = kForever;
  pool.spawn(pinned, 131);
  EXPECT_TRUE(pool.mayHavePinned());
  EXPECT_TRUE(pool.anyPinned());
  pool.mass()[4] = 2.0f;  // a host's write
  EXPECT_FALSE(pool.anyPinned());
  EXPECT_FALSE(pool.mayHavePinned());

  // A mutable access counts as a write of what the flag looks for.
  pool.lifetime();
  EXPECT_TRUE(pool.mayHaveFiniteLifetimes());
  pool.mass();
  EXPECT_TRUE(pool.mayHavePinned());
  pool.dead()[2] = 1;
  EXPECT_TRUE(pool.mayHaveDead());
  EXPECT_EQ(pool.removeDead(), 1u);
}

// Birth ticks are 32 bits: a system runs up to tick 2^32 − 1 and refuses the next with a message,
// before running any tick of the call; a saved state past that is refused too.
TEST(ParticlePool, ARunEndsAtTheLastBirthTick) {
  SystemSettings settings = test::referenceSettings();
  EmitterSettings e;
  e.rate = 60.0;
  ParticleSystem system(settings, {e}, ForceSet{});
  system.restoreClock(ParticleSystem::kMaxTicks - 2, nullptr);
  system.stepTicks(2);
  EXPECT_EQ(system.tickCount(), ParticleSystem::kMaxTicks);
  ASSERT_EQ(system.pool().size(), 2u);
  EXPECT_EQ(system.pool().birthTick()[1], 0xffffffffu);
  EXPECT_EQ(system.pool().age(1), static_cast<float>(1.0 / 60.0));
  try {
    system.step();
    FAIL() << "ran past the last birth tick";
  } catch (const std::overflow_error& error) {
    EXPECT_STREQ(error.what(),
                 "tick 4294967296 is past the last tick a run can have, 4294967295 (birth ticks "
                 "are 32 bits)");
  }
  EXPECT_EQ(system.tickCount(), ParticleSystem::kMaxTicks);
  const std::vector<std::uint64_t> ids{0};
  const std::vector<std::uint32_t> births{0};
  EXPECT_EQ(ParticlePool::restoreProblem(ids, births, 1, ParticleSystem::kMaxTicks + 1),
            "tick 4294967297 is past the last a run can have (4294967296: birth ticks are 32 "
            "bits)");
  EXPECT_EQ(ParticlePool::restoreProblem(ids, births, 1, ParticleSystem::kMaxTicks), std::nullopt);
}

}  // namespace
}  // namespace tickfx
