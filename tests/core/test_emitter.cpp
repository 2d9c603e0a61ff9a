// Emitters: shapes, directions, jitter, the purity of sample(), burst and rate timing, point lists.
#include <gtest/gtest.h>

#include <tbb/task_arena.h>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "CoreTestSupport.h"
#include "particles/DetMath.h"
#include "particles/Emitter.h"
#include "particles/ParallelFor.h"
#include "particles/ParticlePool.h"

namespace tickfx {
namespace {

constexpr int kSamples = 20000;
// Fractions of kSamples: 5 binomial standard deviations at p = 1/2 is 0.018; at p = 1/8, 0.012.
constexpr double kFractionTolerance = 0.018;

const Eigen::Vector3d kCentre(1.0, 2.0, 3.0);

std::vector<ParticleInit> samples(const EmitterSettings& s, std::uint64_t seed = 11) {
  const Emitter emitter(s, 0, 60);
  std::vector<ParticleInit> out;
  for (std::uint64_t serial = 0; serial < kSamples; ++serial)
    out.push_back(emitter.sample(seed, serial));
  return out;
}

Eigen::Vector3d offsetOf(const ParticleInit& p) { return p.position.cast<double>() - kCentre; }

// Positions are the double offset rounded to float once: each coordinate moves by at most
// u·|coordinate|, so a distance by at most √3·u·(largest |coordinate|).
double positionTolerance(double extent) {
  return std::sqrt(3.0) * test::kFloatU * (kCentre.maxCoeff() + extent);
}

double fraction(const std::vector<ParticleInit>& all,
                const std::function<bool(const ParticleInit&)>& f) {
  return static_cast<double>(std::count_if(all.begin(), all.end(), f)) /
         static_cast<double>(all.size());
}

TEST(EmitterShapes, PointPutsEveryParticleOnTheEmitter) {
  EmitterSettings s;
  s.position = kCentre;
  for (const ParticleInit& p : samples(s)) ASSERT_EQ(p.position, kCentre.cast<float>());
}

TEST(EmitterShapes, SphereVolumeIsFilledUniformly) {
  EmitterSettings s;
  s.position = kCentre;
  s.shape = SphereShape{0.5, false};
  const std::vector<ParticleInit> all = samples(s);
  for (const ParticleInit& p : all) ASSERT_LE(offsetOf(p).norm(), 0.5 + positionTolerance(0.5));
  // Uniform in the ball: P(r ≤ x·R) = x³.
  EXPECT_NEAR(fraction(all, [](const ParticleInit& p) { return offsetOf(p).norm() <= 0.25; }),
              0.125, kFractionTolerance);
  EXPECT_NEAR(fraction(all, [](const ParticleInit& p) { return offsetOf(p).norm() <= 0.4; }), 0.512,
              kFractionTolerance);
  EXPECT_NEAR(fraction(all, [](const ParticleInit& p) { return offsetOf(p).z() > 0.0; }), 0.5,
              kFractionTolerance);
}

TEST(EmitterShapes, SphereSurfaceIsAtTheRadius) {
  EmitterSettings s;
  s.position = kCentre;
  s.shape = SphereShape{0.5, true};
  const std::vector<ParticleInit> all = samples(s);
  for (const ParticleInit& p : all) ASSERT_NEAR(offsetOf(p).norm(), 0.5, positionTolerance(0.5));
  for (int axis = 0; axis < 3; ++axis) {
    // On a sphere each coordinate is uniform in [−R, R] (Archimedes): half lie within R/2.
    EXPECT_NEAR(
        fraction(all,
                 [axis](const ParticleInit& p) { return std::abs(offsetOf(p)[axis]) <= 0.25; }),
        0.5, kFractionTolerance)
        << "axis " << axis;
  }
}

TEST(EmitterShapes, BoxStaysWithinItsExtents) {
  EmitterSettings s;
  s.position = kCentre;
  const Eigen::Vector3d size(1.0, 2.0, 0.5);
  s.shape = BoxShape{size};
  const std::vector<ParticleInit> all = samples(s);
  Eigen::Vector3d largest = Eigen::Vector3d::Zero();
  for (const ParticleInit& p : all) {
    const Eigen::Vector3d o = offsetOf(p);
    for (int c = 0; c < 3; ++c) {
      ASSERT_LE(std::abs(o[c]), size[c] / 2.0 + positionTolerance(1.0)) << "axis " << c;
      largest[c] = std::max(largest[c], std::abs(o[c]));
    }
  }
  // The whole box is used, not a smaller one.
  for (int c = 0; c < 3; ++c) EXPECT_GT(largest[c], 0.499 * size[c]) << "axis " << c;
  EXPECT_NEAR(fraction(all, [](const ParticleInit& p) { return std::abs(offsetOf(p).y()) <= 0.5; }),
              0.5, kFractionTolerance);
}

TEST(EmitterShapes, DiscLiesInItsPlaneWithinItsRadius) {
  EmitterSettings s;
  s.position = kCentre;
  const Eigen::Vector3d normal = Eigen::Vector3d(1.0, 2.0, 2.0) / 3.0;
  s.shape = DiscShape{0.8, Eigen::Vector3d(1.0, 2.0, 2.0)};  // normalised by the emitter
  const std::vector<ParticleInit> all = samples(s);
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (const ParticleInit& p : all) {
    const Eigen::Vector3d o = offsetOf(p);
    ASSERT_NEAR(o.dot(normal), 0.0, positionTolerance(0.8));
    ASSERT_LE(o.norm(), 0.8 + positionTolerance(0.8));
    second += o * o.transpose();
  }
  second /= static_cast<double>(all.size());
  // Uniform on the disc: E[x²] = R²/4 along every in-plane axis, 0 along the normal.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(second);
  EXPECT_NEAR(eig.eigenvalues()[0], 0.0, 1e-12);
  EXPECT_NEAR(eig.eigenvalues()[1], 0.16, 0.16 * 0.05);
  EXPECT_NEAR(eig.eigenvalues()[2], 0.16, 0.16 * 0.05);
  EXPECT_NEAR(std::abs(eig.eigenvectors().col(0).dot(normal)), 1.0, 1e-9);
  EXPECT_NEAR(fraction(all, [](const ParticleInit& p) { return offsetOf(p).norm() <= 0.4; }), 0.25,
              kFractionTolerance);
}

double angleDegrees(const Eigen::Vector3f& v, const Eigen::Vector3d& axis) {
  const double c = std::clamp(v.cast<double>().normalized().dot(axis.normalized()), -1.0, 1.0);
  return std::acos(c) * 180.0 / det::kPi;
}

TEST(EmitterDirections, ConeSpreadStaysWithinTheHalfAngle) {
  EmitterSettings s;
  s.direction = Eigen::Vector3d(0.0, 1.0, 1.0);
  s.speed = 3.0;
  s.spreadDegrees = 25.0;
  const std::vector<ParticleInit> all = samples(s);
  double widest = 0.0;
  for (const ParticleInit& p : all) {
    const double angle = angleDegrees(p.velocity, s.direction);
    // Float velocity: direction rounding below 1e-6 rad; the acos near 25° loses nothing more.
    ASSERT_LE(angle, 25.0 + 1e-4);
    widest = std::max(widest, angle);
  }
  EXPECT_GT(widest, 24.5);
  // Uniform over the spherical cap: half its area lies where cos θ ≥ (1 + cos 25°)/2.
  const double cosHalf = (1.0 + std::cos(25.0 * det::kPi / 180.0)) / 2.0;
  EXPECT_NEAR(fraction(all,
                       [&](const ParticleInit& p) {
                         return p.velocity.cast<double>().normalized().dot(
                                    s.direction.normalized()) >= cosHalf;
                       }),
              0.5, kFractionTolerance);
  // And uniform in azimuth about the axis: every half-space whose plane holds the axis has half.
  for (const Eigen::Vector3d& w : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, -1),
                                   Eigen::Vector3d(1, 1, -1), Eigen::Vector3d(1, -1, 1)}) {
    ASSERT_NEAR(w.dot(s.direction), 0.0, 1e-15);
    EXPECT_NEAR(
        fraction(all,
                 [&](const ParticleInit& p) { return p.velocity.cast<double>().dot(w) > 0.0; }),
        0.5, kFractionTolerance)
        << w.transpose();
  }
}

TEST(EmitterDirections, NoSpreadIsTheDirectionAndFullSpreadIsTheSphere) {
  EmitterSettings s;
  s.direction = Eigen::Vector3d(2.0, -1.0, 0.5);
  s.speed = 4.0;
  const Eigen::Vector3f exact = (4.0 * s.direction.normalized()).cast<float>();
  for (const ParticleInit& p : samples(s)) ASSERT_EQ(p.velocity, exact);
  s.spreadDegrees = 180.0;
  EXPECT_NEAR(fraction(samples(s),
                       [&](const ParticleInit& p) {
                         return p.velocity.cast<double>().dot(s.direction) < 0.0;
                       }),
              0.5, kFractionTolerance);
}

TEST(EmitterJitter, SpeedLifetimeAndMassStayInTheirBounds) {
  EmitterSettings s;
  s.speed = 5.0;
  s.speedJitter = 0.2;
  s.spreadDegrees = 40.0;
  s.lifetime = 2.0;
  s.lifetimeJitter = 0.25;
  s.mass = 0.3;
  double minSpeed = 1e9, maxSpeed = 0.0, minLife = 1e9, maxLife = 0.0, sumSpeed = 0.0;
  for (const ParticleInit& p : samples(s)) {
    const double speed = p.velocity.cast<double>().norm();
    // Each float component is within u of its double value, so the norm is within u·|v|.
    ASSERT_GE(speed, 4.0 * (1.0 - 2.0 * test::kFloatU));
    ASSERT_LE(speed, 6.0 * (1.0 + 2.0 * test::kFloatU));
    ASSERT_GE(p.lifetime, 1.5f);
    ASSERT_LE(p.lifetime, 2.5f);
    ASSERT_EQ(p.mass, 0.3f);
    minSpeed = std::min(minSpeed, speed);
    maxSpeed = std::max(maxSpeed, speed);
    minLife = std::min(minLife, static_cast<double>(p.lifetime));
    maxLife = std::max(maxLife, static_cast<double>(p.lifetime));
    sumSpeed += speed;
  }
  // The whole jitter range is used, and centred.
  EXPECT_LT(minSpeed, 4.01);
  EXPECT_GT(maxSpeed, 5.99);
  EXPECT_LT(minLife, 1.51);
  EXPECT_GT(maxLife, 2.49);
  EXPECT_NEAR(sumSpeed / kSamples, 5.0, 0.02);  // σ of the mean: 1/√3 · 1/√20000 = 0.004
}

EmitterSettings randomEverything() {
  EmitterSettings s;
  s.position = kCentre;
  s.shape = SphereShape{0.5, false};
  s.direction = Eigen::Vector3d(0.3, 1.0, 0.0);
  s.speed = 5.0;
  s.speedJitter = 0.3;
  s.spreadDegrees = 30.0;
  s.lifetime = 2.0;
  s.lifetimeJitter = 0.5;
  return s;
}

// sample(seed, serial) depends on nothing else: not on call order, earlier calls, the instance or
// the step rate.
TEST(EmitterSample, IsAPureFunctionOfSeedAndSerial) {
  const Emitter a(randomEverything(), 0, 60);
  const Emitter b(randomEverything(), 0, 144);
  std::vector<ParticleInit> forward;
  for (std::uint64_t serial = 0; serial < 1000; ++serial) forward.push_back(a.sample(42, serial));
  for (std::uint64_t k = 0; k < 1000; ++k) {
    const std::uint64_t serial = (k * 617) % 1000;  // a permutation of 0..999
    ASSERT_TRUE(test::sameBits(b.sample(42, serial), forward[serial])) << "serial " << serial;
    ASSERT_TRUE(test::sameBits(a.sample(42, serial), forward[serial])) << "serial " << serial;
  }
  EXPECT_TRUE(test::sameBits(a.sample(42, 123'456'789'012ULL), b.sample(42, 123'456'789'012ULL)));
}

TEST(EmitterSample, DifferentSeedEmitterOrSerialGivesDifferentParticles) {
  const Emitter first(randomEverything(), 0, 60);
  const Emitter second(randomEverything(), 1, 60);  // the next emitter of the same effect
  for (std::uint64_t serial = 0; serial < 1000; ++serial) {
    const ParticleInit p = first.sample(42, serial);
    ASSERT_NE(p.position, first.sample(43, serial).position) << "serial " << serial;
    ASSERT_NE(p.velocity, first.sample(43, serial).velocity) << "serial " << serial;
    ASSERT_NE(p.lifetime, first.sample(43, serial).lifetime) << "serial " << serial;
    ASSERT_NE(p.position, second.sample(42, serial).position) << "serial " << serial;
    ASSERT_NE(p.position, first.sample(42, serial + 1).position) << "serial " << serial;
  }
}

ParticleInit initOf(const ParticlePool& pool, Eigen::Index r) {
  const auto at = [r](const Vec3Column& c) { return Eigen::Vector3f(c.x[r], c.y[r], c.z[r]); };
  return ParticleInit{at(pool.position()), at(pool.velocity()), pool.lifetime()[r], pool.mass()[r]};
}

// A burst's rows are reserved at once and filled in parallel blocks: on any thread count, the
// rows, ids, births and bits of one spawn() after another, and the spawns past a full pool are
// counted, not filled.
TEST(EmitterBulk, ABurstFillsTheRowsOfOneSpawnAtATimeOnAnyThreadCount) {
  constexpr std::uint64_t kBurst = 3 * kParallelBlockRows + 17;
  constexpr std::size_t kRoom = 2 * kParallelBlockRows + 5;  // 1 row taken below, then the burst
  EmitterSettings s = randomEverything();
  s.mass = 0.25;
  s.bursts = {Burst{0.0, kBurst}};
  const Emitter emitter(s, 2, 60);
  ParticlePool expected(kRoom + 1);
  const ParticleInit first = emitter.sample(7, 0);
  expected.spawn(first, 0);
  for (std::uint64_t serial = 0; serial < kBurst; ++serial)
    expected.spawn(emitter.sample(7, serial), 0);
  ASSERT_EQ(expected.size(), kRoom + 1);
  ASSERT_EQ(expected.droppedSpawns(), kBurst - kRoom);
  for (int threads : {1, 2, 3}) {
    ParticlePool pool(kRoom + 1);
    pool.spawn(first, 0);
    tbb::task_arena arena(threads);
    const std::uint64_t tried = arena.execute([&] { return emitter.emit(pool, 7, 0); });
    EXPECT_EQ(tried, kBurst) << threads << " threads";
    ASSERT_EQ(pool.size(), expected.size()) << threads << " threads";
    EXPECT_EQ(pool.droppedSpawns(), expected.droppedSpawns()) << threads << " threads";
    EXPECT_EQ(pool.nextId(), expected.nextId()) << threads << " threads";
    const auto rows = [](const auto& column, std::size_t n) {
      return std::vector(column.begin(), column.begin() + n);
    };
    EXPECT_EQ(rows(pool.id(), pool.size()), rows(expected.id(), pool.size()))
        << threads << " threads";
    EXPECT_EQ(rows(pool.birthTick(), pool.size()), rows(expected.birthTick(), pool.size()))
        << threads << " threads";
    for (std::size_t row = 0; row < pool.size(); ++row) {
      const auto r = static_cast<Eigen::Index>(row);
      const ParticleInit got = initOf(pool, r);
      const ParticleInit want = initOf(expected, r);
      ASSERT_TRUE(test::sameBits(got, want)) << "row " << row << ", " << threads << " threads";
      ASSERT_EQ(test::bitsOf(pool.mass()[r]), test::bitsOf(expected.mass()[r]));
      if (pool.keepsPrevious()) {
        ASSERT_EQ(test::bitsOf(pool.previousPosition().x[r]), test::bitsOf(pool.position().x[r]));
      }
    }
  }
}

// A burst at time t spawns its count in the first tick that starts at or after t, computed from
// flicks in integers (0.1 s · 60 Hz is tick 6, although 0.1 · 60 = 6.000000000000001 in double).
TEST(EmitterTiming, BurstsSpawnAtTheFirstTickAtOrAfterTheirTime) {
  struct Case {
    std::int64_t rate;
    double time;
    std::int64_t tick;
  };
  for (const Case& c :
       {Case{60, 0.0, 0}, Case{60, 0.1, 6}, Case{60, 0.105, 7}, Case{60, 1.0 / 3.0, 20},
        Case{60, 0.5, 30}, Case{1000, 0.0005, 1}, Case{1000, 0.1, 100}, Case{144, 0.25, 36},
        Case{7, 1.0, 7}, Case{7, 1.01, 8}}) {
    EmitterSettings s;
    s.bursts = {Burst{c.time, 13}};
    const Emitter emitter(s, 0, c.rate);
    ParticlePool pool(100);
    for (std::int64_t tick = 0; tick <= c.tick + 3; ++tick) {
      const std::uint64_t spawned = emitter.emit(pool, 1, tick);
      ASSERT_EQ(spawned, tick == c.tick ? 13u : 0u)
          << c.time << " s at " << c.rate << " Hz, tick " << tick;
    }
    ASSERT_EQ(pool.size(), 13u);
    EXPECT_EQ(pool.birthTick()[0], static_cast<std::uint32_t>(c.tick));
    EXPECT_EQ(pool.birthTick()[12], static_cast<std::uint32_t>(c.tick));
  }
}

TEST(EmitterTiming, SeveralBurstsAndARateWindowShareOneSerialCounter) {
  EmitterSettings s;
  s.rate = 60.0;  // one per tick at 60 Hz while active
  s.start = 0.5;
  s.stop = 1.0;
  s.bursts = {Burst{0.75, 4}, Burst{0.1, 2}};  // unsorted on purpose
  const Emitter emitter(s, 0, 60);
  ParticlePool pool(1000);
  std::map<std::int64_t, std::uint64_t> perTick;
  for (std::int64_t tick = 0; tick < 90; ++tick) {
    const std::uint64_t n = emitter.emit(pool, 1, tick);
    if (n > 0) perTick[tick] = n;
  }
  EXPECT_EQ(pool.size(), 36u);  // 30 ticks of rate in [0.5 s, 1 s) + 2 + 4
  EXPECT_EQ(perTick.at(6), 2u);
  EXPECT_EQ(perTick.at(45), 5u);  // the burst and that tick's rate particle
  EXPECT_EQ(perTick.count(29), 0u);
  EXPECT_EQ(perTick.at(30), 1u);
  EXPECT_EQ(perTick.at(59), 1u);
  EXPECT_EQ(perTick.count(60), 0u);
  EXPECT_EQ(emitter.serialBefore(90), 36u);
  // Serials are the pool's order of birth: particle k is sample(seed, k).
  for (std::size_t i = 0; i < pool.size(); ++i) {
    const ParticleInit expected = emitter.sample(1, i);
    ASSERT_EQ(pool.position().x[static_cast<Eigen::Index>(i)], expected.position.x());
    ASSERT_EQ(pool.velocity().y[static_cast<Eigen::Index>(i)], expected.velocity.y());
  }
}

TEST(EmitterSettingsCheck, RejectsSettingsOutOfRange) {
  auto bad = [](auto&& edit) {
    EmitterSettings s;
    edit(s);
    return [s] { const Emitter e(s, 0, 60); };
  };
  EXPECT_THROW(bad([](EmitterSettings& s) { s.rate = -1.0; })(), std::invalid_argument);
  EXPECT_THROW(bad([](EmitterSettings& s) { s.spreadDegrees = 181.0; })(), std::invalid_argument);
  EXPECT_THROW(bad([](EmitterSettings& s) { s.direction = Eigen::Vector3d::Zero(); })(),
               std::invalid_argument);
  EXPECT_THROW(bad([](EmitterSettings& s) { s.lifetime = 0.0; })(), std::invalid_argument);
  EXPECT_THROW(bad([](EmitterSettings& s) { s.lifetimeJitter = 1.0; })(), std::invalid_argument);
  EXPECT_THROW(bad([](EmitterSettings& s) { s.speedJitter = 1.5; })(), std::invalid_argument);
  EXPECT_THROW(bad([](EmitterSettings& s) { s.stop = -1.0; })(), std::invalid_argument);
  EXPECT_THROW(bad([](EmitterSettings& s) {
                 s.shape = DiscShape{1.0, Eigen::Vector3d::Zero()};
               })(),
               std::invalid_argument);
  EXPECT_NO_THROW(bad([](EmitterSettings&) {})());
}

TEST(EmitterSettingsCheck, ValidateNamesEachProblemByItsKeyAndTheConstructorThrowsTheFirst) {
  EmitterSettings s;
  EXPECT_TRUE(s.validate().empty());
  // Directions are normalised in double: a squared length below the smallest normal double
  // (|v| < 1.49e-154) is refused, zero included; 1.5e-154 passes.
  s.direction = Eigen::Vector3d(1e-200, 1e-200, 0.0);
  s.shape = DiscShape{1.0, Eigen::Vector3d(0.0, -1e-160, 0.0)};
  s.rate = -1.0;
  s.bursts = {{0.5, 1}, {-2.0, 1}};
  const SettingProblems problems = s.validate();
  std::vector<std::string> texts;
  for (const SettingProblem& p : problems) texts.push_back(p.text());
  EXPECT_EQ(texts,
            (std::vector<std::string>{
                "rate: -1 is out of range (expected particles per second, a number from 0 to 1e9)",
                "direction: is too short to normalise in double precision (expected a direction "
                "[x, y, z] at least 1.5e-154 long)",
                "normal: is too short to normalise in double precision (expected a direction [x, "
                "y, z] at least 1.5e-154 long)",
                "bursts.1.time: -2 is out of range (expected seconds, a number from 0 to 1e9)"}));
  try {
    const Emitter e(s, 0, 60);
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "emitter " + problems.front().text());
  }
  s = EmitterSettings{};
  s.direction = Eigen::Vector3d(0.0, 0.0, -1.5e-154);
  s.shape = DiscShape{1.0, Eigen::Vector3d(1.5e-154, 0.0, 0.0)};
  EXPECT_TRUE(s.validate().empty());
  // Normalised to exactly unit vectors: the emitter shoots straight down.
  s.speed = 2.0;
  EXPECT_EQ(Emitter(s, 0, 60).sample(1, 0).velocity, Eigen::Vector3f(0.0f, 0.0f, -2.0f));
}

// ---- point lists (PointListShape): particles born at given points ----------------------------

std::uint32_t floatBits(float x) { return std::bit_cast<std::uint32_t>(x); }

void expectSameBits(const Eigen::Vector3f& got, const Eigen::Vector3f& want,
                    const std::string& what) {
  for (int c = 0; c < 3; ++c)
    EXPECT_EQ(floatBits(got[c]), floatBits(want[c])) << what << " component " << c;
}

constexpr float kDenormal = std::numeric_limits<float>::denorm_min();

const std::vector<Eigen::Vector3f> kPoints = {
    {0.0f, -0.0f, kDenormal}, {1.5f, -2.25f, 1e-30f}, {123.456f, 7.0f, -8.0f}};

TEST(PointListEmitter, SerialSIsBornAtPointSModN) {
  EmitterSettings s;
  s.shape = PointListShape{kPoints, {}};
  s.speed = 3.0;
  s.spreadDegrees = 30.0;
  s.lifetime = 2.0;
  s.lifetimeJitter = 0.5;
  // The same emitter at a point: speeds, directions and lifetimes are the same random numbers.
  EmitterSettings point = s;
  point.shape = PointShape{};
  const Emitter list(s, 4, 60), reference(point, 4, 60);
  for (std::uint64_t serial = 0; serial < 12; ++serial) {
    const ParticleInit p = list.sample(9, serial), q = reference.sample(9, serial);
    expectSameBits(p.position, kPoints[serial % 3], "serial " + std::to_string(serial));
    expectSameBits(p.velocity, q.velocity, "velocity of serial " + std::to_string(serial));
    EXPECT_EQ(floatBits(p.lifetime), floatBits(q.lifetime));
    EXPECT_EQ(floatBits(p.mass), floatBits(q.mass));
  }
}

TEST(PointListEmitter, VelocitiesOfTheListAndThePositionOffset) {
  const std::vector<Eigen::Vector3f> velocities = {
      {-0.0f, 1.0f, 2.0f}, {3.0f, kDenormal, -4.5f}, {1e20f, 0.0f, -1e-20f}};
  EmitterSettings s;
  s.shape = PointListShape{kPoints, velocities};
  s.position = Eigen::Vector3d(1.0, -2.0, 0.1);
  s.speed = 5.0;  // the list's velocities win
  const Emitter e(s, 0, 60);
  for (std::uint64_t serial = 0; serial < 6; ++serial) {
    const ParticleInit p = e.sample(1, serial);
    const std::size_t k = serial % 3;
    // Offset by the emitter's position rounded to float, added in float (one precision).
    expectSameBits(p.position, Eigen::Vector3f(s.position.cast<float>() + kPoints[k]), "position");
    expectSameBits(p.velocity, velocities[k], "velocity");
  }
}

// GCC 12 at -O3 takes assigning a point list over the default point for a read of the list's
// uninitialised storage: a false -Wmaybe-uninitialized (the sanitizer builds turn it off whole).
EmitterSettings withShape(PointListShape shape) {
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
  EmitterSettings s;
  s.shape = std::move(shape);
  return s;
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
}

TEST(PointListEmitter, EmptyListsMismatchedVelocitiesAndNonFinitePointsAreRefused) {
  const auto with = [](PointListShape shape) { return withShape(std::move(shape)); };
  EXPECT_THROW(Emitter(with(PointListShape{}), 0, 60), std::invalid_argument);
  EXPECT_THROW(Emitter(with(PointListShape{kPoints, {Eigen::Vector3f::Zero()}}), 0, 60),
               std::invalid_argument);
  EXPECT_THROW(Emitter(with(PointListShape{
                           {Eigen::Vector3f(std::numeric_limits<float>::infinity(), 0, 0)}, {}}),
                       0, 60),
               std::invalid_argument);
}

}  // namespace
}  // namespace tickfx
