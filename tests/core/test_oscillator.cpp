// The harmonic oscillator k = m = 1, p0 = −1, v0 = 0 (AnchorSpring at the origin): exact
// p(t) = −cos t, v(t) = sin t, E = (p² + v²)/2 = 1/2.
//
// Every scheme is a linear map on (p, v), so its energy has a closed form: a per-step factor for
// the non-symplectic ones, an exactly conserved quadratic form for the symplectic ones. The tests
// hold the float runs to those forms, within float round-off.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "CoreTestSupport.h"
#include "ObliqueTestSupport.h"

namespace tickfx {
namespace {

using test::floatDt;
using test::kFloatU;

std::vector<test::Sample> oscillate(const std::string& integrator, std::int64_t rate,
                                    double seconds) {
  const ForceSet forces = test::unitOscillator();
  ParticleInit init;
  init.position = Eigen::Vector3f(-1.0f, 0.0f, 0.0f);
  std::vector<test::Sample> run{test::Sample{0, -1.0, 0.0}};
  const std::int64_t ticks = std::llround(seconds * static_cast<double>(rate));
  test::runSingle(integrator, forces, init, rate, ticks, 0,
                  [&](const test::Sample& s) { run.push_back(s); });
  return run;
}

double energy(const test::Sample& s) { return 0.5 * (s.p * s.p + s.v * s.v); }

// Each tick rounds p and v a few times (products and sums), each rounding a relative change of at
// most u; a quadratic form of them moves by at most ~2u per rounding. 4u per tick covers it
// (measured worst: 1.1u per tick, position Verlet's Q at dt = 1/20).
double roundOff(std::int64_t ticks) { return 4.0 * static_cast<double>(ticks) * kFloatU; }

std::string rateName(const ::testing::TestParamInfo<std::int64_t>& info) {
  return std::to_string(info.param) + "Hz";
}

// Parameter: the step rate, 20 Hz (dt = 1/20) or 4 Hz (dt = 1/4); every run lasts 20 s.
class OscillatorEnergy : public ::testing::TestWithParam<std::int64_t> {
 protected:
  double dt() const { return floatDt(GetParam()); }
  std::vector<test::Sample> run(const std::string& integrator) const {
    return oscillate(integrator, GetParam(), 20.0);
  }
};

// Explicit Euler: p' = p + dt·v, v' = v − dt·p, so p'² + v'² = (1 + dt²)(p² + v²) exactly.
TEST_P(OscillatorEnergy, ExplicitEulerGainsExactlyOnePlusDtSquaredPerStep) {
  const std::vector<test::Sample> r = run("explicit_euler");
  const double e0 = energy(r[0]);
  for (const test::Sample& s : r) {
    const double model = std::pow(1.0 + dt() * dt(), static_cast<double>(s.ticks));
    // Measured: 1.1e-6 (dt = 1/20, 400 ticks), 4.1e-7 (dt = 1/4, 80 ticks).
    ASSERT_NEAR(energy(s) / e0 / model, 1.0, roundOff(s.ticks)) << "after " << s.ticks << " ticks";
  }
  EXPECT_GT(energy(r.back()), 0.6);  // 1.357 at dt = 1/20, 63.9 at dt = 1/4
}

// Semi-implicit Euler conserves Q = p² + v² − dt·p·v exactly (the map has determinant 1 and
// leaves this form invariant), so E = (p² + v²)/2 stays in [Q/(2 + dt), Q/(2 − dt)]: within
// 2.5 % of 1/2 at dt = 1/20 and within 14.3 % at dt = 1/4. Position Verlet is the same map on
// (p_n, (p_n − p_{n−1})/dt) from its second tick on, so it conserves the same Q.
void expectSymplecticEulerInvariant(const std::vector<test::Sample>& r, std::size_t first,
                                    double h) {
  auto q = [h](const test::Sample& s) { return s.p * s.p + s.v * s.v - h * s.p * s.v; };
  const double q0 = q(r[first]);
  double eMin = 1e9, eMax = 0.0;
  for (std::size_t i = first; i < r.size(); ++i) {
    ASSERT_NEAR(q(r[i]) / q0, 1.0, roundOff(r[i].ticks)) << "after " << r[i].ticks << " ticks";
    eMin = std::min(eMin, energy(r[i]));
    eMax = std::max(eMax, energy(r[i]));
  }
  const double slack = 1.0 + roundOff(r.back().ticks);
  EXPECT_GE(eMin * slack, q0 / (2.0 + h));
  EXPECT_LE(eMax, q0 / (2.0 - h) * slack);
}

TEST_P(OscillatorEnergy, SemiImplicitEulerConservesItsModifiedEnergy) {
  // Measured E range: [0.48780, 0.51282] at dt = 1/20, [0.44445, 0.57125] at dt = 1/4.
  expectSymplecticEulerInvariant(run("semi_implicit_euler"), 0, dt());
}

TEST_P(OscillatorEnergy, PositionVerletConservesTheSameModifiedEnergy) {
  // Its first tick is a start step, not the map; Q is 0.999375 (dt = 1/20) after it.
  expectSymplecticEulerInvariant(run("position_verlet"), 1, dt());
}

// Velocity Verlet conserves Q = (1 − dt²/4)·p² + v², so E stays in [(1 − dt²/4)/2, 1/2]: within
// 0.07 % at dt = 1/20 and 1.6 % at dt = 1/4 (measured minima 0.499687 and 0.492190).
TEST_P(OscillatorEnergy, VelocityVerletConservesItsModifiedEnergy) {
  const std::vector<test::Sample> r = run("velocity_verlet");
  const double c = 1.0 - dt() * dt() / 4.0;
  auto q = [c](const test::Sample& s) { return c * s.p * s.p + s.v * s.v; };
  const double q0 = q(r[0]);
  for (const test::Sample& s : r) {
    ASSERT_NEAR(q(s) / q0, 1.0, roundOff(s.ticks)) << "after " << s.ticks << " ticks";
    const double slack = roundOff(s.ticks);
    ASSERT_GE(energy(s), 0.5 * c * (1.0 - slack));
    ASSERT_LE(energy(s), 0.5 * (1.0 + slack));
  }
}

// tickfx's midpoint (as specified: the second acceleration at the new position) has the step
// matrix M = [[1 − h²/2, h], [−h + h³/2, 1 − h²]] on the spring, det M = 1 − h²/2: the quadratic
// form Q = (1 − h²/2)p² + (h/2)pv + v² shrinks by exactly det M every step, so the energy decays
// as (1 − dt²/2)ⁿ (0.306 after 20 s at dt = 1/20). First order on position-dependent forces.
TEST_P(OscillatorEnergy, MidpointLosesEnergyByItsDeterminantEveryStep) {
  const std::vector<test::Sample> r = run("midpoint");
  const double h = dt();
  auto q = [h](const test::Sample& s) {
    return (1.0 - h * h / 2.0) * s.p * s.p + h / 2.0 * s.p * s.v + s.v * s.v;
  };
  const double q0 = q(r[0]);
  for (const test::Sample& s : r) {
    const double model = std::pow(1.0 - h * h / 2.0, static_cast<double>(s.ticks));
    ASSERT_NEAR(q(s) / q0 / model, 1.0, roundOff(s.ticks)) << "after " << s.ticks << " ticks";
  }
  EXPECT_LT(energy(r.back()),
            0.5 * std::pow(1.0 - h * h / 2.0, static_cast<double>(r.back().ticks)) * 1.1);
}

// RK4's step polynomial 1 + z + z²/2 + z³/6 + z⁴/24 has |·|² = 1 − dt⁶/72 + dt⁸/576: it loses
// energy by 2.7e-4 relative over 20 s at dt = 1/4 (measured 0.499865) and 1e-7 at dt = 1/20.
TEST_P(OscillatorEnergy, Rk4EnergyFollowsItsStepPolynomial) {
  const std::vector<test::Sample> r = run("rk4");
  const double h = dt();
  const double perStep = 1.0 - std::pow(h, 6.0) / 72.0 + std::pow(h, 8.0) / 576.0;
  for (const test::Sample& s : r) {
    const double model = std::pow(perStep, static_cast<double>(s.ticks));
    ASSERT_NEAR(energy(s) / 0.5 / model, 1.0, roundOff(s.ticks)) << "after " << s.ticks << " ticks";
  }
}

INSTANTIATE_TEST_SUITE_P(Dt, OscillatorEnergy, ::testing::Values(20, 4), rateName);

// Orders of convergence: the largest position error over 20 s, for dt halved three times. The rates
// start where the error is asymptotic and stop before float round-off (~5e-7 m over 20 s)
// exceeds about a fifth of the error.
struct OrderCase {
  std::string integrator;
  int expectedOrder;
  std::vector<std::int64_t> rates;
};

void PrintTo(const OrderCase& c, std::ostream* os) { *os << c.integrator; }

std::string orderName(const ::testing::TestParamInfo<OrderCase>& info) {
  return info.param.integrator;
}

double maxPositionError(const std::string& integrator, std::int64_t rate) {
  double worst = 0.0;
  const double dt = floatDt(rate);  // exact: the rates are powers of two
  for (const test::Sample& s : oscillate(integrator, rate, 20.0)) {
    worst = std::max(worst, std::abs(s.p + std::cos(static_cast<double>(s.ticks) * dt)));
  }
  return worst;
}

class ConvergenceOrder : public ::testing::TestWithParam<OrderCase> {};

// Measured orders per halving: explicit Euler 1.05 1.03 1.01; semi-implicit Euler 1.03 1.02 1.01;
// position and velocity Verlet 2.02 2.00 2.00; RK4 3.97 4.02 3.98. Midpoint, first order on the
// spring because its second evaluation reads the new position: it approaches 1 as dt shrinks.
// The tolerance is a quarter of the gap between neighbouring orders.
TEST_P(ConvergenceOrder, HalvingDtDividesTheErrorByTwoToTheOrder) {
  const OrderCase& c = GetParam();
  std::vector<double> errors;
  for (std::int64_t rate : c.rates) errors.push_back(maxPositionError(c.integrator, rate));
  for (std::size_t i = 1; i < errors.size(); ++i) {
    const double order = std::log2(errors[i - 1] / errors[i]);
    EXPECT_NEAR(order, c.expectedOrder, 0.25)
        << c.rates[i - 1] << " → " << c.rates[i] << " Hz: errors " << errors[i - 1] << ", "
        << errors[i];
  }
}

INSTANTIATE_TEST_SUITE_P(AllSchemes, ConvergenceOrder,
                         ::testing::Values(OrderCase{"explicit_euler", 1, {64, 128, 256, 512}},
                                           OrderCase{"semi_implicit_euler", 1, {32, 64, 128, 256}},
                                           OrderCase{"midpoint", 1, {64, 128, 256, 512}},
                                           OrderCase{"position_verlet", 2, {4, 8, 16, 32}},
                                           OrderCase{"velocity_verlet", 2, {4, 8, 16, 32}},
                                           OrderCase{"rk4", 4, {2, 4, 8, 16}}),
                         orderName);

// The trajectories themselves at dt = 1/20 over 20 s: the symplectic schemes stay on the exact
// solution to within their phase error, explicit Euler spirals out. The largest |p − (−cos t)| of
// each float run is that of the scheme's own recurrence in double
// (tests/support/ObliqueTestSupport.h) within the round-off bound there, where that bound is under
// a tenth of it: explicit Euler (0.60 m), semi-implicit Euler (0.027 m) and midpoint (0.21 m). For
// velocity Verlet (1.9e-3 m against a bound of 4.9e-4 m), position Verlet (1.9e-3 m; its bound
// grows as n², 5.4e-3 m) and RK4 (7.7e-7 m; bound 1e-4 m) the run can only show an error under the
// recurrence's plus the bound.
TEST(Oscillator, TrajectoriesAt20HzStayNearTheExactSolution) {
  using oblique::Vec;
  const oblique::Accel accel = [](const std::vector<Vec>& p, const std::vector<Vec>&, double) {
    return std::vector<Vec>{-p[0]};
  };
  oblique::Body start;
  start.p = Vec(-1.0, 0.0, 0.0);
  const std::int64_t ticks = 400;
  std::vector<std::string> unresolved;
  for (const std::string& name : integratorNames()) {
    const oblique::Trajectory recurrence = oblique::runReference(name, accel, {start}, 20, ticks);
    const oblique::Tolerances tol =
        oblique::roundOffTolerances(name, accel, {start}, 20, ticks, 0.0);
    double recurrenceError = 0.0, bound = 0.0;
    for (std::int64_t k = 0; k <= ticks; ++k) {
      const double t = static_cast<double>(k) * floatDt(20);
      const auto i = static_cast<std::size_t>(k);
      recurrenceError = std::max(recurrenceError, std::abs(recurrence.p[i][0].x() + std::cos(t)));
      bound = std::max(bound, tol.p[i][0].x());
    }
    const double measured = maxPositionError(name, 20);
    if (bound < 0.1 * recurrenceError) {
      EXPECT_NEAR(measured, recurrenceError, bound) << name;
    } else {
      EXPECT_LT(measured, recurrenceError + bound) << name;
      unresolved.push_back(name);
    }
  }
  EXPECT_EQ(unresolved, (std::vector<std::string>{"position_verlet", "velocity_verlet", "rk4"}));
  // Explicit Euler's amplitude grows as (1 + dt²)^(n/2), to 1.65 after 400 ticks.
  EXPECT_GT(maxPositionError("explicit_euler", 20), 0.5);
}

}  // namespace
}  // namespace tickfx
