#include "io/EffectLint.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>

namespace tickfx::io {
namespace {

// Energy drift the drift warnings tolerate over the whole output.
constexpr double kTolerableDrift = 0.01;
constexpr std::int64_t kHighestStepRate = 1'000'000'000;

// `value` to `digits` significant digits, without trailing zeros ("4", "3.7", "1.00028").
std::string rounded(double value, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*g", digits, value);
  return buffer;
}

// A factor close to 1 with enough digits to show how far from 1 it is ("1.000278",
// "1.00000025"), never "1".
std::string factorText(double factor) {
  const double change = std::abs(factor - 1.0);
  const int digits =
      change > 0.0 ? 3 + std::max(0, static_cast<int>(std::ceil(-std::log10(change)))) : 6;
  return rounded(factor, std::min(digits, 17));
}

Diagnostic warning(const EffectSettings& effect, const std::string& keyPath, std::string message) {
  SourceLocation at = effect.sources.find(keyPath);
  if (at.file.empty()) at.file = "<effect>";  // settings built in code, not read from a file
  return Diagnostic{Severity::Warning, at.file, at.line, at.column, keyPath, std::move(message)};
}

// The smallest step rate in [from, kHighestStepRate] for which `tooMuch` is false (it must turn
// false for good once it does), or nothing.
std::optional<std::int64_t> smallestStepRate(std::int64_t from,
                                             const std::function<bool(double)>& tooMuch) {
  if (tooMuch(static_cast<double>(kHighestStepRate))) return std::nullopt;
  std::int64_t lo = std::max<std::int64_t>(1, from), hi = kHighestStepRate;
  while (lo < hi) {
    const std::int64_t mid = lo + (hi - lo) / 2;
    if (tooMuch(static_cast<double>(mid))) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo;
}

void lintWind(const EffectSettings& effect, const WindSettings& wind, const std::string& path,
              std::vector<Diagnostic>& out) {
  const double rate = static_cast<double>(effect.simulation.stepRateHz);
  const double f = wind.frequency;
  if (f <= 0.0 || 2.0 * f < rate) return;
  const auto needed = static_cast<std::int64_t>(std::floor(2.0 * f)) + 1;
  const double alias = std::abs(f - rate * std::round(f / rate));
  out.push_back(
      warning(effect, path + ".frequency",
              rounded(f, 6) + " Hz wind is " + (2.0 * f > rate ? "above" : "at") +
                  " the Nyquist limit of " + rounded(rate / 2.0, 6) +
                  " Hz (half of step_rate = " + std::to_string(effect.simulation.stepRateHz) +
                  " Hz) and is sampled as a " + rounded(alias, 4) +
                  " Hz wind (use a step_rate of at least " + std::to_string(needed) + " Hz)"));
}

void lintSpring(const EffectSettings& effect, const AnchorSpringSettings& spring,
                const std::string& path, std::vector<Diagnostic>& out) {
  if (effect.emitters.empty()) return;
  double mass = effect.emitters.front().mass;
  for (const EmitterSettings& e : effect.emitters) mass = std::min(mass, e.mass);
  const std::string& integrator = effect.simulation.integrator;
  const std::int64_t stepRate = effect.simulation.stepRateHz;
  const double rate = static_cast<double>(stepRate);
  const double k = spring.stiffness, c = spring.damping;
  const double omega = std::sqrt(k / mass);
  const double omegaDt = omega / rate;
  const std::string where = path + ".stiffness";
  const std::string stable = "semi_implicit_euler, position_verlet or velocity_verlet";

  if (const std::optional<double> limit = springStabilityLimit(integrator);
      limit && omegaDt >= *limit) {
    const auto needed = static_cast<std::int64_t>(std::floor(omega / *limit)) + 1;
    out.push_back(warning(
        effect, where,
        "omega*dt = " + rounded(omegaDt, 4) + " is past " + integrator + "'s stability limit of " +
            rounded(*limit, 4) + " (omega = sqrt(k/m) = " + rounded(omega, 4) +
            " rad/s for the lightest mass, " + rounded(mass, 4) + " kg, and dt = 1/" +
            std::to_string(stepRate) +
            " s): the spring's motion grows without bound (use a step_rate of at least " +
            std::to_string(needed) + " Hz)"));
    return;
  }

  // Per-step energy factor of a damped spring as a function of the step rate, and the drift over
  // the output it adds up to.
  const double duration = effect.output.durationSeconds();
  std::function<double(double)> perStep;
  std::string verb, change, extra;
  if (integrator == "explicit_euler" && c < k / rate) {
    // |λ|² = det of the step matrix [[1, dt], [−ω²dt, 1 − (c/m)dt]].
    perStep = [=](double h) { return 1.0 + (k / h - c) / (mass * h); };
    verb = "adds energy to this spring every step";
    change = "gain";
    extra = ", damping of at least " + rounded(k / rate, 4) + " N·s/m (k·dt)";
  } else if (integrator == "midpoint" && c == 0.0) {
    perStep = [=](double h) { return 1.0 - (omega * omega) / (2.0 * h * h); };
    verb = "removes energy from this undamped spring every step";
    change = "loss";
  } else {
    return;
  }
  // ln of the drift over the output, counted in the direction the warning is about (a damped
  // spring's physical loss is no gain); a factor <= 0 is a scheme past its stability.
  const double sign = change == "gain" ? 1.0 : -1.0;
  const auto drift = [&](double h) {
    const double g = perStep(h);
    if (!(g > 0.0)) return std::numeric_limits<double>::infinity();
    return std::max(0.0, sign * h * duration * std::log(g));
  };
  const double budget = sign * std::log(1.0 + sign * kTolerableDrift);
  const double total = std::exp(rate * duration * std::log(perStep(rate)));
  std::string fix = "use " + stable + extra;
  const std::optional<std::int64_t> needed =
      smallestStepRate(1, [&](double h) { return drift(h) > budget; });
  if (needed && *needed > stepRate) {
    fix += ", or a step_rate of at least " + std::to_string(*needed) + " Hz to keep the " + change +
           " over the output under 1%";
  }
  out.push_back(warning(effect, where,
                        integrator + " " + verb + " (x" + factorText(perStep(rate)) +
                            " per step, x" + rounded(total, 3) + " over the " +
                            rounded(duration, 4) + " s of output) (" + fix + ")"));
}

}  // namespace

std::optional<double> springStabilityLimit(std::string_view integrator) {
  if (integrator == "semi_implicit_euler" || integrator == "position_verlet" ||
      integrator == "velocity_verlet") {
    return 2.0;
  }
  if (integrator == "rk4") return 2.785;
  if (integrator == "midpoint") return std::sqrt(2.0);
  return std::nullopt;
}

std::vector<Diagnostic> lintEffect(const EffectSettings& effect) {
  std::vector<Diagnostic> out;
  for (std::size_t i = 0; i < effect.forces.size(); ++i) {
    const std::string path = "forces." + std::to_string(i);
    if (const auto* wind = std::get_if<WindSettings>(&effect.forces[i]))
      lintWind(effect, *wind, path, out);
    if (const auto* spring = std::get_if<AnchorSpringSettings>(&effect.forces[i])) {
      lintSpring(effect, *spring, path, out);
    }
  }
  sortDiagnostics(out);
  return out;
}

}  // namespace tickfx::io
