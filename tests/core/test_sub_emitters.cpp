// Sub-emitters against what they promise: n children per event at the event's place and tick,
// in (parent id, ordinal, child index) order, the same bits on any thread count and frame
// schedule, the pool's cap honoured and counted, inherited attributes copied at the event.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "CoreTestSupport.h"
#include "fields/Collider.h"
#include "fields/ColliderSet.h"
#include "particles/EventEmission.h"
#include "particles/ParallelFor.h"
#include "particles/ParticleSystem.h"
#include "particles/StateHash.h"

namespace tickfx {
namespace {

constexpr std::int64_t kRate = 60;

// Three shells fired up at t = 0 that live 0.5 s (30 ticks exactly), in straight lines.
EmitterSettings shells(double lifetime = 0.5) {
  EmitterSettings e;
  e.name = "shells";
  e.bursts = {Burst{0.0, 3}};
  e.speed = 10.0;
  e.spreadDegrees = 30.0;
  e.lifetime = lifetime;
  return e;
}

EmitterSettings sparks(std::uint64_t count) {
  EmitterSettings e;
  e.name = "sparks";
  e.sub.parent = "shells";
  e.sub.on = EmitterEvent::Death;
  e.sub.countMin = e.sub.countMax = count;
  e.speed = 2.0;
  e.spreadDegrees = 180.0;
  e.lifetime = 10.0;
  return e;
}

std::unique_ptr<ParticleSystem> make(const std::vector<EmitterSettings>& emitters,
                                     ForceSet forces = {}, int threads = 1,
                                     std::size_t maxParticles = 1'000'000,
                                     std::vector<ColliderSettings> colliders = {}) {
  SystemSettings s;
  s.stepRateHz = kRate;
  s.seed = 42;
  s.threads = threads;
  s.maxParticles = maxParticles;
  ColliderSet set;
  for (const ColliderSettings& c : colliders) set.add(makeCollider(c));
  return std::make_unique<ParticleSystem>(s, emitters, std::move(forces),
                                          std::vector<StructureSettings>{}, std::move(set));
}

Eigen::Vector3f row3(const Vec3Column& c, std::size_t row) {
  const auto r = static_cast<Eigen::Index>(row);
  return {c.x[r], c.y[r], c.z[r]};
}

float columnValue(const ParticleSystem& s, const std::string& name, std::size_t row) {
  const std::size_t a = s.pool().findAttribute(name);
  EXPECT_NE(a, ParticlePool::npos) << name;
  return s.pool().attribute(a)[static_cast<Eigen::Index>(row)];
}

// Each shell bursts, in the tick its lifetime ends, into exactly 7 sparks born at its last position
// at the next tick (t = 0.5 s), appended in (parent id, child index) order.
TEST(SubEmitters, ShellsBurstIntoExactlyNSparksAtTheirLastPositionAndTime) {
  // The same shells immortal: their state after 30 ticks is the dying shells' last state.
  const auto reference = make({shells(1.0)});
  reference->stepTicks(30);
  ASSERT_EQ(reference->pool().size(), 3u);

  const auto system = make({shells(), sparks(7)});
  system->setKeepPreviousPositions(true);  // read below
  system->stepTicks(30);
  EXPECT_EQ(system->pool().size(), 0u);  // the shells died in tick 29, their sparks wait
  ASSERT_EQ(system->events()->pending().size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    const ParticleEvent& e = system->events()->pending()[k];
    EXPECT_EQ(e.parentId, k);
    EXPECT_EQ(e.kind, EmitterEvent::Death);
    EXPECT_EQ(e.position, row3(reference->pool().position(), k));
    EXPECT_EQ(e.velocity, row3(reference->pool().velocity(), k));
  }
  EXPECT_NE(stateHash(*system), stateHash(system->pool()));  // the pending events are state

  system->step();
  const ParticlePool& pool = system->pool();
  ASSERT_EQ(pool.size(), 21u);
  EXPECT_TRUE(system->events()->pending().empty());
  for (std::size_t i = 0; i < 21; ++i) {
    EXPECT_EQ(pool.id()[i], 3 + i);
    EXPECT_EQ(pool.birthTick()[i], 30u) << "born at t = 0.5 s, the first tick at the death";
    EXPECT_EQ(columnValue(*system, kEmitterColumn, i), 1.0f);
    // Stepped once from where it was born: the previous position is the shell's last.
    EXPECT_EQ(row3(pool.previousPosition(), i), row3(reference->pool().position(), i / 7))
        << "spark " << i;
  }
  // Each spark is its own draw: no two of a shell's sparks leave the same way.
  EXPECT_NE(row3(pool.velocity(), 0), row3(pool.velocity(), 1));
}

// A lifetime that ends on a tick dies in the tick ending there; one that ends inside a tick dies
// in that tick. Either way the children are born at the first tick at or after the death.
TEST(SubEmitters, DeathOnATickVersusInsideATick) {
  for (const auto& [lifetime, birth] : {std::pair{0.5, 30}, std::pair{0.51, 31}}) {
    const auto system = make({shells(lifetime), sparks(2)});
    std::int64_t bornAt = -1;
    for (int k = 0; k < 40 && bornAt < 0; ++k) {
      system->step();
      if (system->pool().size() > 0 && system->pool().birthTick()[0] != 0) {
        bornAt = system->pool().birthTick()[0];
      }
    }
    EXPECT_EQ(bornAt, birth) << "lifetime " << lifetime;
    EXPECT_EQ(system->pool().size(), 6u);
  }
}

// Children past max_particles are refused and counted like refused spawns; the ones kept are the
// first in order (whole families of the lower parent ids first).
TEST(SubEmitters, ChildrenPastThePoolCapAreRefusedAndCounted) {
  const auto reference = make({shells(1.0)});
  reference->stepTicks(30);
  const auto system = make({shells(), sparks(5)}, {}, 1, /*maxParticles=*/12);
  system->setKeepPreviousPositions(true);  // read below
  system->stepTicks(31);
  const ParticlePool& pool = system->pool();
  ASSERT_EQ(pool.size(), 12u);
  EXPECT_EQ(pool.droppedSpawns(), 3u);  // 15 children, 12 places
  for (std::size_t i = 0; i < 12; ++i) {
    EXPECT_EQ(row3(pool.previousPosition(), i), row3(reference->pool().position(), i / 5));
  }
}

// What children inherit is the parent's value at the event: a stored value, or an attribute over
// life evaluated at the parent's age then (a death: nage 1).
TEST(SubEmitters, ChildrenInheritTheParentsAttributesAtTheEvent) {
  EmitterSettings parent = shells();
  LifeAttributeSettings cd;
  cd.name = "Cd";
  cd.value = {0.2f, 0.4f, 0.6f};
  LifeAttributeSettings heat;
  heat.name = "heat";
  heat.kind = LifeAttributeSettings::Kind::Ramp;
  heat.keys = {RampKey{0.0f, {1000.0f}}, RampKey{1.0f, {600.0f}}};
  parent.attributes = {cd, heat};
  EmitterSettings child = sparks(2);
  child.sub.inherit = {"Cd", "heat"};
  const auto system = make({parent, child});
  system->stepTicks(31);
  ASSERT_EQ(system->pool().size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(columnValue(*system, "Cd_r", i), 0.2f);
    EXPECT_EQ(columnValue(*system, "Cd_g", i), 0.4f);
    EXPECT_EQ(columnValue(*system, "Cd_b", i), 0.6f);
    EXPECT_EQ(columnValue(*system, "heat", i), 600.0f);
  }
  // The children show what they stored; the shells (were any alive) their own constant.
  std::vector<float> shown(6);
  ASSERT_TRUE(system->copyColumn("heat", FloatDestination{shown.data(), sizeof(float), 6}));
  EXPECT_EQ(shown, std::vector<float>(6, 600.0f));
}

// Births: children born in the parent's tick, at its birth state; a child emitter may itself be
// a parent (two generations here).
TEST(SubEmitters, BirthChildrenAndGrandchildrenAreBornInTheParentsTick) {
  EmitterSettings trail = sparks(2);
  trail.name = "trail";
  trail.sub.on = EmitterEvent::Birth;
  EmitterSettings dust = sparks(3);
  dust.name = "dust";
  dust.sub.parent = "trail";
  dust.sub.on = EmitterEvent::Birth;
  const auto system = make({shells(), trail, dust});
  system->setKeepPreviousPositions(true);  // read below
  system->step();
  const ParticlePool& pool = system->pool();
  ASSERT_EQ(pool.size(), 3u + 6u + 18u);
  for (std::size_t i = 0; i < pool.size(); ++i) {
    EXPECT_EQ(pool.birthTick()[i], 0u);
    const float e = columnValue(*system, kEmitterColumn, i);
    EXPECT_EQ(e, i < 3 ? 0.0f : (i < 9 ? 1.0f : 2.0f)) << "row " << i;
  }
  // A trail child starts where its shell started: the emitter is a point at the origin.
  EXPECT_EQ(row3(pool.previousPosition(), 3), Eigen::Vector3f::Zero());
}

// A collision sub-emitter: children at each contact's point along its normal; first_only keeps a
// parent's first contact only.
TEST(SubEmitters, CollisionChildrenAtTheContactFirstOnlyOnce) {
  EmitterSettings drops;
  drops.name = "drops";
  drops.position = Eigen::Vector3d(0.0, 0.49, 0.0);
  drops.bursts = {Burst{0.0, 4}};
  drops.direction = Eigen::Vector3d(0.0, -1.0, 0.0);
  drops.speed = 3.0;
  EmitterSettings chips = sparks(2);
  chips.name = "chips";
  chips.sub.parent = "drops";
  chips.sub.on = EmitterEvent::Collision;
  chips.sub.alongNormal = true;
  chips.sub.firstOnly = true;
  chips.spreadDegrees = 0.0;
  ColliderSettings floor;
  floor.type = ColliderType::Plane;
  floor.response = ColliderResponse::Bounce;
  floor.restitution = 1.0;
  ColliderSettings ceiling = floor;
  ceiling.point = Eigen::Vector3d(0.0, 0.5, 0.0);
  ceiling.normal = Eigen::Vector3d(0.0, -1.0, 0.0);
  const auto system = make({drops, chips}, ForceSet{}, 1, 1'000'000, {floor, ceiling});
  // Down 0.49 m at 3 m/s: the floor at t = 0.1633 s, in tick 9, which covers (9/60, 10/60].
  system->stepTicks(10);
  ASSERT_EQ(system->events()->pending().size(), 4u);
  for (const ParticleEvent& e : system->events()->pending()) {
    EXPECT_EQ(e.kind, EmitterEvent::Collision);
    EXPECT_EQ(e.ordinal, 0u);
    EXPECT_NEAR(e.position.y(), 0.0f, 1e-6f);
    EXPECT_EQ(e.normal, Eigen::Vector3f(0.0f, 1.0f, 0.0f));
    EXPECT_EQ(e.velocity.y(), -3.0f);
  }
  system->step();
  const ParticlePool& pool = system->pool();
  ASSERT_EQ(pool.size(), 4u + 8u);
  for (std::size_t i = 4; i < pool.size(); ++i) {
    EXPECT_EQ(pool.velocity().y[static_cast<Eigen::Index>(i)], 2.0f) << "along the normal";
    EXPECT_EQ(pool.birthTick()[i], 10u);
  }
  EXPECT_EQ(columnValue(*system, kContactsColumn, 0), 1.0f);
  // Back up 0.5 m, the drops meet the ceiling at t = 0.33 s: first_only makes no more chips.
  system->stepTicks(15);
  EXPECT_EQ(columnValue(*system, kContactsColumn, 0), 2.0f);
  EXPECT_EQ(system->pool().size(), 12u);
}

// A bigger display (many shells, hundreds of sparks each, across many blocks) with a collision
// generation too: the same state hash on 1, 2 and 3 threads and whatever frames drove it.
std::vector<EmitterSettings> display() {
  EmitterSettings s = shells(0.7);
  s.bursts = {Burst{0.0, 40}, Burst{0.25, 40}};
  s.lifetimeJitter = 0.3;
  EmitterSettings k = sparks(0);
  k.sub.countMin = 300;
  k.sub.countMax = 500;
  k.sub.inheritVelocity = 0.5;
  k.lifetime = 2.0;
  EmitterSettings chips = sparks(1);
  chips.name = "chips";
  chips.sub.parent = "sparks";
  chips.sub.on = EmitterEvent::Collision;
  chips.sub.alongNormal = true;
  chips.lifetime = 0.3;
  return {s, k, chips};
}

std::vector<ColliderSettings> floorAt(double y) {
  ColliderSettings c;
  c.type = ColliderType::Plane;
  c.point = Eigen::Vector3d(0.0, y, 0.0);
  c.response = ColliderResponse::Bounce;
  c.restitution = 0.3;
  return {c};
}

TEST(SubEmitters, SameBitsOnOneTwoAndThreeThreadsAndUnderEveryFrameSchedule) {
  constexpr std::int64_t kTicks = 90;
  std::vector<std::uint64_t> hashes;
  for (int threads : {1, 2, 3}) {
    const auto system = make(display(), test::gravityOnly(), threads, 1'000'000, floorAt(2.0));
    system->stepTicks(kTicks);
    EXPECT_GT(system->pool().size(), 2 * kParallelBlockRows) << "the events span blocks";
    hashes.push_back(stateHash(*system));
  }
  // Frames of 24, 30000/1001 and 144 fps: hashed when the ticks pass kTicks.
  for (const Flicks frame :
       {kFlicksPerSecond / 24, kFlicksPerSecond * 1001 / 30000, kFlicksPerSecond / 144}) {
    const auto system = make(display(), test::gravityOnly(), 2, 1'000'000, floorAt(2.0));
    std::uint64_t hash = 0;
    system->setTickObserver([&](const ParticleSystem& s) {
      if (s.tickCount() == kTicks) hash = stateHash(s);
    });
    while (system->tickCount() < kTicks) system->advance(frame);
    hashes.push_back(hash);
  }
  for (std::size_t k = 1; k < hashes.size(); ++k) EXPECT_EQ(hashes[k], hashes[0]) << "run " << k;
}

TEST(SubEmitters, ParentsThatDoNotExistOrCycleAreRefused) {
  EmitterSettings orphan = sparks(1);
  orphan.sub.parent = "shels";
  EXPECT_THROW(make({shells(), orphan}), std::invalid_argument);
  EmitterSettings a = sparks(1), b = sparks(1);
  a.name = "a";
  a.sub.parent = "b";
  b.name = "b";
  b.sub.parent = "a";
  const SettingProblems problems = validateSubEmitters({shells(), a, b}, {});
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0].text(),
            "1.parent: \"a\" -> \"b\" -> \"a\" is a cycle of parents (expected a chain of parents "
            "ending at an emitter that has none)");
}

}  // namespace
}  // namespace tickfx
