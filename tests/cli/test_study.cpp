// The integrator study's figures against closed-form values: the exact solutions of the three
// experiments, and the exact solutions of each scheme's own recurrence (Euler's error for
// constant acceleration, the oscillator's step matrices, a sampled sine's quadrature factors),
// with the float constants the runs use. Tolerances are float round-off bounds derived below,
// and a check is made only where its bound is a small part of the effect it tells apart.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "ObliqueTestSupport.h"
#include "app/IntegratorStudy.h"
#include "integrators/Integrator.h"

namespace tickfx {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kU = 0x1p-24;  // unit round-off of float
const std::vector<std::int64_t> kRates{1000, 144, 60, 30, 20};

const StudyResults& study() {
  static const StudyResults results = runIntegratorStudy();
  return results;
}

// The step the integrators really take: 1/rate rounded to float once (StepTime::dt()).
double floatDt(std::int64_t rate) { return StepTime{0, rate}.dt(); }

std::int64_t ticksOf(double seconds, std::int64_t rate) {
  return std::llround(seconds * static_cast<double>(rate));
}

const ConstantAccelerationResult& fall(const std::string& integrator, std::int64_t rate, double t) {
  for (const auto& r : study().constantAcceleration) {
    if (r.integrator == integrator && r.stepRateHz == rate && r.time == t) return r;
  }
  throw std::logic_error("no constant-acceleration result for " + integrator);
}

const OscillatorResult& spring(const std::string& integrator, std::int64_t rate) {
  for (const auto& r : study().oscillator) {
    if (r.integrator == integrator && r.stepRateHz == rate) return r;
  }
  throw std::logic_error("no oscillator result for " + integrator);
}

const WindResult& gust(const std::string& integrator, std::int64_t rate, double f) {
  for (const auto& r : study().wind) {
    if (r.integrator == integrator && r.stepRateHz == rate && r.frequencyHz == f) return r;
  }
  throw std::logic_error("no wind result for " + integrator);
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

// ---- coverage --------------------------------------------------------------------------------

TEST(IntegratorStudy, CoversEveryIntegratorRateAndSample) {
  const auto& names = integratorNames();
  ASSERT_EQ(names.size(), 6u);
  EXPECT_EQ(study().constantAcceleration.size(), names.size() * kRates.size() * 2);
  EXPECT_EQ(study().oscillator.size(), names.size() * 2);
  EXPECT_EQ(study().wind.size(), names.size() * kRates.size() * 2);
  EXPECT_EQ(study().constantAcceleration.front().integrator, names.front());
  EXPECT_EQ(study().wind.back().integrator, names.back());
  for (const auto& r : study().constantAcceleration) {
    EXPECT_EQ(r.dt, 1.0 / static_cast<double>(r.stepRateHz));
    // The exact value is the closed form of the fall (its error column is checked against each
    // scheme's closed form below).
    EXPECT_EQ(r.exact, -9.81 * r.time * r.time / 2.0);
  }
}

TEST(IntegratorStudy, ExactSolutions) {
  EXPECT_DOUBLE_EQ(exactConstantAccelerationPosition(10.0), -490.5);
  EXPECT_DOUBLE_EQ(exactConstantAccelerationPosition(0.5), -1.22625);
  // det::cos and det::sin against the libm: both within an ulp or two of the true value (1e-15
  // covers 4 ulps at 1).
  EXPECT_NEAR(exactOscillatorPosition(20.0), -std::cos(20.0), 1e-15);
  EXPECT_NEAR(exactOscillatorVelocity(20.0), std::sin(20.0), 1e-15);
  // Over whole periods the sine term vanishes: p = 150·T/(2πf). A few roundings of 2^-53 of
  // values below 25: 1e-12 covers them.
  EXPECT_NEAR(exactWindPosition(4.0, 2.0), 150.0 * 2.0 / (2.0 * kPi * 4.0), 1e-12);
  EXPECT_NEAR(exactWindPosition(16.0, 2.0), 150.0 * 2.0 / (2.0 * kPi * 16.0), 1e-12);
  EXPECT_NEAR(exactWindVelocity(4.0, 0.125), 2.0 * 150.0 / (2.0 * kPi * 4.0), 1e-12);
}

TEST(IntegratorStudy, RejectsTimesBetweenTicksAndUnknownNames) {
  StudyPlan plan;
  plan.windDuration = 0.01;  // 1.44 ticks at 144 Hz
  EXPECT_THROW(runIntegratorStudy(plan), std::invalid_argument);
  EXPECT_THROW(runOscillator("leapfrog", 20, 1.0), std::invalid_argument);
  EXPECT_THROW(runWind("rk4", 0, 4.0, 1.0), std::invalid_argument);
}

// A regression guard, not a determinism proof: the same code path run twice in one process.
// What it proves is that the study has no hidden state between runs; the promise across frame
// schedules, threads and builds is tested by the determinism and golden-hash tests.
TEST(IntegratorStudy, SamePathTwiceGivesTheSameTablesRegressionGuard) {
  const StudyResults again = runIntegratorStudy();
  EXPECT_EQ(constantAccelerationCsv(again), constantAccelerationCsv(study()));
  EXPECT_EQ(oscillatorCsv(again), oscillatorCsv(study()));
  EXPECT_EQ(windCsv(again), windCsv(study()));
}

// ---- experiment 1: constant acceleration -------------------------------------------------------

// The float acceleration the gravity module adds (9.81 is not a float: 4e-8 relative apart).
const double kFloatGravity = static_cast<double>(static_cast<float>(kStudyGravity));

// Each scheme's recurrence from rest in closed form, with the float constants: after n ticks of
// dt, explicit Euler is at a·dt²·n(n−1)/2 (it moves with the velocity at the start of each
// tick), semi-implicit Euler at a·dt²·n(n+1)/2 (the one at the end), the other four at a·(n·dt)²/2.
double schemePosition(const std::string& integrator, std::int64_t rate, double t) {
  const double h = floatDt(rate);
  const auto n = static_cast<double>(ticksOf(t, rate));
  double steps = n * n;
  if (integrator == "explicit_euler") steps = n * (n - 1.0);
  if (integrator == "semi_implicit_euler") steps = n * (n + 1.0);
  return kFloatGravity * h * h * steps / 2.0;
}

// The first-order error the Eulers make and the other schemes must not: |a|·dt·t/2.
double firstOrderError(std::int64_t rate, double t) { return 9.81 * floatDt(rate) * t / 2.0; }

// Round-off of the fall. Each tick's final additions round p by at most u·|p_k| and v by
// u·|v_k|; with |v_k| = |a|·k·dt and |p_k| = |a|·(k·dt)²/2 the position roundings sum to
// n·u·|p_T|/3 and the velocity roundings move the end position by as much again. The increments
// (h·v, h·a, RK4's stages) are rounded at most 16 times a tick, each by u of h·|v_k| or h·|a|: at
// most 16·u·|p_T| through the position and 32·u·|p_T| through the velocity. So
// (2n/3 + 48)·u·|p_T|. Position Verlet keeps its velocity as p − p_prev: every position
// rounding persists as a velocity error, and they sum twice: (n²/6 + 48)·u·|p_T|.
double fallRoundOff(const std::string& integrator, std::int64_t rate, double t) {
  const auto n = static_cast<double>(ticksOf(t, rate));
  const double factor = integrator == "position_verlet" ? n * n / 6.0 + 48.0 : 2.0 * n / 3.0 + 48.0;
  return factor * kU * std::abs(schemePosition(integrator, rate, t));
}

// Checks every (rate, time) of `integrator` whose round-off bound is under a quarter of the
// first-order error, so that a scheme one order off fails; returns how many it checked.
int expectFallsFollowTheirClosedForm(const std::string& integrator) {
  int checked = 0;
  for (std::int64_t rate : kRates) {
    for (double t : {0.5, 10.0}) {
      const double bound = fallRoundOff(integrator, rate, t);
      if (bound > firstOrderError(rate, t) / 4.0) continue;
      const auto& r = fall(integrator, rate, t);
      EXPECT_NEAR(r.error, schemePosition(integrator, rate, t) - r.exact, bound)
          << integrator << ' ' << rate << " Hz, " << t << " s: first-order error "
          << firstOrderError(rate, t) << " m";
      ++checked;
    }
  }
  return checked;
}

// Explicit Euler lags |a|·dt·T/2 behind the fall; semi-implicit Euler leads by as much. At
// 1000 Hz over 10 s (n = 10⁴) the round-off bound, 0.2 m, is four times the 0.049 m lag itself:
// a float run cannot show it there, and that case is not checked (9 of 10 are).
TEST(IntegratorStudyConstantAcceleration, EulerErrorIsHalfOfADtWorthOfVelocity) {
  EXPECT_EQ(expectFallsFollowTheirClosedForm("explicit_euler"), 9);
  EXPECT_EQ(expectFallsFollowTheirClosedForm("semi_implicit_euler"), 9);
  for (std::int64_t rate : kRates) {
    for (double t : {0.5, 10.0}) {
      // The closed form is the lag: a·dt²·n(n∓1)/2 − a·(n·dt)²/2 = ∓a·dt·t/2.
      const double lag =
          schemePosition("explicit_euler", rate, t) - schemePosition("velocity_verlet", rate, t);
      EXPECT_NEAR(lag, 9.81f * floatDt(rate) * (ticksOf(t, rate) * floatDt(rate)) / 2.0,
                  1e-12 * std::abs(lag))
          << rate << " Hz, " << t << " s";
    }
  }
}

// docs/integrators.md's figure: |a|·dt·T/2 = 9.81 · 0.05 · 10 / 2 = 2.4525 m, with decimal
// constants. The float constants (9.81f, float(0.05)) move the closed form by 3.7e-5 m; the
// round-off bound of 200 ticks is 5.3e-3 m.
TEST(IntegratorStudyConstantAcceleration, ExplicitEulerAt20HzIsOff2_4525mAfter10s) {
  const auto& r = fall("explicit_euler", 20, 10.0);
  EXPECT_DOUBLE_EQ(r.exact, -490.5);
  const double closedForm = schemePosition("explicit_euler", 20, 10.0) - r.exact;
  EXPECT_NEAR(r.error, 2.4525,
              fallRoundOff("explicit_euler", 20, 10.0) + std::abs(closedForm - 2.4525));
  const auto& half = fall("explicit_euler", 20, 0.5);
  EXPECT_NEAR(half.error, 0.122625,
              fallRoundOff("explicit_euler", 20, 0.5) +
                  std::abs(schemePosition("explicit_euler", 20, 0.5) - half.exact - 0.122625));
}

// For a constant force these schemes are exact in real arithmetic: what is left is round-off and
// the float constants, checked where the bound is under a quarter of a first-order error.
TEST(IntegratorStudyConstantAcceleration, SecondOrderAndRk4AreExactUpToRoundOff) {
  for (const char* name : {"midpoint", "velocity_verlet", "rk4"}) {
    EXPECT_EQ(expectFallsFollowTheirClosedForm(name), 9) << name;
  }
}

// Position Verlet is exact in real arithmetic too, but its round-off grows with ticks²: resolvable
// at 20 Hz over both times and at 30, 60 and 144 Hz over 0.5 s.
TEST(IntegratorStudyConstantAcceleration, PositionVerletIsExactUpToRoundOffWhereThatIsResolvable) {
  EXPECT_EQ(expectFallsFollowTheirClosedForm("position_verlet"), 5);
}

// ---- experiment 2: harmonic oscillator ---------------------------------------------------------

// Each scheme is a fixed 2×2 matrix on (p, v) for this force, read off its specification; its
// n-th power in double is what the float run must reproduce. Position Verlet's first step is
// p1 = p0 + h·v0 − h²·p0/2, v1 = v0 − h·p0/2, then the semi-implicit matrix on
// (p_n, (p_n − p_{n−1})/h); midpoint evaluates its second force at the new position.
using Matrix2 = std::array<double, 4>;  // row-major

Matrix2 stepMatrix(const std::string& name, double h) {
  if (name == "explicit_euler") return {1.0, h, -h, 1.0};
  if (name == "semi_implicit_euler" || name == "position_verlet") return {1.0 - h * h, h, -h, 1.0};
  if (name == "midpoint") return {1.0 - h * h / 2.0, h, -h + h * h * h / 2.0, 1.0 - h * h};
  if (name == "velocity_verlet") {
    return {1.0 - h * h / 2.0, h, -h * (1.0 - h * h / 4.0), 1.0 - h * h / 2.0};
  }
  if (name == "rk4") {
    const double c = 1.0 - h * h / 2.0 + h * h * h * h / 24.0, s = h - h * h * h / 6.0;
    return {c, s, -s, c};
  }
  throw std::logic_error("no step matrix for " + name);
}

std::array<double, 2> discreteOscillator(const std::string& name, std::int64_t rate,
                                         double seconds = 20.0) {
  const double h = floatDt(rate);
  const Matrix2 m = stepMatrix(name, h);
  std::array<double, 2> x{-1.0, 0.0};
  for (std::int64_t k = 0; k < ticksOf(seconds, rate); ++k) {
    if (name == "position_verlet" && k == 0) {
      x = {x[0] + h * x[1] - h * h / 2.0 * x[0], x[1] - h / 2.0 * x[0]};
    } else {
      x = {m[0] * x[0] + m[1] * x[1], m[2] * x[0] + m[3] * x[1]};
    }
  }
  return x;
}

// The round-off bound of tests/support/ObliqueTestSupport.h for this run: each tick's roundings (at
// most 16 per component of the step and 24 per force evaluation, each u of what it rounds), carried
// to the end by the scheme's own propagator (explicit Euler's grows, position Verlet's as n²).
struct Bound {
  double p, v;
};

Bound oscillatorRoundOff(const std::string& name, std::int64_t rate, double seconds = 20.0) {
  using oblique::Vec;
  const oblique::Accel accel = [](const std::vector<Vec>& p, const std::vector<Vec>&, double) {
    return std::vector<Vec>{-p[0]};
  };
  oblique::Body start;
  start.p = Vec(-1.0, 0.0, 0.0);
  const oblique::Tolerances tol =
      oblique::roundOffTolerances(name, accel, {start}, rate, ticksOf(seconds, rate), 0.0);
  return {tol.p.back()[0].x(), tol.v.back()[0].x()};
}

TEST(IntegratorStudyOscillator, EverySchemeFollowsItsStepMatrix) {
  for (const std::string& name : integratorNames()) {
    for (std::int64_t rate : {20, 4}) {
      const auto [p, v] = discreteOscillator(name, rate);
      const auto& r = spring(name, rate);
      const Bound bound = oscillatorRoundOff(name, rate);
      // The schemes differ by O(h) per period: the bound stays a small part of one amplitude.
      ASSERT_LT(bound.p, 0.05) << name << ' ' << rate << " Hz";
      EXPECT_NEAR(r.position, p, bound.p) << name << ' ' << rate << " Hz";
      EXPECT_NEAR(r.velocity, v, bound.v) << name << ' ' << rate << " Hz";
      // The error column is the step matrix's own error against −cos t.
      EXPECT_NEAR(r.error, p - exactOscillatorPosition(r.time), bound.p + 1e-15);
    }
  }
}

// Energy ½(p² + v²) of a state within (δp, δv) of (p, v) is within |p|·δp + |v|·δv + (δp² + δv²)/2.
double energySlack(double p, double v, const Bound& b) {
  return std::abs(p) * b.p + std::abs(v) * b.v + (b.p * b.p + b.v * b.v) / 2.0;
}

// [[1, h], [−h, 1]] scales p² + v² by exactly 1 + h² every tick.
TEST(IntegratorStudyOscillator, ExplicitEulerEnergyGrowsAsOnePlusDtSquaredPerTick) {
  for (std::int64_t rate : {20, 4}) {
    const double h = floatDt(rate);
    const auto n = static_cast<double>(ticksOf(20.0, rate));
    const double expected = 0.5 * std::pow(1.0 + h * h, n);
    const auto [p, v] = discreteOscillator("explicit_euler", rate);
    EXPECT_NEAR(spring("explicit_euler", rate).energy, expected,
                energySlack(p, v, oscillatorRoundOff("explicit_euler", rate)) +
                    1e-12 * expected)  // the closed forms' double rounding
        << rate << " Hz";
  }
}

// The symplectic schemes conserve a nearby quadratic form, so the energy stays in a band set by
// dt instead of drifting: semi-implicit Euler keeps p² + v² − h·p·v, so ½(p² + v²) stays within
// [½/(1 + h/2), ½/(1 − h/2)]; velocity Verlet keeps v² + (1 − h²/4)·p², so within
// [½ − h²/8, ½]. Checked where the energy's round-off bound is under a tenth of the band: both
// rates of semi-implicit Euler, velocity Verlet at 4 Hz (at 20 Hz its band, 3.1e-4 J, is
// narrower than the bound).
TEST(IntegratorStudyOscillator, SymplecticSchemesKeepTheEnergyInABand) {
  int checked = 0;
  for (std::int64_t rate : {20, 4}) {
    const double h = floatDt(rate);
    struct Band {
      const char* name;
      double low, high;
    };
    for (const Band& band :
         {Band{"semi_implicit_euler", 0.5 / (1.0 + h / 2.0), 0.5 / (1.0 - h / 2.0)},
          Band{"velocity_verlet", 0.5 - h * h / 8.0, 0.5}}) {
      const auto& r = spring(band.name, rate);
      const double slack = energySlack(r.position, r.velocity, oscillatorRoundOff(band.name, rate));
      if (slack > 0.1 * (band.high - band.low)) continue;
      EXPECT_GE(r.energy, band.low - slack) << band.name << ' ' << rate << " Hz";
      EXPECT_LE(r.energy, band.high + slack) << band.name << ' ' << rate << " Hz";
      ++checked;
    }
  }
  EXPECT_EQ(checked, 3);
}

// The order of a scheme is a property of its step matrix, which EverySchemeFollowsItsStepMatrix
// holds the float runs to. Here the matrices' own errors against −cos t after 20 s, in double:
// dt five times longer (4 Hz against 20 Hz) makes velocity Verlet's error 5² times larger, dt
// twice as long (4 Hz against 8 Hz) RK4's 2⁴ times. The measured order must be within a quarter
// of the gap to the next order.
double matrixError(const std::string& name, std::int64_t rate) {
  return std::abs(discreteOscillator(name, rate)[0] + std::cos(20.0));
}

TEST(IntegratorStudyOscillator, VelocityVerletIsSecondOrderAndRk4FourthOrder) {
  EXPECT_NEAR(std::log(matrixError("velocity_verlet", 4) / matrixError("velocity_verlet", 20)) /
                  std::log(5.0),
              2.0, 0.25);
  EXPECT_NEAR(std::log2(matrixError("rk4", 4) / matrixError("rk4", 8)), 4.0, 0.25);
  // The study's own error figures are those errors, within round-off: for RK4 at 20 Hz
  // (6.6e-7 m) the bound is larger than the error, so the figure says only that it is small.
  for (const char* name : {"velocity_verlet", "rk4"}) {
    for (std::int64_t rate : {20, 4}) {
      EXPECT_NEAR(std::abs(spring(name, rate).error), matrixError(name, rate),
                  oscillatorRoundOff(name, rate).p)
          << name << ' ' << rate << " Hz";
    }
  }
}

// The midpoint scheme as specified evaluates the second force at the end-of-step position, which
// makes it first order when the force depends on position: on the spring its error only halves
// when dt halves (the step matrix's errors at 20, 40 and 80 Hz give orders 0.96 and 0.98, within a
// tenth of 1, the gap to second order being 1), and its energy decays every step, by
// det M = 1 − h²/2. (For forces of time alone it is second order: see the wind tests.) The float
// runs follow the matrix within round-off, under a tenth of their errors.
TEST(IntegratorStudyOscillator, MidpointIsFirstOrderOnASpringAndLosesEnergy) {
  EXPECT_NEAR(std::log2(matrixError("midpoint", 20) / matrixError("midpoint", 40)), 1.0, 0.1);
  EXPECT_NEAR(std::log2(matrixError("midpoint", 40) / matrixError("midpoint", 80)), 1.0, 0.1);
  std::vector<OscillatorResult> runs;
  for (std::int64_t rate : {20, 40, 80}) {
    runs.push_back(runOscillator("midpoint", rate, 20.0));
    const auto [p, v] = discreteOscillator("midpoint", rate);
    const Bound bound = oscillatorRoundOff("midpoint", rate);
    ASSERT_LT(bound.p, 0.1 * matrixError("midpoint", rate)) << rate << " Hz";
    EXPECT_NEAR(runs.back().position, p, bound.p) << rate << " Hz";
    EXPECT_NEAR(runs.back().velocity, v, bound.v) << rate << " Hz";
  }
  // ½·(1 − h²/2)^n: 0.30, 0.39, 0.44 J, apart by far more than their round-off.
  EXPECT_LT(runs[0].energy, runs[1].energy);
  EXPECT_LT(runs[1].energy, runs[2].energy);
  EXPECT_LT(runs[2].energy, 0.5);
}

// ---- experiment 3: periodic wind ---------------------------------------------------------------

// A sine sampled every h over whole periods: each scheme's velocity is a quadrature of the sine,
// and a quadrature of e^{iωt} is the exact integral times a real factor, so the drift after whole
// periods is the exact drift times that factor (θ = ωh; negative past the Nyquist rate).
double trapezoidFactor(double theta) { return (theta / 2.0) / std::tan(theta / 2.0); }
double midpointFactor(double theta) { return (theta / 2.0) / std::sin(theta / 2.0); }
double simpsonFactor(double theta) {
  return theta * (std::cos(theta / 2.0) + 2.0) / (6.0 * std::sin(theta / 2.0));
}

double windFactor(const std::string& name, double theta) {
  if (name == "midpoint") return midpointFactor(theta);
  if (name == "rk4") return simpsonFactor(theta);
  // Both Eulers and both Verlets: left sums and trapezoids of a sine agree over whole periods.
  return trapezoidFactor(theta);
}

// How far the float run may be from factor·exact: the round-off bound of ObliqueTestSupport.h
// (F = 150 m/s², the amplitude), plus the clock: the schemes step by h = (1 + δ)/rate while the
// wind reads the exact k/rate, which scales the drift by at most (1 + δ)² − 1 ≈ 2δ.
double windBound(const std::string& name, std::int64_t rate, double f) {
  using oblique::Vec;
  const double omega = 2.0 * kPi * f;
  const oblique::Accel accel = [omega](const std::vector<Vec>&, const std::vector<Vec>&, double t) {
    return std::vector<Vec>{Vec(kStudyWindAmplitude * std::sin(omega * t), 0.0, 0.0)};
  };
  const oblique::Tolerances tol =
      oblique::roundOffTolerances(name, accel, {oblique::Body{}}, rate, ticksOf(2.0, rate), 150.0);
  const double delta = std::abs(floatDt(rate) * static_cast<double>(rate) - 1.0);
  const double drift =
      std::abs(windFactor(name, omega * floatDt(rate))) * exactWindPosition(f, 2.0);
  return tol.p.back()[0].x() + 2.0001 * delta * drift;
}

// Checked where the bound is under a quarter of the scheme's own quadrature error
// |factor − 1|·exact, the effect that tells the schemes apart: 37 of the 60 runs. Not every
// scheme at 1000 Hz (the factors differ from 1 by 5e-5 at 4 Hz, less than the round-off of 2000
// ticks), most of RK4's (Simpson's factor differs from 1 by about θ⁴/2880), and a few at 144 and
// 60 Hz where position Verlet's n² round-off or the two evaluations of midpoint and velocity
// Verlet outgrow the factor's error.
TEST(IntegratorStudyWind, DriftIsTheExactDriftTimesTheSchemesQuadratureFactor) {
  int checked = 0;
  std::string skipped;
  for (const std::string& name : integratorNames()) {
    for (std::int64_t rate : kRates) {
      for (double f : {4.0, 16.0}) {
        const auto& r = gust(name, rate, f);
        const double factor = windFactor(name, 2.0 * kPi * f * floatDt(rate));
        const double bound = windBound(name, rate, f);
        if (bound > std::abs(factor - 1.0) * r.exact / 4.0) {
          skipped +=
              " " + name + "@" + std::to_string(rate) + "Hz/" + std::to_string(int(f)) + "Hz";
          continue;
        }
        EXPECT_NEAR(r.position, factor * r.exact, bound)
            << name << ' ' << rate << " Hz, f = " << f << " Hz";
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 37) << "not resolvable:" << skipped;
}

// 16 Hz sampled at 20 Hz is indistinguishable from a 4 Hz wind of the opposite sign, so a particle
// that should drift 2.98 m forward is carried 10.32 m backward: the trapezoid factor at
// θ = 2π·16/20 times the exact drift.
TEST(IntegratorStudyWind, SixteenHertzAt20HzIsCarriedBackwards) {
  const auto& r = gust("velocity_verlet", 20, 16.0);
  EXPECT_NEAR(r.exact, 150.0 * 2.0 / (2.0 * kPi * 16.0), 1e-12);
  const double expected = trapezoidFactor(2.0 * kPi * 16.0 * floatDt(20)) * r.exact;
  EXPECT_NEAR(expected, -10.3229, 5e-5);  // the integrator study's figure, to its digits
  EXPECT_NEAR(r.position, expected, windBound("velocity_verlet", 20, 16.0));
  // The 4 Hz wind's samples are those of the 16 Hz one negated (sin(2π·4k/20) = −sin(2π·16k/20)),
  // so its run is the same run mirrored, up to both runs' round-off.
  EXPECT_NEAR(r.position, -gust("velocity_verlet", 20, 4.0).position,
              windBound("velocity_verlet", 20, 16.0) + windBound("velocity_verlet", 20, 4.0));
  // Still below Nyquist at 60 Hz: short by 1 − trapezoidFactor(2π·16/60) = 24 %, but forward.
  const auto& r60 = gust("velocity_verlet", 60, 16.0);
  EXPECT_NEAR(r60.position, trapezoidFactor(2.0 * kPi * 16.0 * floatDt(60)) * r60.exact,
              windBound("velocity_verlet", 60, 16.0));
  EXPECT_GT(trapezoidFactor(2.0 * kPi * 16.0 * floatDt(60)), 0.7);
}

// ---- output ------------------------------------------------------------------------------------

std::vector<std::string> csvFields(const std::string& row) {
  std::vector<std::string> out;
  std::istringstream in(row);
  for (std::string field; std::getline(in, field, ',');) out.push_back(field);
  return out;
}

TEST(IntegratorStudyOutput, TablesAreAlignedWithUnits) {
  struct Expected {
    std::string table;
    const char* unitColumn;
    std::size_t rows;
  };
  const Expected tables[] = {
      {formatConstantAccelerationTable(study()), "position (m)", 60},
      {formatOscillatorTable(study()), "energy (J)", 12},
      {formatWindTable(study()), "f (Hz)", 60},
  };
  for (const auto& [table, unitColumn, expectedRows] : tables) {
    // Title, header, rule, then the rows with a blank line between integrators.
    const auto rows = lines(table);
    ASSERT_EQ(rows.size(), 3 + expectedRows + (integratorNames().size() - 1)) << table;
    for (const char* header : {"integrator", "rate (Hz)", "dt (s)", "t (s)", "error (m)"}) {
      EXPECT_NE(rows[1].find(header), std::string::npos) << header;
    }
    EXPECT_NE(rows[1].find(unitColumn), std::string::npos) << unitColumn;
    EXPECT_EQ(rows[2], std::string(rows[1].size(), '-'));
    for (std::size_t i = 3; i < rows.size(); ++i) {
      if (!rows[i].empty()) {
        EXPECT_EQ(rows[i].size(), rows[1].size()) << rows[i];
      }
    }
  }
}

TEST(IntegratorStudyOutput, PrintStudyWritesAllThreeTables) {
  std::FILE* file = std::tmpfile();
  ASSERT_NE(file, nullptr);
  printStudy(study(), file);
  std::rewind(file);
  std::string text;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, file)) > 0;) text.append(buffer, n);
  std::fclose(file);
  EXPECT_EQ(text, formatConstantAccelerationTable(study()) + "\n" + formatOscillatorTable(study()) +
                      "\n" + formatWindTable(study()));
}

TEST(IntegratorStudyOutput, WritesOneCsvPerExperiment) {
  // Unique per run: other build trees may run this test at the same time.
  const std::filesystem::path root = std::filesystem::path(testing::TempDir()) /
                                     ("tickfx_study_csv_" + std::to_string(std::random_device{}()));
  const std::filesystem::path dir = root / "nested";  // must be created
  const auto paths = writeStudyCsv(study(), dir);
  ASSERT_EQ(paths.size(), 3u);
  EXPECT_EQ(paths[0], dir / "constant_acceleration.csv");
  EXPECT_EQ(paths[1], dir / "oscillator.csv");
  EXPECT_EQ(paths[2], dir / "wind.csv");

  struct Expected {
    const char* header;
    std::size_t rows;
  };
  const Expected expected[] = {
      {"integrator,dt,step_rate_hz,t,position,exact,error", 60},
      {"integrator,dt,step_rate_hz,t,position,exact,error,velocity,energy", 12},
      {"integrator,dt,step_rate_hz,frequency_hz,t,position,exact,error", 60},
  };
  std::vector<std::vector<std::string>> files;
  for (std::size_t i = 0; i < 3; ++i) {
    std::ifstream in(paths[i]);
    std::stringstream text;
    text << in.rdbuf();
    const auto rows = lines(text.str());
    ASSERT_EQ(rows.size(), expected[i].rows + 1) << paths[i];
    EXPECT_EQ(rows[0], expected[i].header);
    const std::size_t columns = csvFields(rows[0]).size();
    for (const auto& row : rows) EXPECT_EQ(csvFields(row).size(), columns) << row;
    files.push_back(rows);
  }
  std::filesystem::remove_all(root);

  EXPECT_EQ(files[0][1].rfind("explicit_euler,0.001,1000,0.5,", 0), 0u) << files[0][1];
  EXPECT_EQ(files[1][1].rfind("explicit_euler,0.05,20,20,", 0), 0u) << files[1][1];
  EXPECT_EQ(files[2][1].rfind("explicit_euler,0.001,1000,4,2,", 0), 0u) << files[2][1];
  // Nine significant digits give back every float of the simulated state exactly.
  for (std::size_t i = 0; i < study().constantAcceleration.size(); ++i) {
    const auto& r = study().constantAcceleration[i];
    const auto fields = csvFields(files[0][i + 1]);
    EXPECT_EQ(fields[0], r.integrator);
    EXPECT_EQ(static_cast<float>(std::stod(fields[4])), static_cast<float>(r.position));
  }
  for (std::size_t i = 0; i < study().oscillator.size(); ++i) {
    const auto fields = csvFields(files[1][i + 1]);
    EXPECT_EQ(static_cast<float>(std::stod(fields[7])),
              static_cast<float>(study().oscillator[i].velocity));
  }
}

}  // namespace
}  // namespace tickfx
