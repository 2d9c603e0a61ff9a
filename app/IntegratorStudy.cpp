#include "app/IntegratorStudy.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "fields/AnchorSpring.h"
#include "fields/ForceSet.h"
#include "fields/Gravity.h"
#include "fields/PeriodicWind.h"
#include "integrators/Integrator.h"
#include "io/util/AtomicFile.h"
#include "particles/DetMath.h"
#include "particles/ParticlePool.h"

namespace tickfx {
namespace {

void requirePositiveRate(std::int64_t stepRateHz) {
  if (stepRateHz <= 0) {
    throw std::invalid_argument("step rate must be positive, got " + std::to_string(stepRateHz));
  }
}

// The study compares states at given times, so a time between ticks would compare the wrong
// state; refuse it rather than round.
std::int64_t wholeTicks(double seconds, std::int64_t stepRateHz) {
  requirePositiveRate(stepRateHz);
  const double ticks = seconds * static_cast<double>(stepRateHz);
  const double rounded = std::nearbyint(ticks);
  if (!(seconds >= 0.0) || std::abs(ticks - rounded) > 1e-9 * std::max(1.0, rounded)) {
    throw std::invalid_argument("time " + std::to_string(seconds) +
                                " s is not a whole number of ticks at " +
                                std::to_string(stepRateHz) + " Hz");
  }
  return static_cast<std::int64_t>(rounded);
}

double stepLength(std::int64_t stepRateHz) { return 1.0 / static_cast<double>(stepRateHz); }

// One particle moved along x through `integrator`, stepped the way ParticleSystem steps it.
// `onTick(ticksDone, p, v)` sees the state after every tick.
template <typename OnTick>
void simulate(std::string_view integratorName, ForceSet& forces, std::int64_t stepRateHz,
              std::int64_t ticks, float p0, float v0, OnTick&& onTick) {
  requirePositiveRate(stepRateHz);
  const std::unique_ptr<Integrator> integrator = makeIntegrator(integratorName);
  ParticlePool pool(1);
  ParticleInit init;
  init.position = Eigen::Vector3f(p0, 0.0f, 0.0f);
  init.velocity = Eigen::Vector3f(v0, 0.0f, 0.0f);
  init.mass = static_cast<float>(kStudyMass);
  pool.spawn(init, 0);
  for (std::int64_t k = 0; k < ticks; ++k) {
    forces.beginTick(pool, k);
    integrator->step(pool, forces, StepTime{k, stepRateHz});
    pool.markAllStepped();
    onTick(k + 1, pool.position().x[0], pool.velocity().x[0]);
  }
}

// The forces of the three experiments, along x.
ForceSet constantAccelerationForces() {
  ForceSet forces;
  forces.add(
      std::make_unique<Gravity>(Eigen::Vector3f(static_cast<float>(kStudyGravity), 0.0f, 0.0f)));
  return forces;
}

ForceSet oscillatorForces() {
  ForceSet forces;
  forces.add(std::make_unique<AnchorSpring>(Eigen::Vector3f::Zero(),
                                            static_cast<float>(kStudySpringStiffness)));
  return forces;
}

ForceSet windForces(double frequencyHz) {
  PeriodicWind::Settings wind;
  wind.direction = Eigen::Vector3f(1.0f, 0.0f, 0.0f);
  wind.base = 0.0f;
  wind.amplitude = static_cast<float>(kStudyWindAmplitude);
  wind.frequency = frequencyHz;
  wind.phase = 0.0;
  ForceSet forces;
  forces.add(std::make_unique<PeriodicWind>(wind));
  return forces;
}

double energyOf(double p, double v) {
  return 0.5 * kStudyMass * v * v + 0.5 * kStudySpringStiffness * p * p;
}

// ---- text output ----------------------------------------------------------------------------

// to_chars is specified as printf in the C locale, so a CSV never gets a decimal comma.
std::string csvNumber(double value) {
  char buffer[64];
  const auto [end, ec] =
      std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::general, 9);
  if (ec != std::errc{}) throw std::runtime_error("cannot format a number for CSV");
  return std::string(buffer, end);
}

std::string csvInteger(std::int64_t value) { return std::to_string(value); }

std::string csvRow(const std::vector<std::string>& fields) {
  std::string line;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    if (i > 0) line += ',';
    line += fields[i];
  }
  line += '\n';
  return line;
}

template <typename... Args>
std::string formatted(const char* format, Args... args) {
  char buffer[128];
  const int n = std::snprintf(buffer, sizeof buffer, format, args...);
  return std::string(buffer, static_cast<std::size_t>(std::clamp(n, 0, 127)));
}

std::string fixed(double value) { return formatted("%.6f", value); }
// Errors span ten orders of magnitude across the schemes, so they are shown in scientific form.
std::string scientific(double value) { return formatted("%+.3e", value); }
std::string timeText(double value) { return formatted("%g", value); }
std::string stepLengthText(std::int64_t stepRateHz) { return "1/" + std::to_string(stepRateHz); }

// A table whose first column (the integrator) is left-aligned and the rest right-aligned; a blank
// line separates integrators so each scheme's rows read as one block.
class Table {
 public:
  Table(std::string title, std::vector<std::string> headers)
      : title_(std::move(title)), headers_(std::move(headers)) {}

  void add(std::vector<std::string> row) { rows_.push_back(std::move(row)); }

  std::string str() const {
    std::vector<std::size_t> width(headers_.size());
    for (std::size_t c = 0; c < headers_.size(); ++c) width[c] = headers_[c].size();
    for (const auto& row : rows_) {
      for (std::size_t c = 0; c < row.size(); ++c) width[c] = std::max(width[c], row[c].size());
    }
    std::string out = title_ + "\n";
    const auto line = [&](const std::vector<std::string>& cells) {
      std::string text;
      for (std::size_t c = 0; c < cells.size(); ++c) {
        const std::string pad(width[c] - cells[c].size(), ' ');
        if (c > 0) text += "  ";
        text += c == 0 ? cells[c] + pad : pad + cells[c];
      }
      while (!text.empty() && text.back() == ' ') text.pop_back();
      out += text + "\n";
    };
    line(headers_);
    std::size_t ruleWidth = 0;
    for (std::size_t c = 0; c < width.size(); ++c) ruleWidth += width[c] + (c > 0 ? 2 : 0);
    out += std::string(ruleWidth, '-') + "\n";
    for (std::size_t r = 0; r < rows_.size(); ++r) {
      if (r > 0 && rows_[r][0] != rows_[r - 1][0]) out += "\n";
      line(rows_[r]);
    }
    return out;
  }

 private:
  std::string title_;
  std::vector<std::string> headers_;
  std::vector<std::vector<std::string>> rows_;
};

// Writes each (name, text) into `dir`, made first; returns the paths in order. Each file is
// written whole or not at all (io::writeFileAtomically): a failure names the file and the
// system's reason, and the files before it stay as written.
std::vector<std::filesystem::path> writeFiles(
    const std::filesystem::path& dir,
    const std::vector<std::pair<std::string, std::string>>& files) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw io::WriteError(dir, error.message());
  std::vector<std::filesystem::path> written;
  for (const auto& file : files) {  // not a structured binding: clang 14 cannot capture one
    const std::string& text = file.second;
    io::writeFileAtomically(dir / file.first, [&text](std::ostream& out) { out << text; });
    written.push_back(dir / file.first);
  }
  return written;
}

}  // namespace

// ---- exact solutions ------------------------------------------------------------------------
// det:: rather than std:: trigonometry so the reported exact values, like the simulated ones,
// have the same bits on every platform.

double exactConstantAccelerationPosition(double t) { return 0.5 * kStudyGravity * t * t; }

double exactOscillatorPosition(double t) { return kStudyOscillatorStart * det::cos(t); }

double exactOscillatorVelocity(double t) { return -kStudyOscillatorStart * det::sin(t); }

double exactWindPosition(double frequencyHz, double t) {
  const double omega = 2.0 * det::kPi * frequencyHz;
  return kStudyWindAmplitude / omega * (t - det::sin(omega * t) / omega);
}

double exactWindVelocity(double frequencyHz, double t) {
  const double omega = 2.0 * det::kPi * frequencyHz;
  return kStudyWindAmplitude / omega * (1.0 - det::cos(omega * t));
}

// ---- the runs -------------------------------------------------------------------------------

std::vector<ConstantAccelerationResult> runConstantAcceleration(
    std::string_view integrator, std::int64_t stepRateHz, const std::vector<double>& sampleTimes) {
  std::vector<std::int64_t> sampleTicks;
  for (double t : sampleTimes) sampleTicks.push_back(wholeTicks(t, stepRateHz));
  // One run to the latest sample; the state at tick 0 (never reported by a step) is the start.
  std::vector<float> sampled(sampleTicks.size(), 0.0f);
  const std::int64_t lastTick =
      sampleTicks.empty() ? 0 : *std::max_element(sampleTicks.begin(), sampleTicks.end());
  ForceSet forces = constantAccelerationForces();
  simulate(integrator, forces, stepRateHz, lastTick, 0.0f, 0.0f,
           [&](std::int64_t tick, float p, float /*v*/) {
             for (std::size_t i = 0; i < sampleTicks.size(); ++i) {
               if (sampleTicks[i] == tick) sampled[i] = p;
             }
           });

  std::vector<ConstantAccelerationResult> out;
  for (std::size_t i = 0; i < sampleTicks.size(); ++i) {
    ConstantAccelerationResult r;
    r.integrator = std::string(integrator);
    r.stepRateHz = stepRateHz;
    r.dt = stepLength(stepRateHz);
    r.time = static_cast<double>(sampleTicks[i]) / static_cast<double>(stepRateHz);
    r.position = sampled[i];
    r.exact = exactConstantAccelerationPosition(r.time);
    r.error = r.position - r.exact;
    out.push_back(std::move(r));
  }
  return out;
}

OscillatorResult runOscillator(std::string_view integrator, std::int64_t stepRateHz,
                               double duration) {
  const std::int64_t ticks = wholeTicks(duration, stepRateHz);
  ForceSet forces = oscillatorForces();
  float p = static_cast<float>(kStudyOscillatorStart), v = 0.0f;
  simulate(integrator, forces, stepRateHz, ticks, p, v, [&](std::int64_t, float pk, float vk) {
    p = pk;
    v = vk;
  });
  OscillatorResult r;
  r.integrator = std::string(integrator);
  r.stepRateHz = stepRateHz;
  r.dt = stepLength(stepRateHz);
  r.time = static_cast<double>(ticks) / static_cast<double>(stepRateHz);
  r.position = p;
  r.exact = exactOscillatorPosition(r.time);
  r.error = r.position - r.exact;
  r.velocity = v;
  r.energy = energyOf(r.position, r.velocity);
  return r;
}

WindResult runWind(std::string_view integrator, std::int64_t stepRateHz, double frequencyHz,
                   double duration) {
  const std::int64_t ticks = wholeTicks(duration, stepRateHz);
  ForceSet forces = windForces(frequencyHz);
  float p = 0.0f;
  simulate(integrator, forces, stepRateHz, ticks, 0.0f, 0.0f,
           [&](std::int64_t, float pk, float) { p = pk; });
  WindResult r;
  r.integrator = std::string(integrator);
  r.stepRateHz = stepRateHz;
  r.dt = stepLength(stepRateHz);
  r.frequencyHz = frequencyHz;
  r.time = static_cast<double>(ticks) / static_cast<double>(stepRateHz);
  r.position = p;
  r.exact = exactWindPosition(frequencyHz, r.time);
  r.error = r.position - r.exact;
  return r;
}

StudyResults runIntegratorStudy(const StudyPlan& plan) {
  const std::vector<std::string>& names =
      plan.integrators.empty() ? integratorNames() : plan.integrators;
  // Validate the whole plan before spending time on any run.
  for (const std::string& name : names) (void)makeIntegrator(name);
  for (std::int64_t rate : plan.stepRatesHz) {
    for (double t : plan.gravitySampleTimes) (void)wholeTicks(t, rate);
    (void)wholeTicks(plan.windDuration, rate);
  }
  for (std::int64_t rate : plan.oscillatorStepRatesHz)
    (void)wholeTicks(plan.oscillatorDuration, rate);

  StudyResults results;
  for (const std::string& name : names) {
    for (std::int64_t rate : plan.stepRatesHz) {
      for (auto& r : runConstantAcceleration(name, rate, plan.gravitySampleTimes)) {
        results.constantAcceleration.push_back(std::move(r));
      }
    }
    for (std::int64_t rate : plan.oscillatorStepRatesHz) {
      results.oscillator.push_back(runOscillator(name, rate, plan.oscillatorDuration));
    }
    for (std::int64_t rate : plan.stepRatesHz) {
      for (double f : plan.windFrequenciesHz) {
        results.wind.push_back(runWind(name, rate, f, plan.windDuration));
      }
    }
  }
  return results;
}

// ---- tables ---------------------------------------------------------------------------------

std::string formatConstantAccelerationTable(const StudyResults& results) {
  Table table(
      "Constant acceleration a = -9.81 m/s^2 from rest; exact p = a*t^2/2",
      {"integrator", "rate (Hz)", "dt (s)", "t (s)", "position (m)", "exact (m)", "error (m)"});
  for (const auto& r : results.constantAcceleration) {
    table.add({r.integrator, std::to_string(r.stepRateHz), stepLengthText(r.stepRateHz),
               timeText(r.time), fixed(r.position), fixed(r.exact), scientific(r.error)});
  }
  return table.str();
}

std::string formatOscillatorTable(const StudyResults& results) {
  Table table(
      "Harmonic oscillator k = 1 N/m, m = 1 kg, p0 = -1 m, v0 = 0; exact p = -cos t, v = sin t, "
      "E = 0.5 J",
      {"integrator", "rate (Hz)", "dt (s)", "t (s)", "position (m)", "exact (m)", "error (m)",
       "velocity (m/s)", "energy (J)"});
  for (const auto& r : results.oscillator) {
    table.add({r.integrator, std::to_string(r.stepRateHz), stepLengthText(r.stepRateHz),
               timeText(r.time), fixed(r.position), fixed(r.exact), scientific(r.error),
               fixed(r.velocity), fixed(r.energy)});
  }
  return table.str();
}

std::string formatWindTable(const StudyResults& results) {
  Table table(
      "Periodic wind a = 150*sin(2*pi*f*t) m/s^2 from rest; exact p = 150/w*(t - sin(w*t)/w), "
      "w = 2*pi*f",
      {"integrator", "rate (Hz)", "dt (s)", "f (Hz)", "t (s)", "position (m)", "exact (m)",
       "error (m)"});
  for (const auto& r : results.wind) {
    table.add({r.integrator, std::to_string(r.stepRateHz), stepLengthText(r.stepRateHz),
               formatted("%g", r.frequencyHz), timeText(r.time), fixed(r.position), fixed(r.exact),
               scientific(r.error)});
  }
  return table.str();
}

void printStudy(const StudyResults& results, std::FILE* out) {
  const std::string text = formatConstantAccelerationTable(results) + "\n" +
                           formatOscillatorTable(results) + "\n" + formatWindTable(results);
  std::fputs(text.c_str(), out);
}

// ---- CSV ------------------------------------------------------------------------------------

std::string constantAccelerationCsv(const StudyResults& results) {
  std::string text = "integrator,dt,step_rate_hz,t,position,exact,error\n";
  for (const auto& r : results.constantAcceleration) {
    text += csvRow({r.integrator, csvNumber(r.dt), csvInteger(r.stepRateHz), csvNumber(r.time),
                    csvNumber(r.position), csvNumber(r.exact), csvNumber(r.error)});
  }
  return text;
}

std::string oscillatorCsv(const StudyResults& results) {
  std::string text = "integrator,dt,step_rate_hz,t,position,exact,error,velocity,energy\n";
  for (const auto& r : results.oscillator) {
    text += csvRow({r.integrator, csvNumber(r.dt), csvInteger(r.stepRateHz), csvNumber(r.time),
                    csvNumber(r.position), csvNumber(r.exact), csvNumber(r.error),
                    csvNumber(r.velocity), csvNumber(r.energy)});
  }
  return text;
}

std::string windCsv(const StudyResults& results) {
  std::string text = "integrator,dt,step_rate_hz,frequency_hz,t,position,exact,error\n";
  for (const auto& r : results.wind) {
    text +=
        csvRow({r.integrator, csvNumber(r.dt), csvInteger(r.stepRateHz), csvNumber(r.frequencyHz),
                csvNumber(r.time), csvNumber(r.position), csvNumber(r.exact), csvNumber(r.error)});
  }
  return text;
}

namespace {

double secondsAtTick(std::int64_t tick, std::int64_t rate) {
  return static_cast<double>(tick) / static_cast<double>(rate);
}

// Rows of series_constant_acceleration.csv: `integrator` at `rate`, every tick from t = 0.
void appendConstantAccelerationSeries(std::string& csv, const std::string& integrator,
                                      std::int64_t rate) {
  ForceSet forces = constantAccelerationForces();
  const auto row = [&](std::int64_t tick, float p) {
    const double t = secondsAtTick(tick, rate), exact = exactConstantAccelerationPosition(t);
    csv += csvRow({integrator, csvInteger(rate), csvNumber(t), csvNumber(p), csvNumber(exact),
                   csvNumber(p - exact)});
  };
  row(0, 0.0f);
  simulate(integrator, forces, rate, wholeTicks(kSeriesConstantAccelerationSeconds, rate), 0.0f,
           0.0f, [&](std::int64_t tick, float p, float) { row(tick, p); });
}

// Rows of series_oscillator.csv: `integrator` at `rate` for `duration` seconds.
void appendOscillatorSeries(std::string& csv, const std::string& integrator, std::int64_t rate,
                            double duration) {
  ForceSet forces = oscillatorForces();
  const auto row = [&](std::int64_t tick, float p, float v) {
    csv += csvRow({integrator, csvInteger(rate), csvNumber(secondsAtTick(tick, rate)), csvNumber(p),
                   csvNumber(v), csvNumber(energyOf(p, v))});
  };
  const auto start = static_cast<float>(kStudyOscillatorStart);
  row(0, start, 0.0f);
  simulate(integrator, forces, rate, wholeTicks(duration, rate), start, 0.0f, row);
}

// Rows of series_wind.csv: semi-implicit Euler at `rate` in a wind of `frequency` Hz.
void appendWindSeries(std::string& csv, std::int64_t rate, double frequency, double duration) {
  ForceSet forces = windForces(frequency);
  const std::string integrator = "semi_implicit_euler";
  const auto row = [&](std::int64_t tick, float p) {
    const double t = secondsAtTick(tick, rate);
    csv += csvRow({integrator, csvInteger(rate), csvNumber(frequency), csvNumber(t), csvNumber(p),
                   csvNumber(exactWindPosition(frequency, t))});
  };
  row(0, 0.0f);
  simulate(integrator, forces, rate, wholeTicks(duration, rate), 0.0f, 0.0f,
           [&](std::int64_t tick, float p, float) { row(tick, p); });
}

}  // namespace

std::vector<std::filesystem::path> writeStudySeriesCsv(const StudyPlan& plan,
                                                       const std::filesystem::path& dir) {
  std::string gravity = "integrator,step_rate_hz,t,position,exact,error\n";
  std::string oscillator = "integrator,step_rate_hz,t,position,velocity,energy\n";
  std::string wind = "integrator,step_rate_hz,frequency_hz,t,position,exact\n";
  for (const std::string& integrator :
       plan.integrators.empty() ? integratorNames() : plan.integrators) {
    for (const std::int64_t rate : plan.stepRatesHz)
      appendConstantAccelerationSeries(gravity, integrator, rate);
    for (const std::int64_t rate : plan.oscillatorStepRatesHz)
      appendOscillatorSeries(oscillator, integrator, rate, plan.oscillatorDuration);
  }
  const double frequency = plan.windFrequenciesHz.empty() ? 16.0 : plan.windFrequenciesHz.back();
  for (const std::int64_t rate : kSeriesWindStepRatesHz)
    appendWindSeries(wind, rate, frequency, plan.windDuration);
  return writeFiles(dir, {{"series_constant_acceleration.csv", gravity},
                          {"series_oscillator.csv", oscillator},
                          {"series_wind.csv", wind}});
}

std::vector<std::filesystem::path> writeStudyCsv(const StudyResults& results,
                                                 const std::filesystem::path& dir) {
  return writeFiles(dir, {{"constant_acceleration.csv", constantAccelerationCsv(results)},
                          {"oscillator.csv", oscillatorCsv(results)},
                          {"wind.csv", windCsv(results)}});
}

}  // namespace tickfx
