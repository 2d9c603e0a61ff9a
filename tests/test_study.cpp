// The integrator study's figures against closed-form values: the exact solutions of the three
// experiments, and the exact solutions of each scheme's own recurrence where those have a closed
// form (Euler's error for constant acceleration, the oscillator's step matrices, a sampled sine's
// quadrature factors). Tolerances are float round-off bounds derived below, not fitted numbers.
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

#include "app/IntegratorStudy.h"
#include "integrators/Integrator.h"

namespace tickfx {
namespace {

constexpr double kPi = std::numbers::pi;
const std::vector<std::int64_t> kRates{1000, 144, 60, 30, 20};

const StudyResults& study() {
  static const StudyResults results = runIntegratorStudy();
  return results;
}

// The step the integrators really take: 1/rate rounded to float once (StepTime::dt()).
double floatDt(std::int64_t rate) { return StepTime{0, rate}.dt(); }

double ulp(double x) {
  const float f = std::abs(static_cast<float>(x));
  return static_cast<double>(std::nextafter(f, INFINITY)) - static_cast<double>(f);
}

// Worst-case float round-off of `ticks` explicit updates: each tick rounds the position (half an
// ulp of the largest |p|) and the velocity (half an ulp of the largest |v|), and a velocity error
// moves the position for at most `duration` seconds. Doubled for the rounding of the products.
double roundOffBound(std::int64_t ticks, double duration, double maxPosition, double maxVelocity) {
  return static_cast<double>(ticks) * (ulp(maxPosition) + duration * ulp(maxVelocity));
}

// Position Verlet holds the velocity as a difference of positions, so every position rounding is
// also a velocity error that persists to the end: the bound grows with ticks².
double positionHistoryRoundOffBound(std::int64_t ticks, double duration, double maxPosition,
                                    double maxVelocity) {
  const double n = static_cast<double>(ticks);
  return n * n * ulp(maxPosition) / 2.0 + roundOffBound(ticks, duration, maxPosition, maxVelocity);
}

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
    EXPECT_EQ(r.error, r.position - r.exact);
  }
}

TEST(IntegratorStudy, ExactSolutions) {
  EXPECT_DOUBLE_EQ(exactConstantAccelerationPosition(10.0), -490.5);
  EXPECT_DOUBLE_EQ(exactConstantAccelerationPosition(0.5), -1.22625);
  EXPECT_NEAR(exactOscillatorPosition(20.0), -std::cos(20.0), 1e-15);
  EXPECT_NEAR(exactOscillatorVelocity(20.0), std::sin(20.0), 1e-15);
  // Over whole periods the sine term vanishes: p = 150·T/(2πf).
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

TEST(IntegratorStudy, IsDeterministic) {
  const StudyResults again = runIntegratorStudy();
  EXPECT_EQ(constantAccelerationCsv(again), constantAccelerationCsv(study()));
  EXPECT_EQ(oscillatorCsv(again), oscillatorCsv(study()));
  EXPECT_EQ(windCsv(again), windCsv(study()));
}

// ---- experiment 1: constant acceleration -------------------------------------------------------

// Explicit Euler moves with the velocity at the start of each tick and lags |a|·dt·T/2 behind;
// semi-implicit Euler moves with the velocity at the end and leads by as much.
TEST(IntegratorStudyConstantAcceleration, EulerErrorIsHalfOfADtWorthOfVelocity) {
  for (std::int64_t rate : kRates) {
    for (double t : {0.5, 10.0}) {
      const double lag = 9.81 * floatDt(rate) * t / 2.0;
      const double bound = roundOffBound(ticksOf(t, rate), t, 0.5 * 9.81 * t * t, 9.81 * t);
      const auto& explicitEuler = fall("explicit_euler", rate, t);
      const auto& semiImplicit = fall("semi_implicit_euler", rate, t);
      EXPECT_NEAR(explicitEuler.error, lag, bound) << rate << " Hz, " << t << " s";
      EXPECT_NEAR(semiImplicit.error, -lag, bound) << rate << " Hz, " << t << " s";
    }
  }
}

TEST(IntegratorStudyConstantAcceleration, ExplicitEulerAt20HzIsOff2_4525mAfter10s) {
  const auto& r = fall("explicit_euler", 20, 10.0);
  EXPECT_DOUBLE_EQ(r.exact, -490.5);
  // 200 ticks at |p| <= 490.5 m, |v| <= 98.1 m/s: about 0.02 m of float round-off at most.
  EXPECT_NEAR(r.error, 2.4525, roundOffBound(200, 10.0, 490.5, 98.1));
  EXPECT_NEAR(fall("explicit_euler", 20, 0.5).error, 0.122625, roundOffBound(10, 0.5, 1.3, 4.9));
}

// For a constant force these schemes are exact in real arithmetic: what is left is round-off.
TEST(IntegratorStudyConstantAcceleration, SecondOrderAndRk4AreExactUpToRoundOff) {
  for (const char* name : {"midpoint", "velocity_verlet", "rk4"}) {
    for (std::int64_t rate : kRates) {
      for (double t : {0.5, 10.0}) {
        const auto& r = fall(name, rate, t);
        EXPECT_NEAR(r.error, 0.0, roundOffBound(ticksOf(t, rate), t, -r.exact, 9.81 * t))
            << name << ' ' << rate << " Hz, " << t << " s";
      }
    }
  }
}

// Position Verlet is exact in real arithmetic too, but its round-off grows with ticks², so the
// check is made only where that bound is still below the first-order error it must beat.
TEST(IntegratorStudyConstantAcceleration, PositionVerletIsExactUpToRoundOffWhereThatIsResolvable) {
  int checked = 0;
  for (std::int64_t rate : kRates) {
    for (double t : {0.5, 10.0}) {
      const auto& r = fall("position_verlet", rate, t);
      const double bound = positionHistoryRoundOffBound(ticksOf(t, rate), t, -r.exact, 9.81 * t);
      if (bound >= 9.81 * floatDt(rate) * t / 2.0) continue;
      EXPECT_NEAR(r.error, 0.0, bound) << rate << " Hz, " << t << " s";
      ++checked;
    }
  }
  EXPECT_GE(checked, 6);
}

// ---- experiment 2: harmonic oscillator ---------------------------------------------------------

// Each one-step scheme is a fixed 2×2 matrix on (p, v) for this force; its n-th power in double
// is what the float run must reproduce.
using Matrix2 = std::array<double, 4>;  // row-major

Matrix2 stepMatrix(const std::string& name, double h) {
  if (name == "explicit_euler") return {1.0, h, -h, 1.0};
  if (name == "semi_implicit_euler") return {1.0 - h * h, h, -h, 1.0};
  if (name == "velocity_verlet") {
    return {1.0 - h * h / 2.0, h, -h * (1.0 - h * h / 4.0), 1.0 - h * h / 2.0};
  }
  if (name == "rk4") {
    const double c = 1.0 - h * h / 2.0 + h * h * h * h / 24.0, s = h - h * h * h / 6.0;
    return {c, s, -s, c};
  }
  throw std::logic_error("no step matrix for " + name);
}

std::array<double, 2> discreteOscillator(const std::string& name, std::int64_t rate) {
  const Matrix2 m = stepMatrix(name, floatDt(rate));
  std::array<double, 2> x{-1.0, 0.0};
  for (std::int64_t k = 0; k < ticksOf(20.0, rate); ++k) {
    x = {m[0] * x[0] + m[1] * x[1], m[2] * x[0] + m[3] * x[1]};
  }
  return x;
}

TEST(IntegratorStudyOscillator, OneStepSchemesFollowTheirStepMatrices) {
  for (const char* name : {"explicit_euler", "semi_implicit_euler", "velocity_verlet", "rk4"}) {
    for (std::int64_t rate : {20, 4}) {
      const auto [p, v] = discreteOscillator(name, rate);
      const auto& r = spring(name, rate);
      // Relative round-off of n ticks: each rounds p and v once or twice (2^-24 each).
      const double amplitude = std::sqrt(p * p + v * v);
      const double tol = 4.0 * static_cast<double>(ticksOf(20.0, rate)) * 0x1p-24 * amplitude;
      EXPECT_NEAR(r.position, p, tol) << name << ' ' << rate << " Hz";
      EXPECT_NEAR(r.velocity, v, tol) << name << ' ' << rate << " Hz";
    }
  }
}

// [[1, h], [−h, 1]] scales p² + v² by 1 + h² every tick.
TEST(IntegratorStudyOscillator, ExplicitEulerEnergyGrowsAsOnePlusDtSquaredPerTick) {
  for (std::int64_t rate : {20, 4}) {
    const double h = floatDt(rate);
    const auto n = static_cast<double>(ticksOf(20.0, rate));
    const double expected = 0.5 * std::pow(1.0 + h * h, n);
    EXPECT_NEAR(spring("explicit_euler", rate).energy, expected, 4.0 * n * 0x1p-24 * expected);
  }
  EXPECT_NEAR(spring("explicit_euler", 20).energy, 1.357446, 1e-5);
  EXPECT_NEAR(spring("explicit_euler", 4).energy, 63.868, 1e-2);
}

// The symplectic schemes conserve a nearby quadratic form, so the energy stays in a band set by
// dt instead of drifting: semi-implicit Euler keeps p² + v² − h·p·v, velocity Verlet keeps
// v² + (1 − h²/4)·p².
TEST(IntegratorStudyOscillator, SymplecticSchemesKeepTheEnergyInABand) {
  constexpr double slop = 1e-5;  // float round-off of 400 ticks, relative to 0.5 J
  for (std::int64_t rate : {20, 4}) {
    const double h = floatDt(rate);
    const double semi = spring("semi_implicit_euler", rate).energy;
    EXPECT_GE(semi, 0.5 / (1.0 + h / 2.0) - slop) << rate << " Hz";
    EXPECT_LE(semi, 0.5 / (1.0 - h / 2.0) + slop) << rate << " Hz";
    const double verlet = spring("velocity_verlet", rate).energy;
    EXPECT_GE(verlet, 0.5 - h * h / 8.0 - slop) << rate << " Hz";
    EXPECT_LE(verlet, 0.5 + slop) << rate << " Hz";
  }
}

TEST(IntegratorStudyOscillator, VelocityVerletIsSecondOrderAndRk4FourthOrder) {
  const double vv20 = spring("velocity_verlet", 20).error, vv4 = spring("velocity_verlet", 4).error;
  EXPECT_NEAR(vv4 / vv20, 25.0, 2.5);  // dt five times longer, error 5² times larger
  EXPECT_LT(std::abs(vv20), 2.5e-3);
  // RK4 drifts in phase by about T·dt⁴/120 rad: 6.5e-4 rad at 4 Hz, 1e-6 rad at 20 Hz (where
  // float round-off is larger).
  EXPECT_LT(std::abs(spring("rk4", 4).error), 6.5e-4);
  EXPECT_LT(std::abs(spring("rk4", 20).error), 5e-6);
  EXPECT_NEAR(spring("rk4", 20).energy, 0.5, 5e-6);
}

// The midpoint scheme as specified evaluates the second force at the end-of-step position, which
// makes it first order when the force depends on position: on the spring its error only halves
// when dt halves, and its energy decays every step. (For forces of time alone it is second order:
// see the wind tests.)
TEST(IntegratorStudyOscillator, MidpointIsFirstOrderOnASpringAndLosesEnergy) {
  const OscillatorResult r20 = runOscillator("midpoint", 20, 20.0);
  const OscillatorResult r40 = runOscillator("midpoint", 40, 20.0);
  const OscillatorResult r80 = runOscillator("midpoint", 80, 20.0);
  EXPECT_NEAR(std::log2(std::abs(r20.error / r40.error)), 1.0, 0.1);
  EXPECT_NEAR(std::log2(std::abs(r40.error / r80.error)), 1.0, 0.1);
  EXPECT_LT(r20.energy, r40.energy);
  EXPECT_LT(r40.energy, r80.energy);
  EXPECT_LT(r80.energy, 0.5);
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

TEST(IntegratorStudyWind, DriftIsTheExactDriftTimesTheSchemesQuadratureFactor) {
  for (const std::string& name : integratorNames()) {
    for (std::int64_t rate : kRates) {
      for (double f : {4.0, 16.0}) {
        const auto& r = gust(name, rate, f);
        const double omega = 2.0 * kPi * f;
        const double factor = windFactor(name, omega * floatDt(rate));
        // Largest |p| and |v| on the way, doubled for the ripple between whole periods.
        const double maxV = 2.0 * std::abs(factor) * 2.0 * 150.0 / omega;
        const double maxP = 2.0 * std::abs(factor) * 150.0 / omega * (2.0 + 1.0 / omega);
        EXPECT_NEAR(r.position, factor * r.exact,
                    roundOffBound(ticksOf(2.0, rate), 2.0, maxP, maxV))
            << name << ' ' << rate << " Hz, f = " << f << " Hz";
      }
    }
  }
}

// 16 Hz sampled at 20 Hz is indistinguishable from a 4 Hz wind of the opposite sign, so a particle
// that should drift 2.98 m forward is carried 10.32 m backward.
TEST(IntegratorStudyWind, SixteenHertzAt20HzIsCarriedBackwards) {
  const auto& r = gust("velocity_verlet", 20, 16.0);
  EXPECT_NEAR(r.exact, 2.984155, 1e-6);
  EXPECT_NEAR(r.position, -10.3229, 1e-3);
  EXPECT_LT(r.error, -13.0);
  EXPECT_NEAR(r.position, -gust("velocity_verlet", 20, 4.0).position, 1e-5);
  // Still below Nyquist at 60 Hz: a quarter short, but forward.
  EXPECT_GT(gust("velocity_verlet", 60, 16.0).position, 0.7 * r.exact);
}

TEST(IntegratorStudyWind, FourHertzStaysCloseForVelocityVerlet) {
  for (std::int64_t rate : kRates) {
    const auto& r = gust("velocity_verlet", rate, 4.0);
    EXPECT_NEAR(r.exact, 11.936621, 1e-6);
    EXPECT_LT(std::abs(r.error) / r.exact, 0.14) << rate << " Hz";  // 13.5 % short at 20 Hz
    if (rate >= 60) {
      EXPECT_LT(std::abs(r.error) / r.exact, 0.015) << rate << " Hz";
    }
  }
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
