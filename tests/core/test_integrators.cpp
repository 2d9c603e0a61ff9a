// Every integrator against the closed form of a fall from rest under a = −9.81 m/s².
//
// For constant a the exact schemes (midpoint, both Verlets, RK4) reproduce p = a·t²/2; explicit
// Euler gives a·dt²·n(n−1)/2 = a·t²/2 + |a|·dt·t/2 (it lags the fall) and semi-implicit Euler
// a·dt²·n(n+1)/2 = a·t²/2 − |a|·dt·t/2 (it overshoots), t = n·dt with dt the float step.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "CoreTestSupport.h"
#include "fields/LinearDrag.h"
#include "integrators/Integrator.h"

namespace tickfx {
namespace {

using test::floatDt;
using test::kFloatU;

// The float the gravity module adds, not the decimal 9.81 (they differ by 4e-8 relative, 2e-5 m
// after a 490 m fall).
const double kA = static_cast<double>(-9.81f);

struct FallResult {
  double p = 0.0, v = 0.0;
  std::int64_t ticks = 0;
};

FallResult fall(const std::string& integrator, std::int64_t rate, double seconds) {
  FallResult r;
  r.ticks = std::llround(seconds * static_cast<double>(rate));
  const ForceSet forces = test::gravityOnly();
  test::runSingle(integrator, forces, ParticleInit{}, rate, r.ticks, 1, [&](const test::Sample& s) {
    r.p = s.p;
    r.v = s.v;
  });
  return r;
}

// Signed scheme error of the position for a fall from rest: +lag for explicit Euler, −overshoot
// for semi-implicit Euler, 0 for the schemes exact on constant acceleration.
double schemeOffset(const std::string& integrator, double dt, double t) {
  const double firstOrder = std::abs(kA) * dt * t / 2.0;
  if (integrator == "explicit_euler") return firstOrder;
  if (integrator == "semi_implicit_euler") return -firstOrder;
  return 0.0;
}

struct FallCase {
  std::string integrator;
  std::int64_t rate;
  double seconds;
};

void PrintTo(const FallCase& c, std::ostream* os) {
  *os << c.integrator << " at " << c.rate << " Hz for " << c.seconds << " s";
}

std::string caseName(const ::testing::TestParamInfo<FallCase>& info) {
  return info.param.integrator + "_" + std::to_string(info.param.rate) + "Hz_" +
         (info.param.seconds < 1.0 ? std::string("0_5s") : std::string("10s"));
}

// Round-off of the fall from rest after `seconds`. Each tick's final additions round v by at most
// u·|v_k| and p by u·|p_k|; summed with |v_k| = |a|·k·dt and |p_k| = |a|(k·dt)²/2, the velocity
// errors moved the position by at most n·u·|p_T|/3 and the position roundings add another
// n·u·|p_T|/3. The increments (h·v, h·a, RK4's stages) are rounded at most 16 times a tick, each by
// u of h·|v_k| or h·|a|: at most 16·u·|p_T| through the position and 32·u·|p_T| through the
// velocity. Position Verlet keeps its velocity as p − p_prev: every rounding of the second
// difference is a velocity error that persists, so its errors sum twice: n²·u·|p_T|/6 instead.
double fallRoundOff(const std::string& integrator, std::int64_t rate, double seconds) {
  const double n = std::round(seconds * static_cast<double>(rate));
  const double t = n * floatDt(rate);
  const double pT = std::abs(0.5 * kA * t * t);
  const double sums = integrator == "position_verlet" ? n * n / 6.0 : 2.0 / 3.0 * n;
  return (sums + 48.0) * kFloatU * pT;
}

double firstOrderError(std::int64_t rate, double seconds) {
  const double dt = floatDt(rate);
  return std::abs(kA) * dt * (std::round(seconds * static_cast<double>(rate)) * dt) / 2.0;
}

// The cases whose round-off bound is under a quarter of the first-order error, so that a scheme
// one order off fails. Not 1000 Hz over 10 s (n = 10⁴: the bound, 0.2 m, is four times the
// 0.049 m first-order error) for any scheme; for position Verlet, whose bound grows as n², neither
// 1000 Hz over 0.5 s nor 60 Hz over 10 s (its quantisation far from the origin is tested below).
std::vector<FallCase> allFallCases() {
  std::vector<FallCase> cases;
  for (const std::string& name : integratorNames()) {
    for (std::int64_t rate : {1000, 60, 20}) {
      for (double seconds : {0.5, 10.0}) {
        if (fallRoundOff(name, rate, seconds) > firstOrderError(rate, seconds) / 4.0) continue;
        cases.push_back({name, rate, seconds});
      }
    }
  }
  return cases;
}

class ConstantAcceleration : public ::testing::TestWithParam<FallCase> {};

TEST_P(ConstantAcceleration, PositionErrorIsTheSchemeError) {
  const FallCase& c = GetParam();
  const FallResult r = fall(c.integrator, c.rate, c.seconds);
  const double dt = floatDt(c.rate);
  const double n = static_cast<double>(r.ticks);
  const double t = n * dt;
  const double exact = 0.5 * kA * t * t;
  const double offset = schemeOffset(c.integrator, dt, t);
  const double firstOrder = std::abs(kA) * dt * t / 2.0;
  const double error = r.p - exact;

  const double roundOff = fallRoundOff(c.integrator, c.rate, c.seconds);
  ASSERT_LE(roundOff, firstOrder / 4.0) << "allFallCases() admits no such case";
  EXPECT_NEAR(error, offset, roundOff)
      << "position " << r.p << " m, exact " << exact << " m, first-order error " << firstOrder;

  // Velocity: exact for every scheme except position Verlet, whose backward difference
  // (p_n − p_{n−1})/dt is the velocity at t − dt/2. Round-off: n additions to v (≤ n·u·|v_T|), or
  // for position Verlet n roundings kept in its second difference (≤ n·u·|p_T|/dt). Checked where
  // that stays below a quarter of the lag |a|·dt/2, so the two cases are told apart.
  const bool verlet = c.integrator == "position_verlet";
  const double expectedV = verlet ? kA * (t - dt / 2.0) : kA * t;
  const double velocityRoundOff =
      verlet ? n * kFloatU * std::abs(exact) / dt : n * kFloatU * std::abs(kA * t);
  if (velocityRoundOff < std::abs(kA) * dt / 4.0) {
    EXPECT_NEAR(r.v, expectedV, velocityRoundOff) << "velocity after " << r.ticks << " ticks";
  }
}

INSTANTIATE_TEST_SUITE_P(AllSchemes, ConstantAcceleration, ::testing::ValuesIn(allFallCases()),
                         caseName);

// The limit PositionVerlet.h documents: past 256 m at 1000 Hz, a·dt² = 9.8e-6 m is below half an
// ulp of p, so the second difference stops growing and the fall lags by metres. That is more than
// the round-off any scheme that keeps its velocity can make over these 10⁴ ticks,
// (2n/3 + 48)·u·|p_T| = 0.2 m (fallRoundOff), which velocity Verlet stays within.
TEST(ConstantAcceleration, PositionVerletQuantisesAFarFineFallAsDocumented) {
  const double exact = 0.5 * kA * 100.0;
  const double oneStepRoundOff = fallRoundOff("velocity_verlet", 1000, 10.0);
  EXPECT_GT(std::abs(fall("position_verlet", 1000, 10.0).p - exact), oneStepRoundOff);
  EXPECT_LT(std::abs(fall("velocity_verlet", 1000, 10.0).p - exact), oneStepRoundOff);
}

// The figure by hand: |a|·dt·T/2 = 9.81 · 0.05 · 10 / 2 = 2.4525 m.
TEST(ConstantAcceleration, EulerErrorsAt20HzOver10sAre2_4525m) {
  const double exact = 0.5 * kA * 100.0;
  const FallResult ee = fall("explicit_euler", 20, 10.0);
  const FallResult se = fall("semi_implicit_euler", 20, 10.0);
  // dt is float(0.05) = 0.05 + 7.5e-10 (1.5e-5 m over the fall); the round-off bound of 200 ticks
  // is (2n/3 + 48)·u·|p_T| = 5.3e-3 m.
  const double tolerance = fallRoundOff("explicit_euler", 20, 10.0) + 1.5e-5;
  EXPECT_NEAR(ee.p - exact, 2.4525, tolerance);
  EXPECT_NEAR(se.p - exact, -2.4525, tolerance);
}

// A particle spawned into a pool that has already stepped must start its scheme on its own tick
// (position and velocity Verlet carry history), whatever its row.
TEST(ConstantAcceleration, LateSpawnStartsCleanlyInEveryScheme) {
  const ForceSet forces = test::gravityOnly();
  for (const std::string& name : integratorNames()) {
    ParticlePool pool(4);
    std::unique_ptr<Integrator> scheme = makeIntegrator(name);
    const std::int64_t rate = 60;
    ParticleInit early;
    early.position = Eigen::Vector3f(1.0f, 0.0f, 0.0f);
    pool.spawn(early, 0);
    const std::int64_t lateTick = 7, total = 31;
    for (std::int64_t k = 0; k < total; ++k) {
      if (k == lateTick) {
        ParticleInit late;
        late.velocity = Eigen::Vector3f(0.0f, 5.0f, 0.0f);
        pool.spawn(late, k);
      }
      scheme->step(pool, forces, StepTime{k, rate});
      pool.markAllStepped();
    }
    const double dt = floatDt(rate);
    const double n = static_cast<double>(total - lateTick);
    const double t = n * dt;
    const double exact = 5.0 * t + 0.5 * kA * t * t;
    const double offset = schemeOffset(name, dt, t);
    // At most 31 ticks at |p| < 2.4 m: round-off below 3e-5 m (position Verlet's n²·u·|p|/6),
    // first-order errors 0.03 m and more.
    EXPECT_NEAR(pool.position().y[1] - exact, offset, 3e-5) << name << ", the late particle";
    const double tEarly = static_cast<double>(total) * dt;
    EXPECT_NEAR(pool.position().y[0] - 0.5 * kA * tEarly * tEarly, schemeOffset(name, dt, tEarly),
                3e-5)
        << name << ", the early particle";
  }
}

// Regression (issue 10, item 16), docs/integrators.md's order table: position Verlet's velocity is
// the last step's difference of positions, half a step behind, so a force that reads velocity makes
// it first order: under linear drag (k = 2/s, from 10 m/s, 1 s) its position error halves when the
// step halves, where velocity Verlet's quarters. The figures are the schemes' closed forms
// (test_forces_oblique): position Verlet −0.04975 m at 60 Hz and −0.02481 m at 120 Hz.
TEST(LinearDragOrder, PositionVerletIsFirstOrderWhenForcesReadVelocity) {
  constexpr double kDrag = 2.0, kSpeed = 10.0, kSeconds = 1.0;
  ForceSet forces;
  forces.add(std::make_unique<LinearDrag>(static_cast<float>(kDrag), Eigen::Vector3f::Zero()));
  ParticleInit init;
  init.velocity = Eigen::Vector3f(static_cast<float>(kSpeed), 0.0f, 0.0f);
  const double exact = kSpeed * (1.0 - std::exp(-kDrag * kSeconds)) / kDrag;
  auto errorAt = [&](const std::string& integrator, std::int64_t rate) {
    double p = 0.0;
    test::runSingle(integrator, forces, init, rate, rate, 0,
                    [&](const test::Sample& s) { p = s.p; });
    return p - exact;
  };
  // Round-off bounds as for the fall (fallRoundOff): the distance is at most 5 m, and position
  // Verlet's velocity keeps every rounding of its positions, so its bound grows as n².
  auto roundOff = [&](const std::string& integrator, std::int64_t rate) {
    const double n = static_cast<double>(rate) * kSeconds;
    return ((integrator == "position_verlet" ? n * n / 6.0 : 2.0 / 3.0 * n) + 48.0) * kFloatU * 5.0;
  };
  const double verlet60 = errorAt("position_verlet", 60),
               verlet120 = errorAt("position_verlet", 120);
  EXPECT_NEAR(verlet60, -0.0497522, roundOff("position_verlet", 60));    // 1.8e-4
  EXPECT_NEAR(verlet120, -0.0248127, roundOff("position_verlet", 120));  // 7.2e-4
  EXPECT_GT(verlet60 / verlet120, 1.9) << "first order";
  EXPECT_LT(verlet60 / verlet120, 2.1) << "first order";
  const double velocity60 = errorAt("velocity_verlet", 60);
  const double velocity120 = errorAt("velocity_verlet", 120);
  EXPECT_NEAR(velocity60, 5.6182e-4, roundOff("velocity_verlet", 60));    // 2.6e-5
  EXPECT_NEAR(velocity120, 1.4202e-4, roundOff("velocity_verlet", 120));  // 3.1e-5
  EXPECT_GT(velocity60 / velocity120, 3.0) << "second order";
}

TEST(IntegratorRegistry, NamesMakeTheirSchemes) {
  const std::vector<std::string> expected{"explicit_euler",  "semi_implicit_euler", "midpoint",
                                          "position_verlet", "velocity_verlet",     "rk4"};
  EXPECT_EQ(integratorNames(), expected);
  const std::vector<int> orders{1, 1, 2, 2, 2, 4};
  const std::vector<int> evaluations{1, 1, 2, 1, 1, 4};
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const std::unique_ptr<Integrator> scheme = makeIntegrator(expected[i]);
    EXPECT_EQ(scheme->name(), expected[i]);
    EXPECT_EQ(scheme->order(), orders[i]) << expected[i];
    EXPECT_EQ(scheme->evaluationsPerStep(), evaluations[i]) << expected[i];
  }
  EXPECT_THROW(makeIntegrator("leapfrog"), std::invalid_argument);
  EXPECT_THROW(makeIntegrator(""), std::invalid_argument);
}

TEST(IntegratorRegistry, StepTimeIsExactFromIntegers) {
  const StepTime t{7, 60};
  EXPECT_EQ(t.dt(), static_cast<float>(1.0 / 60.0));
  EXPECT_EQ(t.stage(0).seconds(), 7.0 / 60.0);
  EXPECT_EQ(t.stage(1).seconds(), 7.5 / 60.0);
  EXPECT_EQ(t.stage(2).seconds(), 8.0 / 60.0);
}

}  // namespace
}  // namespace tickfx
