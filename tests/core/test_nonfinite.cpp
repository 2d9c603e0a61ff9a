// Non-finite state: the check finds every non-finite component, and each policy does what it says
// at the tick the arithmetic predicts, whatever the threads and the pass layout.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "CoreTestSupport.h"
#include "fields/SpringNetwork.h"
#include "integrators/Integrator.h"
#include "integrators/NonfiniteExceptions.h"
#include "particles/NonfiniteState.h"
#include "particles/StateHash.h"

namespace tickfx {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Row r (r = 0 … 5) gets a non-finite value in component r of (position, velocity) only: the
// check must look at all six. Rows 6 and 7 are finite, one of them at the largest float.
TEST(NonfiniteCheck, FlagsExactlyTheRowsWithANonFiniteComponent) {
  ParticlePool pool(8);
  for (int r = 0; r < 8; ++r) pool.spawn(ParticleInit{}, 0);
  const float bad[6] = {kInf, -kInf, kNaN, -kNaN, kInf, kNaN};
  for (int r = 0; r < 6; ++r) {
    Vec3Column& column = r < 3 ? pool.position() : pool.velocity();
    column[r % 3][r] = bad[r];
  }
  // Finite values whose sum overflows: the quick test passes them on, the exact one clears them.
  pool.position().x[6] = std::numeric_limits<float>::max();
  pool.position().y[6] = std::numeric_limits<float>::max();
  pool.velocity().z[7] = -std::numeric_limits<float>::denorm_min();
  pool.dead()[7] = 1;  // an ordinary death keeps its flag
  NonfiniteCheck check;
  check.scan(pool, 6, 8);
  EXPECT_FALSE(check.found());
  // Two calls over disjoint rows, as two threads' tiles would.
  check.scan(pool, 0, 3);
  check.scan(pool, 3, 6);
  EXPECT_TRUE(check.found());
  for (int r = 0; r < 6; ++r) EXPECT_EQ(pool.dead()[r], NonfiniteCheck::kFlag) << "row " << r;
  EXPECT_EQ(pool.dead()[6], 0);
  EXPECT_EQ(pool.dead()[7], 1);
  check.clear();
  EXPECT_FALSE(check.found());
}

TEST(NonfinitePolicy, NamesRoundTripAndOthersAreRefused) {
  EXPECT_EQ(nonfinitePolicyNames(), (std::vector<std::string>{"stop", "kill", "keep"}));
  for (const std::string& name : nonfinitePolicyNames()) {
    EXPECT_EQ(nameOf(nonfinitePolicyNamed(name)), name);
  }
  try {
    nonfinitePolicyNamed("explode");
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "nonfinite policy \"explode\" is not one of stop, kill, keep");
  }
}

TEST(NonfiniteEvent, DescribesTheTickTimeCountAndIds) {
  NonfiniteEvent e{95, 30, 24, {0, 1, 2, 3, 4, 5, 6, 7}};
  EXPECT_EQ(e.describe(),
            "tick 95 (t = 3.16666667 s): 24 particles have a non-finite position or velocity (ids "
            "0, 1, 2, 3, 4, 5, 6, 7, ...)");
  e = NonfiniteEvent{3, 60, 1, {12}};
  EXPECT_EQ(e.describe(),
            "tick 3 (t = 0.05 s): 1 particle has a non-finite position or velocity (id 12)");
}

// Drag k = 600/s at 60 Hz under semi-implicit Euler: v ← v + (−k·v)·dt = −9·v each tick, an
// unstable step, so |v| = 9ⁿ·|v₀| after n ticks. The first value to overflow float (max 3.4e38)
// is the acceleration k·|v|, once |v| > 3.4e38 / 600 = 5.7e35: it is infinite in the tick after
// the first n with 9ⁿ·|v₀| > 5.7e35, and velocity and position with it. For |v₀| = 1 and 2 that
// n is 38 (9³⁷ = 2.0e35, 2·9³⁷ = 4.1e35 are below; 9³⁸ = 1.8e36 is above), so tick 39; for 1e-3
// it is 41 (1e-3·9⁴⁰ = 1.5e35, 1e-3·9⁴¹ = 1.3e36), so tick 42. The factor is rounded in float,
// within 1e-6 of −9 over 42 ticks: far from these margins (the narrowest is 1.4×).
// Which passes a scheme takes under the forces of a test scene: with nothing but uniform forces
// and a drag, the one pass (UniformAndDragRows.h, checked by exceptions); with a weak anchor
// spring too (local and arithmetic only), its force passes tile by tile, checked by exceptions;
// with a spring network (even empty: not local), its force passes each over all rows in turn,
// checked by sums in its last update loop.
enum class Passes { OnePass, Tiles, Split };

void addLayoutForces(ForceSet& forces, Passes passes) {
  if (passes == Passes::Tiles) {
    forces.add(std::make_unique<AnchorSpring>(Eigen::Vector3f::Zero(), 1e-3f));
  }
  if (passes == Passes::Split) forces.add(std::make_unique<SpringNetwork>());
}

struct Exploding {
  static constexpr std::int64_t kFirstTick = 39, kLastTick = 42;

  std::unique_ptr<ParticleSystem> system;

  Exploding(NonfinitePolicy policy, int threads, Passes passes,
            const std::string& integrator = "semi_implicit_euler") {
    SystemSettings s;
    s.stepRateHz = 60;
    s.integrator = integrator;
    s.threads = threads;
    s.nonfinite = policy;
    ForceSet forces;
    forces.add(std::make_unique<LinearDrag>(600.0f));
    addLayoutForces(forces, passes);
    system = std::make_unique<ParticleSystem>(s, std::vector<EmitterSettings>{}, std::move(forces));
    const Eigen::Vector3f velocities[] = {
        {0.0f, 0.0f, 2.0f}, {0.0f, 1e-3f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}};
    // Many quiet rows around them, so that the bad ones sit in different tiles and blocks.
    for (int r = 0; r < 3000; ++r) {
      ParticleInit p;
      p.position = Eigen::Vector3f(0.001f * static_cast<float>(r), 0.0f, 0.0f);
      if (r % 1000 == 0) p.velocity = velocities[r / 1000];
      system->editPool().spawn(p, 0);
    }
  }
};

bool finiteState(const ParticlePool& pool) {
  for (const Vec3Column* c : {&pool.position(), &pool.velocity()}) {
    for (int k = 0; k < 3; ++k) {
      if (!(*c)[k].head(static_cast<Eigen::Index>(pool.size())).allFinite()) return false;
    }
  }
  return true;
}

// The ids of the rows with a non-finite position or velocity component, in row order.
std::vector<std::uint64_t> nonfiniteIds(const ParticlePool& pool) {
  std::vector<std::uint64_t> ids;
  for (std::size_t r = 0; r < pool.size(); ++r) {
    bool finite = true;
    for (int c = 0; c < 3; ++c) {
      const auto i = static_cast<Eigen::Index>(r);
      finite =
          finite && std::isfinite(pool.position()[c][i]) && std::isfinite(pool.velocity()[c][i]);
    }
    if (!finite) ids.push_back(pool.id()[r]);
  }
  return ids;
}

class NonfiniteRun : public ::testing::TestWithParam<std::tuple<int, bool>> {
 protected:
  Exploding make(NonfinitePolicy policy) const {
    return Exploding(policy, std::get<0>(GetParam()),
                     std::get<1>(GetParam()) ? Passes::Split : Passes::OnePass);
  }
};

TEST_P(NonfiniteRun, StopHaltsAtTheTickTheArithmeticPredictsWithTheStateItMade) {
  Exploding stop = make(NonfinitePolicy::Stop), keep = make(NonfinitePolicy::Keep);
  for (std::int64_t tick = 1; tick < Exploding::kFirstTick; ++tick) {
    stop.system->step();
    keep.system->step();
    ASSERT_FALSE(stop.system->nonfiniteStop()) << "tick " << tick;
    ASSERT_TRUE(finiteState(keep.system->pool())) << "tick " << tick;
  }
  stop.system->step();
  keep.system->step();
  ASSERT_TRUE(stop.system->nonfiniteStop());
  const NonfiniteEvent& e = *stop.system->nonfiniteStop();
  EXPECT_EQ(e.tick, Exploding::kFirstTick);
  EXPECT_EQ(e.stepRateHz, 60);
  EXPECT_EQ(e.particles, 2u);
  EXPECT_EQ(e.firstIds, (std::vector<std::uint64_t>{0, 2000}));
  EXPECT_FALSE(finiteState(keep.system->pool()));
  // The check reads and flags, never changes a value: the stopped state is the kept one.
  EXPECT_EQ(stop.system->tickCount(), Exploding::kFirstTick);
  EXPECT_EQ(stateHash(stop.system->pool()), stateHash(keep.system->pool()));
  EXPECT_EQ(stop.system->pool().size(), 3000u) << "nobody removed";
  // And nothing more runs, by any door.
  stop.system->stepTicks(5);
  stop.system->advance(kFlicksPerSecond);
  EXPECT_EQ(stop.system->tickCount(), Exploding::kFirstTick);
  EXPECT_EQ(stateHash(stop.system->pool()), stateHash(keep.system->pool()));
}

TEST_P(NonfiniteRun, KillRemovesEachParticleAtItsOwnTickAndCountsIt) {
  Exploding kill = make(NonfinitePolicy::Kill);
  kill.system->stepTicks(Exploding::kFirstTick - 1);
  EXPECT_EQ(kill.system->pool().size(), 3000u);
  kill.system->step();
  EXPECT_EQ(kill.system->pool().size(), 2998u);
  EXPECT_EQ(kill.system->nonfiniteKilled(), 2u);
  kill.system->stepTicks(Exploding::kLastTick - Exploding::kFirstTick - 1);
  EXPECT_EQ(kill.system->nonfiniteKilled(), 2u);
  kill.system->step();
  EXPECT_EQ(kill.system->nonfiniteKilled(), 3u);
  EXPECT_EQ(kill.system->pool().size(), 2997u);
  EXPECT_FALSE(kill.system->nonfiniteStop());
  kill.system->stepTicks(100);
  EXPECT_TRUE(finiteState(kill.system->pool()));
  EXPECT_EQ(kill.system->pool().size(), 2997u) << "the quiet rows live on";
  EXPECT_EQ(kill.system->tickCount(), Exploding::kLastTick + 100);
}

// Each integrator checks inside its own update loops (integrators/CheckedRows.h): the one pass
// ("fused": the drag alone), the force passes tile by tile ("tiles", by exceptions) and over all
// rows ("split", by sums), so each is tested three ways (see Passes): in
// lockstep with an unchecked run of the same effect, the checked one must stop at the first tick
// whose state has a non-finite position or velocity, naming exactly those rows. Drag of 600/s at 60
// Hz is unstable under every scheme here. Under explicit Euler the velocity goes non-finite a tick
// before the position does (the position takes the old velocity): a check of positions alone would
// report a tick late.
class NonfiniteEveryScheme : public ::testing::TestWithParam<std::tuple<std::string, Passes>> {};

// Steps `stop` (checked) and `keep` (unchecked, the same effect) in lockstep: `stop` must stop at
// the first tick whose state has a non-finite position or velocity, naming exactly those rows,
// with the state `keep` made. Returns that tick (0 if none in `ticks`).
std::int64_t expectStopsWithTheUncheckedRun(ParticleSystem& stop, ParticleSystem& keep,
                                            std::int64_t ticks) {
  const ParticlePool& kept = keep.pool();
  for (std::int64_t tick = 1; tick <= ticks; ++tick) {
    stop.step();
    keep.step();
    if (finiteState(kept)) {
      EXPECT_FALSE(stop.nonfiniteStop()) << "tick " << tick;
      if (stop.nonfiniteStop()) return 0;
      continue;
    }
    EXPECT_TRUE(stop.nonfiniteStop()) << "tick " << tick;
    if (!stop.nonfiniteStop()) return 0;
    const NonfiniteEvent& e = *stop.nonfiniteStop();
    EXPECT_EQ(e.tick, tick);
    std::vector<std::uint64_t> ids = nonfiniteIds(kept);
    EXPECT_EQ(e.particles, ids.size());
    ids.resize(std::min(ids.size(), NonfiniteEvent::kIdsKept));
    EXPECT_EQ(e.firstIds, ids);
    EXPECT_EQ(stateHash(stop.pool()), stateHash(kept)) << "the check changed the state";
    return tick;
  }
  return 0;
}

TEST_P(NonfiniteEveryScheme, StopsAtTheFirstNonFiniteTickNamingTheRowsOfTheUncheckedRun) {
  const auto& [integrator, passes] = GetParam();
  Exploding stop(NonfinitePolicy::Stop, 1, passes, integrator);
  Exploding keep(NonfinitePolicy::Keep, 1, passes, integrator);
  EXPECT_NE(expectStopsWithTheUncheckedRun(*stop.system, *keep.system, 400), 0)
      << integrator << " stayed finite for 400 ticks: the scene no longer explodes";
}

// A position that overflows while every velocity stays finite: 3.3e38 m at 4e37 m/s in each
// layout (Passes), 6.7e35 m a tick at 60 Hz, past
// the largest float (3.40e38) in the 16th tick (RK4's v + 2·v2 + 2·v3 + v4 = 2.4e38 stays
// finite); position Verlet's 2·p overflows in the first.
// From the second tick on the rows start finite, so the check of the one pass and of the tiles
// is the overflow flag alone; the split passes sum the new position.
TEST_P(NonfiniteEveryScheme, APositionThatOverflowsWithAFiniteVelocityStopsItsTick) {
  const auto& [integrator, passes] = GetParam();
  const auto make = [&, passes = passes, integrator = integrator](NonfinitePolicy policy) {
    SystemSettings s;
    s.stepRateHz = 60;
    s.integrator = integrator;
    s.nonfinite = policy;
    ForceSet forces;
    addLayoutForces(forces, passes);
    auto system =
        std::make_unique<ParticleSystem>(s, std::vector<EmitterSettings>{}, std::move(forces));
    for (int r = 0; r < 3000; ++r) {
      ParticleInit p;
      if (r == 1500) {
        p.position.x() = 3.3e38f;
        p.velocity.x() = 4e37f;
      }
      system->editPool().spawn(p, 0);
    }
    return system;
  };
  auto stop = make(NonfinitePolicy::Stop), keep = make(NonfinitePolicy::Keep);
  const std::int64_t tick = expectStopsWithTheUncheckedRun(*stop, *keep, 30);
  EXPECT_EQ(tick, integrator == "position_verlet" ? 1 : 16);
}

std::string schemeLayoutName(
    const ::testing::TestParamInfo<std::tuple<std::string, Passes>>& info) {
  const char* names[] = {"_fused", "_tiles", "_split"};
  return std::get<0>(info.param) + names[static_cast<int>(std::get<1>(info.param))];
}

INSTANTIATE_TEST_SUITE_P(Schemes, NonfiniteEveryScheme,
                         ::testing::Combine(::testing::ValuesIn(integratorNames()),
                                            ::testing::Values(Passes::OnePass, Passes::Tiles,
                                                              Passes::Split)),
                         schemeLayoutName);

// Explicit Euler's velocity is non-finite a tick before its position: the check must see it.
TEST(NonfiniteExplicitEuler, AVelocityThatIsNotFiniteStopsTheRunBeforeThePositionFollows) {
  Exploding keep(NonfinitePolicy::Keep, 1, Passes::OnePass, "explicit_euler");
  const ParticlePool& kept = keep.system->pool();
  bool velocityFirst = false;
  for (int tick = 0; tick < 400 && finiteState(kept); ++tick) {
    keep.system->step();
    const auto n = static_cast<Eigen::Index>(kept.size());
    bool positions = true;
    for (int c = 0; c < 3; ++c) positions = positions && kept.position()[c].head(n).allFinite();
    velocityFirst = !finiteState(kept) && positions;
  }
  EXPECT_TRUE(velocityFirst) << "the scene no longer shows the case the check must cover";
}

// The one pass checks the rows it steps by the exceptions its arithmetic raises: invalid for a
// NaN made from numbers, overflow and division by zero for an infinity. A NaN or an infinity that
// is already there spreads without raising anything, which is why the inputs must be finite.
TEST(NonfiniteExceptions, RaisedExactlyWhenArithmeticOnFiniteValuesMakesANonFiniteOne) {
  takeNonfiniteExceptions();  // whatever the thread did before
  volatile float big = std::numeric_limits<float>::max(), zero = 0.0f, one = 1.0f;
  volatile float nan = kNaN, inf = kInf;
  volatile float out = big * 0.5f + one;
  EXPECT_FALSE(takeNonfiniteExceptions()) << "finite arithmetic";
  out = big * 2.0f;
  EXPECT_TRUE(takeNonfiniteExceptions()) << "overflow";
  EXPECT_FALSE(takeNonfiniteExceptions()) << "taking them clears them";
  out = zero / zero;
  EXPECT_TRUE(takeNonfiniteExceptions()) << "0/0";
  out = one / zero;
  EXPECT_TRUE(takeNonfiniteExceptions()) << "division by zero";
  out = inf - inf;
  EXPECT_TRUE(takeNonfiniteExceptions()) << "inf - inf";
  out = nan * 2.0f + inf;
  EXPECT_FALSE(takeNonfiniteExceptions()) << "a NaN or an infinity that is there spreads quietly";
  static_cast<void>(out);
}

// A host's switch: unchecked, the run goes on past its first non-finite tick (the NaNs and
// infinities there spread quietly, raising no exception); switched to stop, the next tick stops
// on the rows that are non-finite by then. Switched back to keep, a stopped system stays stopped.
TEST(NonfinitePolicySwitch, ACheckSwitchedOnAfterUncheckedTicksFindsWhatTheyMade) {
  Exploding run(NonfinitePolicy::Keep, 1, Passes::OnePass, "midpoint");
  Exploding stop(NonfinitePolicy::Stop, 1, Passes::OnePass, "midpoint");
  while (!stop.system->nonfiniteStop()) stop.system->step();
  const std::int64_t first = stop.system->nonfiniteStop()->tick;
  run.system->stepTicks(first + 2);
  ASSERT_FALSE(finiteState(run.system->pool()));
  run.system->setNonfinitePolicy(NonfinitePolicy::Stop);
  run.system->step();
  ASSERT_TRUE(run.system->nonfiniteStop());
  EXPECT_EQ(run.system->nonfiniteStop()->tick, first + 3);
  const std::vector<std::uint64_t> ids = nonfiniteIds(run.system->pool());
  EXPECT_EQ(run.system->nonfiniteStop()->particles, ids.size());
  EXPECT_EQ(run.system->nonfiniteStop()->firstIds, ids);
  EXPECT_GT(ids.size(), stop.system->nonfiniteStop()->particles) << "more rows by then";
  run.system->setNonfinitePolicy(NonfinitePolicy::Keep);
  run.system->step();
  EXPECT_EQ(run.system->tickCount(), first + 3);
}

// A quiet effect (a drag of 1/s alone: every scheme's one pass) of 3000 rows, `threads` threads.
std::unique_ptr<ParticleSystem> quietEffect(const std::string& integrator, int threads,
                                            std::unique_ptr<ForceModule> extra = nullptr) {
  SystemSettings s;
  s.stepRateHz = 60;
  s.integrator = integrator;
  s.threads = threads;
  ForceSet forces;
  if (extra) forces.add(std::move(extra));
  forces.add(std::make_unique<LinearDrag>(1.0f));
  auto system =
      std::make_unique<ParticleSystem>(s, std::vector<EmitterSettings>{}, std::move(forces));
  for (int r = 0; r < 3000; ++r) {
    ParticleInit p;
    p.position = Eigen::Vector3f(0.001f * static_cast<float>(r), 1.0f, 0.0f);
    p.velocity = Eigen::Vector3f(0.0f, 0.5f, 0.25f);
    system->editPool().spawn(p, 0);
  }
  return system;
}

class NonfiniteOnePass : public ::testing::TestWithParam<std::tuple<std::string, int>> {};

// Values a host writes between ticks did not come from a checked tick: the next tick checks every
// value it writes, so a NaN velocity and an infinite position, which would spread through the
// one pass without raising an exception, stop it at that tick with exactly those rows.
TEST_P(NonfiniteOnePass, ValuesWrittenBetweenTicksStopTheNextTick) {
  const auto& [integrator, threads] = GetParam();
  auto system = quietEffect(integrator, threads);
  system->stepTicks(5);
  system->step();
  ASSERT_FALSE(system->nonfiniteStop());
  ParticlePool& pool = system->editPool();
  pool.velocity().y[1200] = kNaN;
  pool.position().x[2500] = kInf;
  system->step();
  ASSERT_TRUE(system->nonfiniteStop());
  const NonfiniteEvent& e = *system->nonfiniteStop();
  EXPECT_EQ(e.tick, 7);
  EXPECT_EQ(e.particles, 2u);
  EXPECT_EQ(e.firstIds, (std::vector<std::uint64_t>{1200, 2500}));
}

// Steps `system` through the ticks before `tick` (it must not stop in them), then once more:
// the event of that tick, or nullptr when it did not stop.
const NonfiniteEvent* stopAtTick(ParticleSystem& system, std::int64_t tick) {
  for (std::int64_t t = 1; t < tick; ++t) system.step();
  EXPECT_FALSE(system.nonfiniteStop()) << "stopped before tick " << tick;
  system.step();
  return system.nonfiniteStop() ? &*system.nonfiniteStop() : nullptr;
}

// A uniform acceleration of (0, g, 0) that a host's own module gives, g NaN from the tick that
// ends at kBadTick on (the one that starts at kBadTick − 1).
class FailingUniformModule : public ForceModule {
 public:
  static constexpr std::int64_t kBadTick = 4;
  std::string_view typeName() const override { return "failing_uniform"; }
  bool uniformAcceleration(const ForceInput& in, Eigen::Vector3f& a) const override {
    a = Eigen::Vector3f(0.0f, in.at.tick + 1 >= kBadTick ? kNaN : -9.81f, 0.0f);
    return true;
  }
  void accumulate(const ForceInput& in, RowRange rows, Vec3Rows& acceleration) const override {
    Eigen::Vector3f a;
    uniformAcceleration(in, a);
    for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(rows.count()); ++i) {
      acceleration.y[i] += a.y();
    }
  }
};

// The forms of the one pass are constants of the tick: a NaN among them spreads into every row
// without an exception, so the one pass checks every value for that tick.
TEST_P(NonfiniteOnePass, ANonFiniteUniformAccelerationStopsTheTickThatUsesIt) {
  const auto& [integrator, threads] = GetParam();
  auto system = quietEffect(integrator, threads, std::make_unique<FailingUniformModule>());
  const NonfiniteEvent* e = stopAtTick(*system, FailingUniformModule::kBadTick);
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->tick, FailingUniformModule::kBadTick);
  EXPECT_EQ(e->particles, 3000u);
}

// A host's own local module that reads a table it was given, in which one value is NaN: nothing
// raises an exception when that NaN is added, so modules are not arithmetic only unless they say
// so (ForceModule::arithmeticOnly), and the force passes sum what they write.
class TableModule : public ForceModule {
 public:
  static constexpr std::int64_t kBadTick = 5;
  static constexpr std::uint64_t kBadId = 2100;
  std::string_view typeName() const override { return "table"; }
  void accumulate(const ForceInput& in, RowRange rows, Vec3Rows& acceleration) const override {
    for (std::size_t r = rows.begin; r < rows.end; ++r) {
      const bool bad = in.pool.id()[r] == kBadId && in.at.tick + 1 >= kBadTick;
      acceleration.z[static_cast<Eigen::Index>(r - rows.begin)] += bad ? kNaN : 0.5f;
    }
  }
};

TEST_P(NonfiniteOnePass, ANaNFromAModulesTableStopsTheTickThatReadsIt) {
  const auto& [integrator, threads] = GetParam();
  auto system = quietEffect(integrator, threads, std::make_unique<TableModule>());
  const NonfiniteEvent* e = stopAtTick(*system, TableModule::kBadTick);
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->tick, TableModule::kBadTick);
  EXPECT_EQ(e->firstIds, (std::vector<std::uint64_t>{TableModule::kBadId}));
}

std::string onePassName(const ::testing::TestParamInfo<std::tuple<std::string, int>>& info) {
  return std::get<0>(info.param) + "_" + std::to_string(std::get<1>(info.param)) + "threads";
}

INSTANTIATE_TEST_SUITE_P(Schemes, NonfiniteOnePass,
                         ::testing::Combine(::testing::ValuesIn(integratorNames()),
                                            ::testing::Values(1, 3)),
                         onePassName);

// Rows spawned for a tick were not made by a checked tick either: with the stepped rows known
// finite (the one pass then checks them by exceptions), a NaN in a spawned row is still found,
// and only that row is flagged.
TEST(NonfiniteOnePassSpawns, ANonFiniteSpawnedRowIsFlaggedAmongFiniteSteppedRows) {
  for (const std::string& name : integratorNames()) {
    ParticlePool pool(2000);
    for (int r = 0; r < 2000; ++r) {
      ParticleInit p;
      p.velocity = Eigen::Vector3f(1.0f, 0.0f, 0.0f);
      pool.spawn(p, 0);
      if (r == 1499) pool.markAllStepped();  // rows 1500.. are this tick's spawns
    }
    pool.velocity().z[1700] = kNaN;
    ForceSet forces;
    forces.add(std::make_unique<LinearDrag>(1.0f));
    NonfiniteCheck check;
    check.setSteppedRowsFinite(true);
    makeIntegrator(name)->step(pool, forces, StepTime{1, 60}, &check);
    ASSERT_TRUE(check.found()) << name;
    for (std::size_t r = 0; r < pool.size(); ++r) {
      EXPECT_EQ(pool.dead()[r], r == 1700 ? NonfiniteCheck::kFlag : 0) << name << " row " << r;
    }
  }
}

std::string layoutName(const ::testing::TestParamInfo<std::tuple<int, bool>>& info) {
  return std::to_string(std::get<0>(info.param)) + "threads_" +
         (std::get<1>(info.param) ? "split" : "fused");
}

INSTANTIATE_TEST_SUITE_P(Layouts, NonfiniteRun,
                         ::testing::Combine(::testing::Values(1, 3), ::testing::Bool()),
                         layoutName);

}  // namespace
}  // namespace tickfx
