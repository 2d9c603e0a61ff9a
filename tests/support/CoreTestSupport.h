// Helpers shared by the core tests: single-particle runs, a reference effect, frame sequences.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fields/AnchorSpring.h"
#include "fields/ForceSet.h"
#include "fields/Gravity.h"
#include "fields/LinearDrag.h"
#include "fields/PeriodicWind.h"
#include "fields/SpringNetwork.h"
#include "integrators/Integrator.h"
#include "particles/Clock.h"
#include "particles/ParticlePool.h"
#include "particles/ParticleSystem.h"
#include "particles/Random.h"

namespace tickfx::test {

/// Unit round-off of float (half the distance from 1 to the next float).
inline constexpr double kFloatU = 0x1p-24;

/// The step the integrators really take: 1/rate rounded to float once.
inline double floatDt(std::int64_t rate) { return StepTime{0, rate}.dt(); }

inline std::uint32_t bitsOf(float f) {
  std::uint32_t b = 0;
  std::memcpy(&b, &f, sizeof b);
  return b;
}

/// Whether two particles' starting values (position, velocity, lifetime, mass) have the same bits.
inline bool sameBits(const ParticleInit& a, const ParticleInit& b) {
  for (int c = 0; c < 3; ++c) {
    if (bitsOf(a.position[c]) != bitsOf(b.position[c])) return false;
    if (bitsOf(a.velocity[c]) != bitsOf(b.velocity[c])) return false;
  }
  return bitsOf(a.lifetime) == bitsOf(b.lifetime) && bitsOf(a.mass) == bitsOf(b.mass);
}

/// The pool's ages at its clock (ParticlePool::ages), rows [0, size()).
inline FloatColumn agesOf(const ParticlePool& pool) {
  FloatColumn ages(static_cast<Eigen::Index>(pool.size()));
  pool.ages(0, pool.size(), ages.data());
  return ages;
}

inline float withBits(std::uint32_t b) {
  float f = 0.0f;
  std::memcpy(&f, &b, sizeof f);
  return f;
}

/// State of particle 0 after a tick, widened to double.
struct Sample {
  std::int64_t ticks = 0;  // ticks completed
  double p = 0.0;          // one component of position
  double v = 0.0;          // the same component of velocity
};

/// Drives `integrator` directly on a one-particle pool for `ticks` ticks at `rate` Hz, calling
/// `observe` after every tick with component `axis` of the state.
inline void runSingle(const std::string& integrator, const ForceSet& forces,
                      const ParticleInit& init, std::int64_t rate, std::int64_t ticks, int axis,
                      const std::function<void(const Sample&)>& observe) {
  ParticlePool pool(1);
  std::unique_ptr<Integrator> scheme = makeIntegrator(integrator);
  pool.spawn(init, 0);
  for (std::int64_t k = 0; k < ticks; ++k) {
    scheme->step(pool, forces, StepTime{k, rate});
    pool.markAllStepped();
    observe(Sample{k + 1, pool.position()[axis][0], pool.velocity()[axis][0]});
  }
}

inline ForceSet gravityOnly() {
  ForceSet f;
  f.add(std::make_unique<Gravity>(Eigen::Vector3f(0.0f, -9.81f, 0.0f)));
  return f;
}

/// k = 1 N/m, m = 1 kg, anchored at the origin: ω = 1 rad/s.
inline ForceSet unitOscillator() {
  ForceSet f;
  f.add(std::make_unique<AnchorSpring>(Eigen::Vector3f::Zero(), 1.0f));
  return f;
}

/// The reference effect of the driver and hash tests: a rate emitter with a burst, spread, speed
/// and lifetime jitter (particles die within the run), under gravity, drag and a gusting wind.
inline EmitterSettings referenceEmitter() {
  EmitterSettings e;
  e.name = "fountain";
  e.position = Eigen::Vector3d(0.0, 0.5, 0.0);
  e.shape = SphereShape{0.1, false};
  e.rate = 240.0;
  e.bursts = {Burst{0.5, 40}};
  e.direction = Eigen::Vector3d(0.0, 1.0, 0.2);
  e.speed = 6.0;
  e.speedJitter = 0.25;
  e.spreadDegrees = 20.0;
  e.lifetime = 1.2;
  e.lifetimeJitter = 0.5;
  return e;
}

/// A crowd that keeps the scheduling busy: 20 000 particles at once (several blocks of rows and
/// many tiles), 3001 a second after (new rows every tick, starting mid-tile), dying from 0.2 to
/// 0.6 s after birth (deaths every tick once the first expire).
inline EmitterSettings crowdEmitter() {
  EmitterSettings e;
  e.shape = SphereShape{0.5, false};
  e.bursts = {{0.0, 20000}};
  e.rate = 3001.0;
  e.speed = 3.0;
  e.spreadDegrees = 40.0;
  e.lifetime = 0.4;
  e.lifetimeJitter = 0.5;
  return e;
}

/// Gravity then a periodic wind of 4 m/s² at 3 Hz: the uniform modules of the scheduling tests.
inline ForceSet gravityAndWind() {
  ForceSet forces;
  forces.add(std::make_unique<Gravity>());
  PeriodicWind::Settings wind;
  wind.amplitude = 4.0f;
  wind.frequency = 3.0;
  forces.add(std::make_unique<PeriodicWind>(wind));
  return forces;
}

inline ForceSet referenceForces() {
  ForceSet f;
  f.add(std::make_unique<Gravity>(Eigen::Vector3f(0.0f, -9.81f, 0.0f)));
  f.add(std::make_unique<LinearDrag>(0.3f, Eigen::Vector3f(1.0f, 0.0f, 0.0f)));
  PeriodicWind::Settings wind;
  wind.direction = Eigen::Vector3f(1.0f, 0.0f, 1.0f);
  wind.base = 0.2f;
  wind.amplitude = 2.0f;
  wind.frequency = 0.7;
  wind.phase = 0.3;
  f.add(std::make_unique<PeriodicWind>(wind));
  return f;
}

inline SystemSettings referenceSettings(const std::string& integrator = "semi_implicit_euler") {
  SystemSettings s;
  s.stepRateHz = 60;
  s.integrator = integrator;
  s.seed = 1234;
  s.maxParticles = 100'000;
  s.maxTicksPerFrame = 16;
  s.threads = 1;
  return s;
}

inline std::unique_ptr<ParticleSystem> referenceSystem(const SystemSettings& settings) {
  return std::make_unique<ParticleSystem>(
      settings, std::vector<EmitterSettings>{referenceEmitter()}, referenceForces());
}

/// A seeded sequence of frame durations in [minFrame, maxFrame] flicks (counter-based, so the
/// same on every standard library).
class JitteredFrames {
 public:
  JitteredFrames(std::uint64_t seed, Flicks minFrame, Flicks maxFrame)
      : seed_(seed), min_(minFrame), span_(static_cast<std::uint64_t>(maxFrame - minFrame) + 1) {}
  Flicks next() {
    const std::uint64_t bits = randomBits(RandomKey{seed_, 7, serial_++, 0});
    return min_ + static_cast<Flicks>(bits % span_);
  }

 private:
  std::uint64_t seed_;
  Flicks min_;
  std::uint64_t span_;
  std::uint64_t serial_ = 0;
};

}  // namespace tickfx::test
