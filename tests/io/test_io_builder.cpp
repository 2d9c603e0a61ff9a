// The builder: an effect file and the same system built by hand are bit-identical, and every key
// of the file reaches the simulation.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "fields/AnchorSpring.h"
#include "fields/Gravity.h"
#include "fields/LinearDrag.h"
#include "fields/PeriodicWind.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectParser.h"
#include "particles/StateHash.h"

namespace tickfx::io {
namespace {

EffectSettings load(const LoadResult& result) {
  EXPECT_TRUE(result.ok()) << (result.diagnostics.empty() ? "" : result.diagnostics[0].format());
  return result.ok() ? *result.effect : EffectSettings{};
}

std::uint64_t hashAfter(ParticleSystem& system, std::int64_t ticks) {
  system.stepTicks(ticks);
  return stateHash(system.pool());
}

TEST(ioBuilder, FountainSampleEqualsHandBuiltFountain) {
  const EffectSettings effect = load(loadEffectFile(TICKFX_SOURCE_DIR "/samples/fountain.toml"));

  // samples/fountain.toml written out by hand, as samples/fountain_demo.cpp does.
  SystemSettings settings;
  settings.stepRateHz = 120;
  settings.integrator = "semi_implicit_euler";
  settings.seed = 7;
  settings.maxParticles = 100000;
  EmitterSettings nozzle;
  nozzle.name = "nozzle";
  nozzle.shape = DiscShape{0.1, Eigen::Vector3d::UnitY()};
  nozzle.rate = 2000.0;
  nozzle.direction = Eigen::Vector3d::UnitY();
  nozzle.speed = 8.0;
  nozzle.speedJitter = 0.1;
  nozzle.spreadDegrees = 12.0;
  nozzle.lifetime = 2.5;
  nozzle.lifetimeJitter = 0.2;
  ForceSet forces;
  forces.add(std::make_unique<Gravity>(Eigen::Vector3f(0.0f, -9.81f, 0.0f)));
  forces.add(std::make_unique<LinearDrag>(0.2f));
  ColliderSettings ground;  // the plane y = 0, normal +y
  ground.restitution = 0.3;
  ground.friction = 0.4;
  ColliderSet colliders;
  colliders.add(makeCollider(ground));
  ParticleSystem byHand(settings, {nozzle}, std::move(forces), {}, std::move(colliders));

  const std::unique_ptr<ParticleSystem> built = buildSystem(effect);
  // 3 s: particles born, flying, and the first ones dead (lifetime 2.5 s ± 20 %).
  const std::uint64_t expected = hashAfter(byHand, 360);
  EXPECT_EQ(hashAfter(*built, 360), expected);
  EXPECT_GT(built->pool().size(), 1000u);
  EXPECT_EQ(built->pool().nextId(), 6000u);  // 2000 particles/s for 3 s, exactly
}

// Every key that changes the simulation, set away from its default.
const char* const kEveryKey = R"(format_version = 1
[simulation]
step_rate = 60
integrator = "velocity_verlet"
seed = 99
max_particles = 5000
max_ticks_per_frame = 3
overrun = "fall_behind"
threads = 2

[[emitters]]
name = "ring"
position = [0.5, 1.0, -0.25]
shape = "disc"
radius = 0.3
normal = [0.0, 0.0, 1.0]
rate = 900.0
start = 0.1
stop = 0.75
bursts = [{ time = 0.5, count = 300 }]
direction = [0.2, 1.0, 0.0]
speed = 3.0
speed_jitter = 0.2
spread = 25.0
lifetime = 0.6
lifetime_jitter = 0.3
mass = 0.5

[[emitters]]
name = "ball"
shape = "sphere"
radius = 0.4
surface = true
bursts = [{ time = 0.0, count = 200 }]
speed = 1.0
spread = 180.0

[[emitters]]
name = "crate"
shape = "box"
size = [1.0, 0.5, 2.0]
rate = 300.0
mass = 2.0

[[forces]]
type = "gravity"
acceleration = [0.0, -3.7, 0.0]

[[forces]]
type = "drag"
k = 0.4
air_velocity = [1.0, 0.0, -1.0]

[[forces]]
type = "wind"
direction = [0.0, 0.0, 1.0]
base = 0.5
amplitude = 2.5
frequency = 0.75
phase = 1.25

[[forces]]
type = "anchor_spring"
rest = [0.0, 1.0, 0.0]
stiffness = 8.0
damping = 0.3
)";

TEST(ioBuilder, EveryKeyEqualsHandBuilt) {
  const EffectSettings effect = load(parseEffect(kEveryKey, "every.toml"));

  SystemSettings settings;
  settings.stepRateHz = 60;
  settings.integrator = "velocity_verlet";
  settings.seed = 99;
  settings.maxParticles = 5000;
  settings.maxTicksPerFrame = 3;
  settings.overrunPolicy = OverrunPolicy::FallBehind;
  settings.threads = 2;
  EmitterSettings ring;
  ring.name = "ring";
  ring.position = Eigen::Vector3d(0.5, 1.0, -0.25);
  ring.shape = DiscShape{0.3, Eigen::Vector3d::UnitZ()};
  ring.rate = 900.0;
  ring.start = 0.1;
  ring.stop = 0.75;
  ring.bursts = {Burst{0.5, 300}};
  ring.direction = Eigen::Vector3d(0.2, 1.0, 0.0);
  ring.speed = 3.0;
  ring.speedJitter = 0.2;
  ring.spreadDegrees = 25.0;
  ring.lifetime = 0.6;
  ring.lifetimeJitter = 0.3;
  ring.mass = 0.5;
  EmitterSettings ball;
  ball.name = "ball";
  ball.shape = SphereShape{0.4, true};
  ball.bursts = {Burst{0.0, 200}};
  ball.speed = 1.0;
  ball.spreadDegrees = 180.0;
  EmitterSettings crate;
  crate.name = "crate";
  crate.shape = BoxShape{Eigen::Vector3d(1.0, 0.5, 2.0)};
  crate.rate = 300.0;
  crate.mass = 2.0;
  ForceSet forces;
  forces.add(std::make_unique<Gravity>(Eigen::Vector3f(0.0f, -3.7f, 0.0f)));
  forces.add(std::make_unique<LinearDrag>(0.4f, Eigen::Vector3f(1.0f, 0.0f, -1.0f)));
  PeriodicWind::Settings wind;
  wind.direction = Eigen::Vector3f::UnitZ();
  wind.base = 0.5f;
  wind.amplitude = 2.5f;
  wind.frequency = 0.75;
  wind.phase = 1.25;
  forces.add(std::make_unique<PeriodicWind>(wind));
  forces.add(std::make_unique<AnchorSpring>(Eigen::Vector3f(0.0f, 1.0f, 0.0f), 8.0f, 0.3f));
  ParticleSystem byHand(settings, {ring, ball, crate}, std::move(forces));

  const std::unique_ptr<ParticleSystem> built = buildSystem(effect);
  EXPECT_EQ(hashAfter(*built, 60), hashAfter(byHand, 60));
  // The keys that never touch the state: they shape the driver and the thread arena.
  EXPECT_EQ(built->driver().maxTicksPerAdvance(), 3);
  EXPECT_EQ(built->driver().policy(), OverrunPolicy::FallBehind);
  EXPECT_EQ(built->settings().threads, 2);
  EXPECT_EQ(buildSystem(effect, 1)->settings().threads, 1);  // the command line's --threads
}

TEST(ioBuilder, EveryKeyReachesTheSimulation) {
  // Changing any one key (through an override) changes the state after one second: no key is
  // read and then dropped on the way to the system.
  const std::unique_ptr<ParticleSystem> base =
      buildSystem(load(parseEffect(kEveryKey, "every.toml")));
  const std::uint64_t baseHash = hashAfter(*base, 60);
  const std::vector<std::string> changes = {"simulation.step_rate=50",
                                            "simulation.integrator=rk4",
                                            "simulation.seed=100",
                                            "simulation.max_particles=400",
                                            "emitters.0.position=[0.5, 1.0, 0.25]",
                                            "emitters.0.radius=0.35",
                                            "emitters.0.normal=[0, 1, 0]",
                                            "emitters.0.rate=1000",
                                            "emitters.0.start=0.2",
                                            "emitters.0.stop=0.7",
                                            "emitters.0.bursts.0.time=0.6",
                                            "emitters.0.bursts.0.count=301",
                                            "emitters.0.direction=[0.3, 1, 0]",
                                            "emitters.0.speed=3.1",
                                            "emitters.0.speed_jitter=0.25",
                                            "emitters.0.spread=26",
                                            "emitters.0.lifetime=0.55",
                                            "emitters.0.lifetime_jitter=0.35",
                                            "emitters.0.mass=0.6",
                                            "emitters.1.surface=false",
                                            "emitters.1.radius=0.5",
                                            "emitters.2.size=[1, 0.5, 2.5]",
                                            "forces.0.acceleration=[0, -3.8, 0]",
                                            "forces.1.k=0.45",
                                            "forces.1.air_velocity=[1, 0, -1.5]",
                                            "forces.2.direction=[0, 0.1, 1]",
                                            "forces.2.base=0.6",
                                            "forces.2.amplitude=2.6",
                                            "forces.2.frequency=0.8",
                                            "forces.2.phase=1.3",
                                            "forces.3.rest=[0, 1.1, 0]",
                                            "forces.3.stiffness=8.5",
                                            "forces.3.damping=0.35"};
  for (const std::string& change : changes) {
    const LoadResult changed = parseEffect(kEveryKey, "every.toml", {change});
    ASSERT_TRUE(changed.ok()) << change;
    EXPECT_NE(hashAfter(*buildSystem(*changed.effect), 60), baseHash) << change;
  }
}

TEST(ioBuilder, OscillatorFollowsMinusCosine) {
  // samples/oscillator.toml: x(t) = −cos t, to velocity Verlet's second order at 60 Hz.
  const std::unique_ptr<ParticleSystem> system =
      buildSystem(load(loadEffectFile(TICKFX_SOURCE_DIR "/samples/oscillator.toml")));
  for (int second = 1; second <= 6; ++second) {
    system->stepTicks(60);
    ASSERT_EQ(system->pool().size(), 1u);
    EXPECT_NEAR(system->pool().position().x[0], -std::cos(static_cast<double>(second)), 1e-3)
        << "t = " << second << " s";
  }
}

TEST(ioBuilder, ForcesInFileOrder) {
  const EffectSettings effect = load(parseEffect(kEveryKey, "every.toml"));
  const ForceSet forces = buildForces(effect.forces);
  ASSERT_EQ(forces.size(), 4u);
  EXPECT_EQ(forces.module(0).typeName(), "gravity");
  EXPECT_EQ(forces.module(1).typeName(), "drag");
  EXPECT_EQ(forces.module(2).typeName(), "wind");
  EXPECT_EQ(forces.module(3).typeName(), "anchor_spring");
  for (std::size_t i = 0; i < forces.size(); ++i) {
    EXPECT_EQ(forces.module(i).typeName(), forceTypeName(effect.forces[i]));
  }
}

}  // namespace
}  // namespace tickfx::io
