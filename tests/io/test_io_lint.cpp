// Lint warnings: their messages and numbers, and that the limits they quote are the core's.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "integrators/Integrator.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectLint.h"
#include "io/effect/EffectParser.h"

namespace tickfx::io {
namespace {

using Lines = std::vector<std::string>;

EffectSettings load(const std::string& text) {
  const LoadResult result = parseEffect(text, "lint.toml");
  EXPECT_TRUE(result.ok()) << (result.diagnostics.empty() ? "" : result.diagnostics[0].format());
  return result.ok() ? *result.effect : EffectSettings{};
}

Lines warnings(const std::string& text) {
  Lines out;
  for (const Diagnostic& d : lintEffect(load(text))) {
    EXPECT_EQ(d.severity, Severity::Warning);
    out.push_back(d.format());
  }
  return out;
}

std::string windEffect(int stepRate, double frequency) {
  return "format_version = 1\n"
         "[simulation]\n"
         "step_rate = " +
         std::to_string(stepRate) +
         "\n"
         "[[emitters]]\n"
         "bursts = [{ time = 0.0, count = 1 }]\n"
         "[[forces]]\n"
         "type = \"wind\"\n"
         "amplitude = 150.0\n"
         "frequency = " +
         std::to_string(frequency) + "\n";
}

// One particle of `mass` kg at x = −1 on a spring anchored at the origin (the oscillator).
std::string springEffect(const std::string& integrator, int stepRate, double stiffness,
                         double damping = 0.0, double mass = 1.0, double seconds = 10.0) {
  return "format_version = 1\n"
         "[simulation]\n"
         "step_rate = " +
         std::to_string(stepRate) +
         "\n"
         "integrator = \"" +
         integrator +
         "\"\n"
         "[[emitters]]\n"
         "position = [-1.0, 0.0, 0.0]\n"
         "bursts = [{ time = 0.0, count = 1 }]\n"
         "mass = " +
         std::to_string(mass) +
         "\n"
         "[[forces]]\n"
         "type = \"anchor_spring\"\n"
         "stiffness = " +
         std::to_string(stiffness) +
         "\n"
         "damping = " +
         std::to_string(damping) +
         "\n"
         "[output]\n"
         "seconds = " +
         std::to_string(seconds) + "\n";
}

TEST(ioLint, NyquistWarningNamesTheStepRateNeeded) {
  // The seed's example: 16 Hz wind at 20 Hz is sampled as a 4 Hz wind.
  EXPECT_EQ(
      warnings(windEffect(20, 16.0)),
      (Lines{"lint.toml:9:13: warning: forces.0.frequency: 16 Hz wind is above the Nyquist "
             "limit of 10 Hz (half of step_rate = 20 Hz) and is sampled as a 4 Hz wind (use a "
             "step_rate of at least 33 Hz)"}));
  // Exactly at the limit still aliases (two samples per period see a constant).
  EXPECT_EQ(
      warnings(windEffect(20, 10.0)),
      (Lines{"lint.toml:9:13: warning: forces.0.frequency: 10 Hz wind is at the Nyquist limit "
             "of 10 Hz (half of step_rate = 20 Hz) and is sampled as a 10 Hz wind (use a "
             "step_rate of at least 21 Hz)"}));
  // A fractional frequency: the smallest integer step rate above 2f.
  EXPECT_EQ(
      warnings(windEffect(30, 16.3)),
      (Lines{"lint.toml:9:13: warning: forces.0.frequency: 16.3 Hz wind is above the Nyquist "
             "limit of 15 Hz (half of step_rate = 30 Hz) and is sampled as a 13.7 Hz wind (use "
             "a step_rate of at least 33 Hz)"}));
  EXPECT_TRUE(warnings(windEffect(33, 16.0)).empty());
  EXPECT_TRUE(warnings(windEffect(240, 16.0)).empty());
  EXPECT_TRUE(warnings(windEffect(20, 0.0)).empty());  // a constant wind
}

TEST(ioLint, AliasedWindPushesTheWrongWay) {
  // What the warning is about, in the core: with phase 0 the true wind's impulse is positive
  // over the first half period, so the particle drifts to +x; sampled at 20 Hz the 16 Hz sine
  // is a −4 Hz one and the particle drifts to −x.
  const auto drift = [](int stepRate) {
    const std::unique_ptr<ParticleSystem> system = buildSystem(load(windEffect(stepRate, 16.0)));
    system->stepTicks(stepRate);  // one second
    return system->pool().position().x[0];
  };
  EXPECT_LT(drift(20), 0.0f);
  EXPECT_GT(drift(240), 0.0f);
}

TEST(ioLint, ExplicitEulerSpringGainsEnergy) {
  EXPECT_EQ(
      warnings(springEffect("explicit_euler", 60, 1.0)),
      (Lines{"lint.toml:11:13: warning: forces.0.stiffness: explicit_euler adds energy to this "
             "spring every step (x1.000278 per step, x1.18 over the 10 s of output) (use "
             "semi_implicit_euler, position_verlet or velocity_verlet, damping of at least "
             "0.01667 N·s/m (k·dt), or a step_rate of at least 1005 Hz to keep the gain over "
             "the output under 1%)"}));
  // Damping of at least k·dt cancels the gain: nothing to say.
  EXPECT_TRUE(warnings(springEffect("explicit_euler", 60, 1.0, 1.0 / 60.0 + 1e-9)).empty());
  // Already fast enough for 1 % over the output: the warning keeps the other fixes only.
  EXPECT_EQ(
      warnings(springEffect("explicit_euler", 2000, 1.0)),
      (Lines{"lint.toml:2:1: warning: simulation.max_ticks_per_frame: a real-time host advancing "
             "at the output's 24 fps needs up to 84 ticks a frame at 2000 Hz, more than "
             "max_ticks_per_frame = 16, and would drop ticks (`tickfx run` runs them all; use a "
             "max_ticks_per_frame of at least 84 or a step_rate of at most 384 Hz)",
             "lint.toml:11:13: warning: forces.0.stiffness: explicit_euler adds energy to this "
             "spring every step (x1.00000025 per step, x1.01 over the 10 s of output) (use "
             "semi_implicit_euler, position_verlet or velocity_verlet, damping of at least "
             "0.0005 N·s/m (k·dt))"}));
}

TEST(ioLint, MidpointUndampedSpringLosesEnergy) {
  EXPECT_EQ(
      warnings(springEffect("midpoint", 60, 1.0)),
      (Lines{"lint.toml:11:13: warning: forces.0.stiffness: midpoint removes energy from this "
             "undamped spring every step (x0.9998611 per step, x0.92 over the 10 s of output) "
             "(use semi_implicit_euler, position_verlet or velocity_verlet, or a step_rate of "
             "at least 498 Hz to keep the loss over the output under 1%)"}));
  // A damped spring loses energy anyway: the scheme's share is not worth a warning.
  EXPECT_TRUE(warnings(springEffect("midpoint", 60, 1.0, 0.1)).empty());
}

TEST(ioLint, SpringPastTheStabilityLimitNamesTheStepRate) {
  // ω = √(k/m) with the lightest mass: k = 100, m = 0.25 → ω = 20 rad/s; at 8 Hz ω·dt = 2.5.
  EXPECT_EQ(
      warnings(springEffect("velocity_verlet", 8, 100.0, 0.0, 0.25)),
      (Lines{"lint.toml:11:13: warning: forces.0.stiffness: omega*dt = 2.5 is past "
             "velocity_verlet's stability limit of 2 (omega = sqrt(k/m) = 20 rad/s for the "
             "lightest mass, 0.25 kg, and dt = 1/8 s): the spring's motion grows without bound "
             "(use a step_rate of at least 11 Hz)"}));
  EXPECT_TRUE(warnings(springEffect("velocity_verlet", 11, 100.0, 0.0, 0.25)).empty());
  EXPECT_EQ(
      warnings(springEffect("rk4", 7, 400.0)),
      (Lines{"lint.toml:11:13: warning: forces.0.stiffness: omega*dt = 2.857 is past rk4's "
             "stability limit of 2.785 (omega = sqrt(k/m) = 20 rad/s for the lightest mass, 1 "
             "kg, and dt = 1/7 s): the spring's motion grows without bound (use a step_rate of "
             "at least 8 Hz)"}));
  // Midpoint past √2: the stability warning replaces the energy one.
  const Lines midpoint = warnings(springEffect("midpoint", 10, 400.0));
  ASSERT_EQ(midpoint.size(), 1u);
  EXPECT_NE(midpoint[0].find("past midpoint's stability limit of 1.414"), std::string::npos);
  EXPECT_NE(midpoint[0].find("(use a step_rate of at least 15 Hz)"), std::string::npos);
  // The lightest of several emitters' masses decides.
  EffectSettings two = load(springEffect("semi_implicit_euler", 60, 1.0));
  two.emitters.push_back(two.emitters[0]);
  two.emitters[1].name = "light";
  two.emitters[1].mass = 1e-4;  // ω = 100 rad/s, ω·dt = 1.67: fine
  EXPECT_TRUE(lintEffect(two).empty());
  two.emitters[1].mass = 1e-5;  // ω = 316 rad/s, ω·dt = 5.3
  const std::vector<Diagnostic> light = lintEffect(two);
  ASSERT_EQ(light.size(), 1u);
  EXPECT_NE(light[0].message.find("(use a step_rate of at least 159 Hz)"), std::string::npos);
}

// The oscillator with a second anchor spring of the same stiffness and damping, at the same rest
// point: every anchor spring pulls on every particle, so the two act as one of twice the
// stiffness.
std::string twoSpringEffect(const std::string& integrator, int stepRate, double stiffness,
                            double damping = 0.0) {
  return springEffect(integrator, stepRate, stiffness, damping) +
         "[[forces]]\n"
         "type = \"anchor_spring\"\n"
         "stiffness = " +
         std::to_string(stiffness) +
         "\n"
         "damping = " +
         std::to_string(damping) + "\n";
}

TEST(ioLint, AnchorSpringsOnTheSameParticlesAddUp) {
  // Each spring alone: ω = √(10000/1) = 100 rad/s, ω·dt = 1.67 at 60 Hz, under the limit of 2.
  EXPECT_TRUE(warnings(springEffect("semi_implicit_euler", 60, 10000.0)).empty());
  // Together: k = 20000 N/m, ω = 141.4 rad/s, ω·dt = 2.36, and ⌊141.4 / 2⌋ + 1 = 71 Hz.
  EXPECT_EQ(
      warnings(twoSpringEffect("semi_implicit_euler", 60, 10000.0)),
      (Lines{"lint.toml:11:13: warning: forces.0.stiffness: omega*dt = 2.357 is past "
             "semi_implicit_euler's stability limit of 2 (omega = sqrt(k/m) = 141.4 rad/s with k "
             "= 20000 N/m, the stiffnesses of the anchor springs forces.0 and forces.1 added up "
             "(each pulls on every particle), for the lightest mass, 1 kg, and dt = 1/60 s): the "
             "springs' motion grows without bound (use a step_rate of at least 71 Hz)"}));
  EXPECT_TRUE(warnings(twoSpringEffect("semi_implicit_euler", 71, 10000.0)).empty());
  // What the warning says, in the core: past the limit together the particle flies off; at the
  // step rate the warning names it stays on the springs, within semi-implicit Euler's largest
  // excursion from x0 = −1 at rest, 1 / √(1 − (ω·dt/2)²) = 11.09 this close to the limit.
  const auto largest = [](int stepRate) {
    const std::unique_ptr<ParticleSystem> system =
        buildSystem(load(twoSpringEffect("semi_implicit_euler", stepRate, 10000.0)));
    float most = 0.0f;
    for (int i = 0; i < 300; ++i) {
      system->step();
      most = std::max(most, std::abs(system->pool().position().x[0]));
    }
    return most;
  };
  EXPECT_FALSE(largest(60) < 1e6f);
  const double omegaDt = std::sqrt(20000.0) / 71.0;
  EXPECT_LT(largest(71), 1.001 / std::sqrt(1.0 - omegaDt * omegaDt / 4.0));
  // The energy drift is judged on the sum too: k = 2 N/m, c = 0 for explicit Euler at 60 Hz.
  EXPECT_EQ(
      warnings(twoSpringEffect("explicit_euler", 60, 1.0)),
      (Lines{"lint.toml:11:13: warning: forces.0.stiffness: explicit_euler adds energy to the "
             "anchor springs forces.0 and forces.1 every step (k = 2 N/m and c = 0 N·s/m added "
             "up: each pulls on every particle) (x1.000556 per step, x1.4 over the 10 s of "
             "output) (use semi_implicit_euler, position_verlet or velocity_verlet, damping of at "
             "least 0.03333 N·s/m (k·dt, in all), or a step_rate of at least 2010 Hz to keep the "
             "gain over the output under 1%)"}));
  // Damping of k·dt in all, split over the two springs, cancels the gain.
  EXPECT_TRUE(warnings(twoSpringEffect("explicit_euler", 60, 1.0, 1.0 / 60.0 + 1e-9)).empty());
}

TEST(ioLint, StabilityLimitsAreTheCoresOwn) {
  // Each documented limit, checked against the integrator itself: the oscillator stays bounded
  // at 0.95 × the limit and grows at 1.05 × the limit.
  for (const std::string& integrator : integratorNames()) {
    const std::optional<double> limit = springStabilityLimit(integrator);
    if (!limit) continue;
    for (const double factor : {0.95, 1.05}) {
      const int rate = 60;
      const double omega = factor * *limit * rate;
      const std::unique_ptr<ParticleSystem> system =
          buildSystem(load(springEffect(integrator, rate, omega * omega)));
      float largest = 0.0f;
      for (int i = 0; i < 300; ++i) {
        system->step();
        largest = std::max(largest, std::abs(system->pool().position().x[0]));
      }
      if (factor < 1.0) {
        EXPECT_LT(largest, 10.0f) << integrator << " below its limit";
      } else {
        EXPECT_FALSE(largest < 1e6f) << integrator << " above its limit";
      }
    }
  }
  EXPECT_FALSE(springStabilityLimit("explicit_euler").has_value());
}

TEST(ioLint, PredictedEnergyDriftIsTheCoresOwn) {
  // The factors the drift warnings quote (x1.18 for explicit Euler, x0.92 for midpoint over 10 s
  // at 60 Hz, ω = 1), against the core. The spring is linear, so the phase-space area spanned by
  // two particles' states (x, v) is multiplied by exactly the step matrix's determinant each
  // tick: that determinant is the energy factor of a complex eigenvalue pair, |λ|².
  const auto areaRatio = [](const std::string& integrator) {
    const std::string text = springEffect(integrator, 60, 1.0) +
                             "[[emitters]]\n"
                             "name = \"moving\"\n"
                             "direction = [1.0, 0.0, 0.0]\n"
                             "speed = 1.0\n"
                             "bursts = [{ time = 0.0, count = 1 }]\n";
    const std::unique_ptr<ParticleSystem> system = buildSystem(load(text));
    system->stepTicks(600);
    const auto& p = system->pool().position().x;
    const auto& v = system->pool().velocity().x;
    // Initially (x, v) = (−1, 0) and (0, 1): area −1.
    return -(static_cast<double>(p[0]) * v[1] - static_cast<double>(p[1]) * v[0]);
  };
  EXPECT_NEAR(areaRatio("explicit_euler"), std::pow(1.0 + 1.0 / 3600.0, 600), 1e-4);
  EXPECT_NEAR(areaRatio("midpoint"), std::pow(1.0 - 1.0 / 7200.0, 600), 1e-4);
}

TEST(ioLint, SettingsWithoutSourcesStillFormat) {
  EffectSettings e = load(windEffect(20, 16.0));
  e.sources = SourceMap{};  // settings made in code
  const std::vector<Diagnostic> w = lintEffect(e);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].file, "<effect>");
  EXPECT_EQ(w[0].line, 0);
  EXPECT_EQ(w[0].format().rfind("<effect>: warning: forces.0.frequency: 16 Hz wind", 0), 0u);
}

}  // namespace
}  // namespace tickfx::io
