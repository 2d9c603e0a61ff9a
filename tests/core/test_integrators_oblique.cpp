// The integrator study's two closed-form experiments, turned off the axes: a fall under a
// constant acceleration along ê = (2, −3, 6)/7, and the unit oscillator along ê and on an
// ellipse whose start position and velocity point along no axis and not along each other. Every
// component has its own size, so a scheme that drops, swaps or mis-signs a component fails.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "ObliqueTestSupport.h"
#include "fields/AnchorSpring.h"
#include "fields/Gravity.h"

namespace tickfx::oblique {
namespace {

// ---- constant acceleration ----------------------------------------------------------------------

// 9.81 m/s² along ê, rounded to float per component: the values the gravity module adds.
Vec fallAcceleration() {
  const Vec e = Vec(2.0, -3.0, 6.0) / 7.0;
  return floats(static_cast<float>(9.81 * e.x()), static_cast<float>(9.81 * e.y()),
                static_cast<float>(9.81 * e.z()));
}

struct FallCase {
  std::string scheme;
  std::int64_t rate;
  double seconds;
};

void PrintTo(const FallCase& c, std::ostream* os) {
  *os << c.scheme << " at " << c.rate << " Hz for " << c.seconds << " s";
}

// The cases whose round-off bound (below) is under a quarter of the first-order error along
// every axis, so that the exact schemes and the two Eulers are told apart. 1000 Hz over 10 s is
// not (n = 10⁴: the bound is 1.5 times the lag), for any scheme; position Verlet's n² bound
// rules out 1000 Hz over 0.5 s and 60 Hz over 10 s as well (its quantisation there is the
// subject of test_integrators' PositionVerletQuantisesAFarFineFallAsDocumented).
std::vector<FallCase> fallCases() {
  std::vector<FallCase> out;
  for (const std::string& scheme : integratorNames()) {
    for (std::int64_t rate : {1000, 60, 20}) {
      for (double seconds : {0.5, 10.0}) {
        const auto n = std::llround(seconds * static_cast<double>(rate));
        if (n > (scheme == "position_verlet" ? 293 : 2470)) continue;
        out.push_back({scheme, rate, seconds});
      }
    }
  }
  return out;
}

std::string fallName(const ::testing::TestParamInfo<FallCase>& info) {
  return info.param.scheme + "_" + std::to_string(info.param.rate) + "Hz_" +
         (info.param.seconds < 1.0 ? std::string("0_5s") : std::string("10s"));
}

class ObliqueFall : public ::testing::TestWithParam<FallCase> {};

// From rest at the origin, p(t) = a·t²/2 exactly for midpoint, both Verlets and RK4; explicit
// Euler lags by a·dt·t/2 (it moves with the velocity at the start of each tick) and
// semi-implicit Euler leads by as much, component by component, t = n·dt with dt the float step.
//
// Round-off: each tick's final additions round p by at most u·|p_k| and v by u·|v_k|; with
// |v_k| = |a|·k·dt and |p_k| = |a|·(k·dt)²/2 the position roundings sum to n·u·|p_T|/3 and the
// velocity roundings move the end position by as much again. The increments themselves (h·v,
// h·a, RK4's stages) are rounded at most 16 times a tick, each by u of h·|v_k| or h·|a|: at most
// 16·u·|p_T| through the position and 32·u·|p_T| through the velocity. So (2n/3 + 48)·u·|p_T|;
// position Verlet keeps its velocity as p − p_prev, every position rounding persists as a
// velocity error and they sum twice: (n²/6 + 48)·u·|p_T|.
TEST_P(ObliqueFall, EveryComponentIsTheSchemesClosedForm) {
  const FallCase& c = GetParam();
  const Vec a = fallAcceleration();
  ForceSet forces;
  forces.add(std::make_unique<Gravity>(narrow(a)));
  const auto ticks = std::llround(c.seconds * static_cast<double>(c.rate));
  const Trajectory run = runFloat(c.scheme, forces, {Body{}}, c.rate, ticks);

  const double h = stepOf(c.rate);
  const auto n = static_cast<double>(ticks);
  const double t = n * h;
  double offset = 0.0;
  if (c.scheme == "explicit_euler") offset = -h * t / 2.0;
  if (c.scheme == "semi_implicit_euler") offset = h * t / 2.0;
  const bool verlet = c.scheme == "position_verlet";
  const double factor = verlet ? n * n / 6.0 + 48.0 : 2.0 * n / 3.0 + 48.0;
  for (int k = 0; k < 3; ++k) {
    const double exact = a[k] * t * t / 2.0;
    const double firstOrder = std::abs(a[k]) * h * t / 2.0;
    const double tolerance = factor * kU * std::abs(exact);
    ASSERT_LE(tolerance, firstOrder / 4.0) << axisName(k) << ": fallCases() admits no such case";
    EXPECT_NEAR(run.p.back()[0][k], exact + a[k] * offset, tolerance)
        << axisName(k) << ": exact " << exact << " m, first-order error " << firstOrder << " m";
    // Velocity: a·t for every scheme but position Verlet, whose backward difference is the
    // velocity at t − dt/2. Its n additions round by at most n·u·|v_T|/2, its increments by
    // 16·u·|v_T|; position Verlet's difference of two positions by twice the position bound
    // over dt. Checked where that is under a quarter of the half-step lag |a|·dt/2.
    const double velocityTolerance =
        verlet ? 2.0 * tolerance / h : (n / 2.0 + 16.0) * kU * std::abs(a[k] * t);
    if (velocityTolerance < std::abs(a[k]) * h / 8.0) {
      EXPECT_NEAR(run.v.back()[0][k], a[k] * (verlet ? t - h / 2.0 : t), velocityTolerance)
          << axisName(k);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllSchemes, ObliqueFall, ::testing::ValuesIn(fallCases()), fallName);

// ---- the oscillator ----------------------------------------------------------------------------

// k = m = 1 anchored at the origin: each component is the study's oscillator, and every scheme
// is one 2×2 matrix S on (p, v) per component, read off its specification (h = dt, ω = 1):
//   explicit Euler        [[1, h], [−h, 1]]
//   semi-implicit Euler   [[1 − h², h], [−h, 1]]
//   midpoint              [[1 − h²/2, h], [−h + h³/2, 1 − h²]]   (second force at the new position)
//   position Verlet       its first step p1 = p0 + h·v0 − h²·p0/2, v1 = v0 − h·p0/2; then the
//                         semi-implicit matrix on (p_n, (p_n − p_{n−1})/h)
//   velocity Verlet       [[1 − h²/2, h], [−h·(1 − h²/4), 1 − h²/2]]
//   RK4                   [[c, s], [−s, c]], c = 1 − h²/2 + h⁴/24, s = h − h³/6
using Matrix2 = std::array<double, 4>;  // row-major

Matrix2 stepMatrix(const std::string& scheme, double h) {
  if (scheme == "explicit_euler") return {1.0, h, -h, 1.0};
  if (scheme == "semi_implicit_euler" || scheme == "position_verlet") {
    return {1.0 - h * h, h, -h, 1.0};
  }
  if (scheme == "midpoint") return {1.0 - h * h / 2.0, h, -h + h * h * h / 2.0, 1.0 - h * h};
  if (scheme == "velocity_verlet") {
    return {1.0 - h * h / 2.0, h, -h * (1.0 - h * h / 4.0), 1.0 - h * h / 2.0};
  }
  const double c = 1.0 - h * h / 2.0 + h * h * h * h / 24.0, s = h - h * h * h / 6.0;
  return {c, s, -s, c};
}

Trajectory oscillatorClosedForm(const std::string& scheme, const Body& b, std::int64_t rate,
                                std::int64_t ticks) {
  const double h = stepOf(rate);
  const Matrix2 m = stepMatrix(scheme, h);
  Trajectory out{{{b.p}}, {{b.v}}};
  Vec p = b.p, v = b.v;
  for (std::int64_t k = 0; k < ticks; ++k) {
    if (scheme == "position_verlet" && k == 0) {
      const Vec p1 = p + h * v - h * h / 2.0 * p;
      v = (p1 - p) / h;
      p = p1;
    } else {
      const Vec np = m[0] * p + m[1] * v;
      v = m[2] * p + m[3] * v;
      p = np;
    }
    out.p.push_back({p});
    out.v.push_back({v});
  }
  return out;
}

struct OscillatorCase {
  std::string scheme;
  std::int64_t rate;  // 20 Hz or 4 Hz, as the study
  bool ellipse;       // false: along ê from −ê at rest; true: an ellipse across the axes
};

void PrintTo(const OscillatorCase& c, std::ostream* os) {
  *os << c.scheme << " at " << c.rate << " Hz, " << (c.ellipse ? "ellipse" : "along ê");
}

std::vector<OscillatorCase> oscillatorCases() {
  std::vector<OscillatorCase> out;
  for (const std::string& scheme : integratorNames()) {
    for (std::int64_t rate : {20, 4}) {
      for (bool ellipse : {false, true}) out.push_back({scheme, rate, ellipse});
    }
  }
  return out;
}

std::string oscillatorName(const ::testing::TestParamInfo<OscillatorCase>& info) {
  return info.param.scheme + "_" + std::to_string(info.param.rate) + "Hz_" +
         (info.param.ellipse ? "ellipse" : "axis");
}

class ObliqueOscillator : public ::testing::TestWithParam<OscillatorCase> {};

// 20 s, the study's run. The expected state is S^n applied to each component's own start; the
// tolerance is ObliqueTestSupport's round-off bound, carried by the scheme's own propagator (it
// grows with explicit Euler's amplitude, (1 + h²)^(n/2), and as n² for position Verlet), and
// must stay under a tenth of the distance each component moved from where free motion would be.
TEST_P(ObliqueOscillator, EveryComponentFollowsTheSchemesStepMatrix) {
  const OscillatorCase& c = GetParam();
  Body b;
  if (c.ellipse) {
    b.p = floats(-0.75f, 0.5f, 0.25f);
    b.v = floats(0.25f, 0.5f, -0.625f);
  } else {
    const Vec e = Vec(2.0, -3.0, 6.0) / 7.0;
    b.p =
        floats(static_cast<float>(-e.x()), static_cast<float>(-e.y()), static_cast<float>(-e.z()));
  }
  ForceSet forces;
  forces.add(std::make_unique<AnchorSpring>(Eigen::Vector3f::Zero(), 1.0f));
  const Accel accel = [](const std::vector<Vec>& p, const std::vector<Vec>&, double) {
    return std::vector<Vec>{-p[0]};
  };
  const std::int64_t ticks = 20 * c.rate;
  const Trajectory run = runFloat(c.scheme, forces, {b}, c.rate, ticks);
  const Trajectory want = oscillatorClosedForm(c.scheme, b, c.rate, ticks);
  // |p| and |v| stay below the amplitude, which explicit Euler grows to 11× at 4 Hz: the force's
  // terms are bounded by the trajectory itself (F = max |a| = max |p|).
  const Tolerances tol = roundOffTolerances(c.scheme, accel, {b}, c.rate, ticks, 0.0);
  const double seconds = static_cast<double>(ticks) * stepOf(c.rate);
  ASSERT_TRUE(toleranceBelowEffect(tol, effectOf({b}, want.p.back(), want.v.back(), seconds), 0.1));
  EXPECT_TRUE(followsWithin(run, want, tol));
}

INSTANTIATE_TEST_SUITE_P(AllSchemes, ObliqueOscillator, ::testing::ValuesIn(oscillatorCases()),
                         oscillatorName);

// The closed forms above and ObliqueTestSupport's recurrences are written independently: they
// agree to double round-off, so neither carries a slip the other does not.
TEST(ObliqueOscillatorReference, StepMatricesAreTheSchemesRecurrences) {
  Body b;
  b.p = floats(-0.75f, 0.5f, 0.25f);
  b.v = floats(0.25f, 0.5f, -0.625f);
  const Accel accel = [](const std::vector<Vec>& p, const std::vector<Vec>&, double) {
    return std::vector<Vec>{-p[0]};
  };
  for (const std::string& scheme : integratorNames()) {
    const Trajectory closed = oscillatorClosedForm(scheme, b, 20, 400);
    const Trajectory recurrence = runReference(scheme, accel, {b}, 20, 400);
    for (std::size_t k = 0; k < closed.p.size(); ++k) {
      // 400 ticks of a few roundings of 2^-53 on values below 2 (explicit Euler's amplitude
      // grows to 1.65): under 1e-12.
      ASSERT_LT((closed.p[k][0] - recurrence.p[k][0]).cwiseAbs().maxCoeff(), 1e-12)
          << scheme << ", tick " << k;
      ASSERT_LT((closed.v[k][0] - recurrence.v[k][0]).cwiseAbs().maxCoeff(), 1e-12)
          << scheme << ", tick " << k;
    }
  }
}

}  // namespace
}  // namespace tickfx::oblique
