// The integrator study: three small experiments with closed-form answers, run through every
// integrator at the step rates an effect may use, so the error of each scheme can be read off a
// table instead of argued about.
//
// Units throughout: seconds (s), metres (m), metres per second (m/s), m/s² for accelerations,
// hertz (Hz) for step rates and wind frequencies, joules (J) for energy (the particle has 1 kg).
// The simulations run in float exactly as the library runs them; the exact values are computed
// in double; the simulated values are widened to double only for reporting.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>
#include "fields/ForceSet.h"

namespace tickfx {

/// Acceleration of the constant-acceleration experiment (m/s², along x).
inline constexpr double kStudyGravity = -9.81;
/// Oscillator experiment: stiffness (N/m), mass (kg), start position (m) and velocity (m/s).
/// The exact motion is p(t) = −cos t, v(t) = sin t, with energy 0.5 J at all times.
inline constexpr double kStudySpringStiffness = 1.0;
inline constexpr double kStudyMass = 1.0;
inline constexpr double kStudyOscillatorStart = -1.0;
/// Oscillator energy of the exact solution (J): ½·k·p0².
inline constexpr double kStudyOscillatorEnergy = 0.5;
/// Amplitude of the wind experiment's acceleration 150·sin(2π·f·t) (m/s², along x).
inline constexpr double kStudyWindAmplitude = 150.0;

/// What the study runs. The defaults are the published study; every time must be a whole number
/// of ticks at every rate it is used with (runIntegratorStudy throws std::invalid_argument if not).
struct StudyPlan {
  /// Integrator names (see integratorNames()); empty means all of them, in the registry's order.
  std::vector<std::string> integrators;
  /// Step rates (Hz) of the constant-acceleration and wind experiments: dt = 1/rate.
  std::vector<std::int64_t> stepRatesHz{1000, 144, 60, 30, 20};
  /// Times (s) at which the falling particle is sampled (one run to the latest of them).
  std::vector<double> gravitySampleTimes{0.5, 10.0};
  /// Step rates (Hz) of the oscillator experiment: dt = 1/20 s and 1/4 s.
  std::vector<std::int64_t> oscillatorStepRatesHz{20, 4};
  /// How long the oscillator runs (s).
  double oscillatorDuration = 20.0;
  /// Wind frequencies f (Hz).
  std::vector<double> windFrequenciesHz{4.0, 16.0};
  /// How long the wind blows (s).
  double windDuration = 2.0;
};

/// One sample of the constant-acceleration experiment: from rest at the origin under
/// kStudyGravity, against p(t) = a·t²/2.
struct ConstantAccelerationResult {
  std::string integrator;
  std::int64_t stepRateHz = 0;
  double dt = 0.0;        // s, exactly 1/stepRateHz (the integrator rounds it to float once)
  double time = 0.0;      // s
  double position = 0.0;  // m, simulated
  double exact = 0.0;     // m
  double error = 0.0;     // m, position − exact (signed)
};

/// The end of one oscillator run: k = 1 N/m, m = 1 kg, from p = −1 m at rest, against
/// p(t) = −cos t, v(t) = sin t.
struct OscillatorResult {
  std::string integrator;
  std::int64_t stepRateHz = 0;
  double dt = 0.0;        // s, exactly 1/stepRateHz
  double time = 0.0;      // s
  double position = 0.0;  // m, simulated
  double exact = 0.0;     // m, −cos t
  double error = 0.0;     // m, position − exact (signed)
  double velocity = 0.0;  // m/s, simulated (exact: sin t)
  double energy = 0.0;    // J, ½·m·v² + ½·k·p² of the simulated state (exact: 0.5 J)
};

/// The end of one wind run: a(t) = 150·sin(2π·f·t) from rest at the origin, against
/// p(t) = 150/ω·(t − sin(ωt)/ω), ω = 2π·f.
struct WindResult {
  std::string integrator;
  std::int64_t stepRateHz = 0;
  double dt = 0.0;           // s, exactly 1/stepRateHz
  double frequencyHz = 0.0;  // Hz, f
  double time = 0.0;         // s
  double position = 0.0;     // m, simulated
  double exact = 0.0;        // m
  double error = 0.0;        // m, position − exact (signed)
};

/// Everything the study measured, ordered by integrator (plan order), then step rate (plan
/// order), then wind frequency or sample time.
struct StudyResults {
  std::vector<ConstantAccelerationResult> constantAcceleration;
  std::vector<OscillatorResult> oscillator;
  std::vector<WindResult> wind;
};

/// Runs the three experiments. Each run is one particle in a ParticlePool, moved along x by a
/// ForceSet through the named integrator, one StepTime{tick, rate} at a time with
/// markAllStepped() after each step, as ParticleSystem does. Deterministic: the same plan gives
/// the same bits on every run. Throws std::invalid_argument for an unknown integrator, a
/// non-positive rate or a time that is not a whole number of ticks.
StudyResults runIntegratorStudy(const StudyPlan& plan = {});

// The single runs the study is made of, for callers that want one figure.

/// Constant acceleration: one sample per entry of `sampleTimes` (s), in the given order.
std::vector<ConstantAccelerationResult> runConstantAcceleration(
    std::string_view integrator, std::int64_t stepRateHz, const std::vector<double>& sampleTimes);
/// Harmonic oscillator after `duration` seconds.
OscillatorResult runOscillator(std::string_view integrator, std::int64_t stepRateHz,
                               double duration);
/// Periodic wind of `frequencyHz` after `duration` seconds.
WindResult runWind(std::string_view integrator, std::int64_t stepRateHz, double frequencyHz,
                   double duration);

/// Exact solutions (double), for the tables and for checking the runs.
double exactConstantAccelerationPosition(double t);      // m
double exactOscillatorPosition(double t);                // m
double exactOscillatorVelocity(double t);                // m/s
double exactWindPosition(double frequencyHz, double t);  // m
double exactWindVelocity(double frequencyHz, double t);  // m/s

/// Each experiment as an aligned text table with a title line and units in the headers.
std::string formatConstantAccelerationTable(const StudyResults& results);
std::string formatOscillatorTable(const StudyResults& results);
std::string formatWindTable(const StudyResults& results);
/// The three tables, separated by blank lines, written to `out`.
void printStudy(const StudyResults& results, std::FILE* out);

/// Each experiment as CSV text: a header row, then one row per result, numbers as %.9g
/// (locale-independent). Columns:
///   constant acceleration: integrator,dt,step_rate_hz,t,position,exact,error
///   oscillator:            integrator,dt,step_rate_hz,t,position,exact,error,velocity,energy
///   wind:                  integrator,dt,step_rate_hz,frequency_hz,t,position,exact,error
std::string constantAccelerationCsv(const StudyResults& results);
std::string oscillatorCsv(const StudyResults& results);
std::string windCsv(const StudyResults& results);

/// Writes constant_acceleration.csv, oscillator.csv and wind.csv into `dir` (created if
/// missing, files replaced) and returns their paths in that order. Throws
/// std::filesystem::filesystem_error or std::runtime_error when a file cannot be written.
std::vector<std::filesystem::path> writeStudyCsv(const StudyResults& results,
                                                 const std::filesystem::path& dir);

/// Seconds of constant acceleration the series cover (the errors have grown visibly by then).
inline constexpr double kSeriesConstantAccelerationSeconds = 2.0;
/// Step rates of the wind series: the aliasing rate of the source material against a fine one.
inline constexpr std::int64_t kSeriesWindStepRatesHz[] = {20, 1000};

/// Every tick of the runs the study's figures plot (`tickfx study --plots`), as CSV, from each
/// run's start (t = 0) on:
///   series_constant_acceleration.csv  integrator,step_rate_hz,t,position,exact,error
///       every integrator at every plan rate, for kSeriesConstantAccelerationSeconds;
///   series_oscillator.csv             integrator,step_rate_hz,t,position,velocity,energy
///       every integrator at the plan's oscillator rates, for the plan's oscillator duration;
///   series_wind.csv                   integrator,step_rate_hz,frequency_hz,t,position,exact
///       semi-implicit Euler at kSeriesWindStepRatesHz, the plan's last wind frequency, for the
///       plan's wind duration.
/// Writes them into `dir` (created if missing) and returns their paths in that order; throws as
/// writeStudyCsv() does.
std::vector<std::filesystem::path> writeStudySeriesCsv(const StudyPlan& plan,
                                                       const std::filesystem::path& dir);

}  // namespace tickfx
