// Shards (particles/Shard.h) in the core: the partition, the pool's strided ids, and systems split
// into shards whose rows, put together by id, are the whole system's rows bit for bit, for every
// integrator and thread count, with a structure and a particle bound no run exceeds.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "particles/Shard.h"
#include "particles/StateHash.h"
#include "tests/support/CoreTestSupport.h"

namespace tickfx {
namespace {

using namespace tickfx::test;

TEST(Shard, ParsesAndNamesWhatIsWrong) {
  const Shard s = Shard::parse("2/7");
  EXPECT_EQ(s.index, 2u);
  EXPECT_EQ(s.count, 7u);
  EXPECT_EQ(s.text(), "2/7");
  EXPECT_TRUE(Shard::parse("0/1").whole());
  const auto message = [](const std::string& text) {
    try {
      Shard::parse(text);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message("7/7"), "'7/7': index 7 is not below the count 7");
  EXPECT_EQ(message("0/0"), "'0/0': the count 0 is not from 1 to 65536");
  EXPECT_EQ(message("0/65537"), "'0/65537': the count 65537 is not from 1 to 65536");
  for (const char* bad : {"", "3", "/3", "1/", "-1/3", "1/3x", "1 /3", "a/b"})
    EXPECT_EQ(message(bad), "'" + std::string(bad) + "' is not I/N (shard I of N, from 0)");
}

// firstOwnedSerial() is the first serial at or after s that ownerOfSerial() gives the shard.
TEST(Shard, FirstOwnedSerialIsTheRoundRobinsNext) {
  for (std::uint32_t count : {1u, 2u, 3u, 7u}) {
    for (std::uint32_t index = 0; index < count; ++index) {
      const Shard shard{index, count};
      for (std::uint32_t emitter = 0; emitter < 9; ++emitter) {
        for (std::uint64_t serial = 0; serial < 30; ++serial) {
          std::uint64_t expected = serial;
          while (shard.ownerOfSerial(emitter, expected) != index) ++expected;
          EXPECT_EQ(shard.firstOwnedSerial(emitter, serial), expected);
        }
      }
    }
  }
}

TEST(Shard, StridedRowsTakeTheirIdsAndCountTheRest) {
  ParticlePool pool(100);
  pool.appendRows(2, 0);                                             // ids 0, 1
  const std::size_t first = pool.appendRowsStrided(3, 1, 1, 4, 12);  // ids 3, 7, 11 of 2..13
  EXPECT_EQ(first, 2u);
  EXPECT_EQ(std::vector<std::uint64_t>(pool.id().begin(), pool.id().begin() + 5),
            (std::vector<std::uint64_t>{0, 1, 3, 7, 11}));
  EXPECT_EQ(pool.nextId(), 14u);
  pool.skipIds(5);
  EXPECT_EQ(pool.nextId(), 19u);
  EXPECT_EQ(pool.appendRows(1, 2), 5u);
  EXPECT_EQ(pool.id().at(5), 19u);
}

// Every row of a system: its id and the bits of every column stateHash() covers.
std::map<std::uint64_t, std::vector<std::uint64_t>> rowsById(const ParticlePool& pool) {
  std::map<std::uint64_t, std::vector<std::uint64_t>> rows;
  for (std::size_t r = 0; r < pool.size(); ++r) rows[pool.id()[r]] = stateRowBits(pool, r);
  return rows;
}

std::unique_ptr<ParticleSystem> shardedSystem(const SystemSettings& settings, const Shard& shard) {
  // Two ropes, the second born later: structures 0 and 1, in shards 0 and 1 of two or more.
  StructureSettings rope, later;
  rope.stiffness = later.stiffness = 50.0;
  later.shape = RopeShape{Eigen::Vector3d(0.0, 1.0, 0.0), Eigen::Vector3d(1.0, 1.0, 0.0), 12};
  later.time = 0.1;
  auto system = std::make_unique<ParticleSystem>(
      settings, std::vector<EmitterSettings>{referenceEmitter(), crowdEmitter()}, referenceForces(),
      std::vector<StructureSettings>{rope, later});
  system->setShard(shard);
  return system;
}

TEST(Shard, ShardsPutTogetherAreTheWholeSystem) {
  for (const std::string integrator : {"semi_implicit_euler", "rk4", "velocity_verlet"}) {
    SCOPED_TRACE(integrator);
    SystemSettings settings = referenceSettings(integrator);
    settings.threads = 2;
    const auto whole = shardedSystem(settings, Shard{});
    // Up to 0.4 s: most of the crowd is alive.
    JitteredFrames frames(5, kFlicksPerSecond / 100, kFlicksPerSecond / 20);
    std::vector<Flicks> durations;
    for (int f = 0; f < 8; ++f) durations.push_back(frames.next());
    for (Flicks d : durations) whole->advance(d);
    const auto expected = rowsById(whole->pool());
    ASSERT_GT(expected.size(), 2 * 8192u);  // several blocks of rows
    for (std::uint32_t count : {2u, 3u, 7u}) {
      std::map<std::uint64_t, std::vector<std::uint64_t>> merged;
      std::size_t biggest = 0, smallest = SIZE_MAX;
      for (std::uint32_t index = 0; index < count; ++index) {
        settings.threads = static_cast<int>(1 + index % 3);  // thread counts do not matter
        const auto part = shardedSystem(settings, Shard{index, count});
        for (Flicks d : durations) part->advance(d);
        EXPECT_EQ(part->pool().nextId(), whole->pool().nextId());
        EXPECT_EQ(part->tickCount(), whole->tickCount());
        for (auto& [id, bits] : rowsById(part->pool())) {
          EXPECT_TRUE(merged.emplace(id, std::move(bits)).second) << "id " << id << " twice";
        }
        biggest = std::max(biggest, part->pool().size());
        smallest = std::min(smallest, part->pool().size());
      }
      EXPECT_TRUE(merged == expected) << count << " shards";
      // Balanced: round robin within each emitter (the ropes, whole, sit in shards 0 and 1).
      EXPECT_LT(biggest - smallest, expected.size() / count / 10) << count;
    }
  }
}

TEST(Shard, ParticleBoundIsNeverExceeded) {
  SystemSettings settings = referenceSettings();
  const auto system = shardedSystem(settings, Shard{});
  const std::int64_t ticks = 180;
  const std::uint64_t bound = system->particleBound(ticks);
  std::size_t peak = 0;
  while (system->tickCount() < ticks) {
    system->step();
    peak = std::max(peak, system->pool().size());
  }
  EXPECT_GE(bound, peak);
  // Not far above it either: the crowd's 20 000 live 0.2 to 0.6 s.
  EXPECT_LT(bound, peak + peak / 2);
}

TEST(Shard, SubEmittersCannotBeSharded) {
  EmitterSettings child = referenceEmitter();
  child.name = "child";
  child.rate = 0.0;
  child.bursts.clear();
  child.sub.parent = "fountain";
  child.sub.on = EmitterEvent::Death;
  ParticleSystem system(referenceSettings(), {referenceEmitter(), child}, referenceForces());
  EXPECT_THROW(system.setShard(Shard{0, 2}), std::invalid_argument);
  EXPECT_NO_THROW(system.setShard(Shard{0, 1}));
}

}  // namespace
}  // namespace tickfx
