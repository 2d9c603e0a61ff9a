#include "io/effect/EffectLint.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>

#include "io/effect/ColliderLint.h"
#include "io/effect/VectorFieldSource.h"

namespace tickfx::io {
namespace {

// The words of the warnings about an unstable step, which instabilityWarning() looks for.
const std::string kGrowsWithoutBound = "grows without bound";
const std::string kAddsEnergy = "adds energy to";

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

// Warns at forces.N.frequency about a wind at or above the Nyquist limit: docs/effects.md,
// "Lint warnings", "Wind above the Nyquist limit".
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

// Warns at simulation.max_ticks_per_frame when a real-time host advancing at the output's fps
// would drop ticks: docs/effects.md, "[simulation]" (max_ticks_per_frame and overrun).
void lintTickCap(const EffectSettings& effect, std::vector<Diagnostic>& out) {
  const SystemSettings& sim = effect.simulation;
  const FrameRate fps = effect.output.fps;
  const __int128 perFrame = static_cast<__int128>(sim.stepRateHz) * fps.denominator;
  const auto needed = static_cast<std::int64_t>((perFrame + fps.numerator - 1) / fps.numerator);
  if (needed <= sim.maxTicksPerFrame) return;
  const auto fastest = static_cast<std::int64_t>(static_cast<__int128>(sim.maxTicksPerFrame) *
                                                 fps.numerator / fps.denominator);
  const std::string rate = std::to_string(fps.numerator) +
                           (fps.denominator == 1 ? "" : "/" + std::to_string(fps.denominator));
  out.push_back(warning(
      effect, "simulation.max_ticks_per_frame",
      "a real-time host advancing at the output's " + rate + " fps needs up to " +
          std::to_string(needed) + " ticks a frame at " + std::to_string(sim.stepRateHz) +
          " Hz, more than max_ticks_per_frame = " + std::to_string(sim.maxTicksPerFrame) +
          ", and would drop ticks (`tickfx run` runs them all; use a max_ticks_per_frame of at "
          "least " +
          std::to_string(needed) + " or a step_rate of at most " + std::to_string(fastest) +
          " Hz)"));
}

// Warns at `path` about the vector field `field`, loaded (or baked) as the builder will, or
// `built` when the builder made it: a file that will not load, and a field that carries particles
// more than a voxel a step. docs/effects.md, "Lint warnings", "A vector field that does not load"
// and "A field that carries particles more than a voxel a step".
void lintVectorField(const EffectSettings& effect, const VectorFieldSettings& field,
                     const std::string& path, const VectorField* built,
                     std::vector<Diagnostic>& out) {
  std::unique_ptr<VectorField> owned;
  const VectorField* loaded = built;
  try {
    if (loaded == nullptr) {
      owned = loadVectorField(field);
      loaded = owned.get();
    }
  } catch (const std::runtime_error& e) {
    out.push_back(warning(effect, path + (field.bake ? ".bake" : ".file"),
                          std::string(e.what()) +
                              " (tickfx run stops at this: write the file first, e.g. with "
                              "tickfx bake-field, or correct file and grid)"));
    return;
  }
  if (field.mode == VectorField::Mode::Force) return;
  // S of docs/effects.md ("A field that carries particles more than a voxel a step").
  const double speed = loaded->maxMagnitude() *
                       (field.mode == VectorField::Mode::Advect ? std::abs(field.scale) : 1.0);
  const double voxel = loaded->voxelSize();
  const double rate = static_cast<double>(effect.simulation.stepRateHz);
  if (!(speed / rate > voxel)) return;
  auto needed = static_cast<std::int64_t>(std::ceil(speed / voxel));
  while (speed / static_cast<double>(needed) > voxel) ++needed;  // ceil's rounding, at most once
  out.push_back(warning(effect, path,
                        "the field carries particles up to " + rounded(speed, 4) + " m/s, " +
                            rounded(speed, 4) + "·dt = " + rounded(speed / rate, 4) +
                            " m a step, more than a voxel (" + rounded(voxel, 4) +
                            " m) (use a step_rate of at least " + std::to_string(needed) + " Hz)"));
}

// The lightest particle mass of the effect (emitters' and structures'), or nothing.
std::optional<double> lightestMass(const EffectSettings& effect) {
  std::optional<double> mass;
  for (const EmitterSettings& e : effect.emitters) mass = std::min(mass.value_or(e.mass), e.mass);
  for (const StructureSettings& s : effect.structures)
    mass = std::min(mass.value_or(s.mass), s.mass);
  return mass;
}

// A stiffness or a rate to 4 significant digits, large ones as whole numbers ("20000", not
// "2e+04").
std::string quantity(double value) {
  if (std::abs(value) >= 1e4 && std::abs(value) < 1e15) return std::to_string(std::llround(value));
  return rounded(value, 4);
}

// "forces.0", "forces.0 and forces.2", "forces.0, forces.2 and forces.5", and past three "...
// and 4 more".
std::string listOf(const std::vector<std::string>& paths) {
  constexpr std::size_t kListed = 3;
  std::string out;
  for (std::size_t i = 0; i < paths.size() && i < kListed; ++i) {
    const bool last = i + 1 == paths.size() || i + 1 == kListed;
    out += (i == 0 ? "" : (last && paths.size() <= kListed ? " and " : ", ")) + paths[i];
  }
  if (paths.size() > kListed) out += " and " + std::to_string(paths.size() - kListed) + " more";
  return out;
}

// Checks the effect's anchor springs as one spring of their stiffnesses and dampings added up:
// against the integrator's stability limit and, within it, for energy drift under explicit_euler
// and midpoint. docs/effects.md, "Lint warnings", "Anchor spring past the integrator's stability
// limit" and "Anchor spring whose energy drifts every step". At most one warning, at the first
// spring's stiffness.
void lintAnchorSprings(const EffectSettings& effect, std::vector<Diagnostic>& out) {
  std::vector<std::string> paths;
  double k = 0.0, c = 0.0;
  for (std::size_t i = 0; i < effect.forces.size(); ++i) {
    if (const auto* a = std::get_if<AnchorSpringSettings>(&effect.forces[i])) {
      paths.push_back("forces." + std::to_string(i));
      k += a->stiffness;
      c += a->damping;
    }
  }
  const std::optional<double> lightest = lightestMass(effect);
  if (paths.empty() || !lightest) return;
  const bool one = paths.size() == 1;
  const std::string springs = "the anchor springs " + listOf(paths);
  const double mass = *lightest;
  const std::string& integrator = effect.simulation.integrator;
  const std::int64_t stepRate = effect.simulation.stepRateHz;
  const double rate = static_cast<double>(stepRate);
  const double omega = std::sqrt(k / mass);
  const double omegaDt = omega / rate;
  const std::string where = paths.front() + ".stiffness";
  const std::string stable = "semi_implicit_euler, position_verlet or velocity_verlet";

  if (const std::optional<double> limit = springStabilityLimit(integrator);
      limit && omegaDt >= *limit) {
    const auto needed = static_cast<std::int64_t>(std::floor(omega / *limit)) + 1;
    const std::string together = one ? " "
                                     : " with k = " + quantity(k) + " N/m, the stiffnesses of " +
                                           springs + " added up (each pulls on every particle), ";
    out.push_back(warning(effect, where,
                          "omega*dt = " + rounded(omegaDt, 4) + " is past " + integrator +
                              "'s stability limit of " + rounded(*limit, 4) +
                              " (omega = sqrt(k/m) = " + rounded(omega, 4) + " rad/s" + together +
                              "for the lightest mass, " + rounded(mass, 4) + " kg, and dt = 1/" +
                              std::to_string(stepRate) + " s): the " +
                              (one ? "spring's" : "springs'") + " motion " + kGrowsWithoutBound +
                              " (use a step_rate of at least " + std::to_string(needed) + " Hz)"));
    return;
  }

  // Per-step energy factor of a damped spring as a function of the step rate, and the drift over
  // the output it adds up to.
  const double duration = effect.output.durationSeconds();
  std::function<double(double)> perStep;
  std::string verb, change, extra;
  const std::string added = " (k = " + quantity(k) + " N/m and c = " + quantity(c) +
                            " N·s/m added up: each pulls on every particle)";
  if (integrator == "explicit_euler" && c < k / rate) {
    // |λ|² = det of the step matrix [[1, dt], [−ω²dt, 1 − (c/m)dt]].
    perStep = [=](double h) { return 1.0 + (k / h - c) / (mass * h); };
    verb = one ? kAddsEnergy + " this spring every step"
               : kAddsEnergy + " " + springs + " every step" + added;
    change = "gain";
    extra = ", damping of at least " + rounded(k / rate, 4) + " N·s/m (k·dt" +
            (one ? "" : ", in all") + ")";
  } else if (integrator == "midpoint" && c == 0.0) {
    perStep = [=](double h) { return 1.0 - (omega * omega) / (2.0 * h * h); };
    verb = one ? "removes energy from this undamped spring every step"
               : "removes energy from " + springs + ", undamped, every step" + added;
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

// 1 + the explicit-Euler energy factor's excess, written so that huge factors stay readable.
std::string totalText(double total) {
  return std::isfinite(total) ? "x" + rounded(total, 3) : "beyond x1e308";
}

}  // namespace

StructureStiffness structureStiffness(const StructureSettings& structure) {
  StructureStiffness out;
  const double k = structure.stiffness;
  if (const auto* cloth = std::get_if<ClothShape>(&structure.shape)) {
    out.springFactor = 4.0 * (1.0 + cloth->shearStiffnessScale + cloth->bendStiffnessScale);
    out.formula = "4k(1 + shear_scale + bend_scale)";
  } else if (const auto* cluster = std::get_if<ClusterShape>(&structure.shape)) {
    const double n = clusterNeighbours(*cluster);
    out.neighbours = n;
    const double spread = n + kClusterSpread * std::sqrt(n);
    if (cluster->count <= 1) {
      out.springFactor = 0.0;  // a lone particle: no springs
      out.formula = "0";
    } else if (std::max(spread, 4.0) >= cluster->count) {
      out.springFactor = cluster->count;
      out.formula = "count*k";
    } else if (spread < 4.0) {
      out.springFactor = 4.0;
      out.formula = "4k";
    } else {
      out.springFactor = spread;
      out.formula = "(n + 3*sqrt(n))*k";
    }
  } else {
    out.springFactor = 4.0;
    out.formula = "4k";
  }
  out.stiffness = out.springFactor * k;
  return out;
}

namespace {

// Checks the stiffest structure (largest ω, anchor springs included) against the integrator's
// stability limit and, under explicit_euler, for energy gain: docs/effects.md, "Lint warnings",
// "A structure past the integrator's stability limit" and "A structure under explicit Euler". At
// most one warning, at that structure's stiffness.
void lintStructures(const EffectSettings& effect, std::vector<Diagnostic>& out) {
  double anchorK = 0.0, anchorC = 0.0;
  for (const ForceSettings& f : effect.forces) {
    if (const auto* a = std::get_if<AnchorSpringSettings>(&f)) {
      anchorK += a->stiffness;
      anchorC += a->damping;
    }
  }
  std::optional<std::size_t> stiffest;
  double stiffestOmega = 0.0;
  for (std::size_t i = 0; i < effect.structures.size(); ++i) {
    const StructureSettings& s = effect.structures[i];
    if (structureStiffness(s).springFactor <= 0.0) continue;  // a lone particle: no springs
    const double omega = std::sqrt((structureStiffness(s).stiffness + anchorK) / s.mass);
    if (!stiffest || omega > stiffestOmega) {
      stiffest = i;
      stiffestOmega = omega;
    }
  }
  if (!stiffest) return;
  const StructureSettings& s = effect.structures[*stiffest];
  const StructureStiffness stiffness = structureStiffness(s);
  const std::string type(structureTypeName(s.shape));
  const std::string where = structureKeyPath(effect, *stiffest) + ".stiffness";
  const std::string& integrator = effect.simulation.integrator;
  const std::int64_t stepRate = effect.simulation.stepRateHz;
  const double rate = static_cast<double>(stepRate);
  const double m = s.mass;
  const double kTotal = stiffness.stiffness + anchorK;
  const double cTotal = stiffness.springFactor * s.damping + anchorC;
  const double omega = stiffestOmega;
  const double omegaDt = omega / rate;

  if (const std::optional<double> limit = springStabilityLimit(integrator);
      limit && omegaDt >= *limit) {
    const auto needed = static_cast<std::int64_t>(std::floor(omega / *limit)) + 1;
    std::string keff = "k_eff = " + stiffness.formula;
    if (anchorK > 0.0) keff += " + " + quantity(anchorK);
    keff += " = " + quantity(kTotal) + " N/m for a " + type + "'s springs";
    if (anchorK > 0.0) keff += " and the anchor springs";
    if (stiffness.neighbours) {
      keff += ", n = " + rounded(*stiffness.neighbours, 4) + " neighbours of a particle on average";
    }
    out.push_back(warning(
        effect, where,
        "omega*dt = " + rounded(omegaDt, 4) + " is past " + integrator + "'s stability limit of " +
            rounded(*limit, 4) + " (omega = sqrt(k_eff/m) = " + quantity(omega) + " rad/s, " +
            keff + ", m = " + rounded(m, 4) + " kg, and dt = 1/" + std::to_string(stepRate) +
            " s): the " + type + "'s fastest vibration " + kGrowsWithoutBound +
            " (use a step_rate of " + "at least " + std::to_string(needed) + " Hz)"));
    return;
  }
  if (integrator != "explicit_euler" || cTotal >= kTotal / rate) return;
  // Energy factor a step of the fastest vibration (docs/effects.md, "A structure under explicit
  // Euler").
  const auto perStep = [=](double h) { return 1.0 + (kTotal / h - cTotal) / (m * h); };
  const double duration = effect.output.durationSeconds();
  const double budget = std::log(1.0 + kTolerableDrift);
  const double total = std::exp(rate * duration * std::log(perStep(rate)));
  // The damping per spring that makes c_eff = k_eff·dt.
  const double neededDamping = (kTotal / rate - anchorC) / stiffness.springFactor;
  const std::string dampingWhy = anchorK > 0.0 ? "k·dt with the anchor springs" : "k·dt";
  std::string fix =
      "use semi_implicit_euler, position_verlet or velocity_verlet, damping of at least " +
      rounded(neededDamping, 4) + " N·s/m (" + dampingWhy + ")";
  const std::optional<std::int64_t> needed = smallestStepRate(1, [&](double h) {
    const double g = perStep(h);
    return h * duration * std::log(g) > budget;
  });
  if (needed && *needed > stepRate) {
    fix += ", or a step_rate of at least " + std::to_string(*needed) +
           " Hz to keep the gain over the output under 1%";
  }
  out.push_back(warning(effect, where,
                        "explicit_euler " + kAddsEnergy + " this " + type +
                            "'s springs every step (x" + factorText(perStep(rate)) + " per step, " +
                            totalText(total) + " over the " + rounded(duration, 4) +
                            " s of output, for its fastest vibration) (" + fix + ")"));
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

namespace {

// Cd, Alpha or pscale declared by some emitters and not by another: that one's particles show
// Houdini's default (1), which for pscale is a radius of a metre.
void lintPartialAttributes(const EffectSettings& effect, std::vector<Diagnostic>& out) {
  for (const char* name : {"Cd", "Alpha", "pscale"}) {
    const EmitterSettings* declaring = nullptr;
    for (const EmitterSettings& e : effect.emitters) {
      for (const LifeAttributeSettings& a : e.attributes) {
        if (a.name == name && declaring == nullptr) declaring = &e;
      }
    }
    if (declaring == nullptr) continue;
    for (std::size_t i = 0; i < effect.emitters.size(); ++i) {
      const EmitterSettings& e = effect.emitters[i];
      const auto has = [&](const std::string& n) { return n == name; };
      if (std::any_of(e.attributes.begin(), e.attributes.end(),
                      [&](const LifeAttributeSettings& a) { return has(a.name); }) ||
          std::any_of(e.sub.inherit.begin(), e.sub.inherit.end(), has)) {
        continue;
      }
      out.push_back(warning(effect, emitterKeyPath(effect, i),
                            "\"" + e.name + "\" declares no " + name + " while \"" +
                                declaring->name + "\" does: its particles show " + name +
                                " = 1, Houdini's default" +
                                (std::string(name) == "pscale" ? " (a radius of 1 m)" : "")));
    }
  }
}

}  // namespace

std::vector<Diagnostic> lintEffect(const EffectSettings& effect, const ForceSet* built,
                                   const ColliderSet* colliders) {
  std::vector<Diagnostic> out;
  for (std::size_t i = 0; i < effect.forces.size(); ++i) {
    const std::string path = "forces." + std::to_string(i);
    if (const auto* wind = std::get_if<WindSettings>(&effect.forces[i]))
      lintWind(effect, *wind, path, out);
    if (const auto* field = std::get_if<VectorFieldSettings>(&effect.forces[i])) {
      // The builder's module when there is one: a field sequence is not loaded twice.
      const VectorField* module = built != nullptr && i < built->size()
                                      ? dynamic_cast<const VectorField*>(&built->module(i))
                                      : nullptr;
      lintVectorField(effect, *field, path, module, out);
    }
  }
  lintAnchorSprings(effect, out);
  lintStructures(effect, out);
  lintTickCap(effect, out);
  lintPartialAttributes(effect, out);
  detail::lintColliders(effect, colliders, out);
  sortDiagnostics(out);
  return out;
}

const Diagnostic* instabilityWarning(const std::vector<Diagnostic>& lint) {
  for (const Diagnostic& d : lint) {
    if (d.severity != Severity::Warning) continue;
    if (d.message.find(kGrowsWithoutBound) != std::string::npos ||
        d.message.find(kAddsEnergy) != std::string::npos) {
      return &d;
    }
  }
  return nullptr;
}

}  // namespace tickfx::io
