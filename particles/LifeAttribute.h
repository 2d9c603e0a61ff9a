// An attribute of an emitter's particles that is a pure function of the particle: a constant, a
// random value per particle, or a ramp over its normalised age. Such an attribute costs nothing in
// a tick: it is evaluated when a frame is written, captured or rendered.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "particles/SettingProblem.h"

namespace tickfx {

/// How a ramp goes from one key to the next.
enum class RampInterpolation {
  Linear,    // straight between the keys
  Smooth,    // smoothstep, w² (3 − 2w): flat at every key
  Constant,  // the key at or before nage, until the next
};

/// One key of a ramp: the value at nage (age / lifetime, in [0, 1]).
struct RampKey {
  float nage = 0.0f;
  std::array<float, 3> value{};  // only the first components() are used
};

/// An attribute over life. `name` is Houdini's: "Cd" (linear RGB, three components), "Alpha"
/// (opacity, 0 to 1), "pscale" (radius, metres), or any other name for a custom float attribute.
/// Values are float, the simulation's precision; everything is evaluated in float.
struct LifeAttributeSettings {
  enum class Kind { Constant, Random, Ramp };

  std::string name;
  Kind kind = Kind::Constant;
  std::array<float, 3> value{};  // Constant: the value; Random: the low end
  std::array<float, 3> high{};   // Random: the high end
  std::vector<RampKey> keys;     // Ramp: at least one, nage rising, in [0, 1]
  RampInterpolation interpolation = RampInterpolation::Linear;

  /// 3 for "Cd", 1 for every other name.
  int components() const { return name == "Cd" ? 3 : 1; }
  /// The columns the attribute is written in: "Cd_r", "Cd_g", "Cd_b" for Cd, else the name.
  std::vector<std::string> columnNames() const { return columnNamesOf(name); }
  static std::vector<std::string> columnNamesOf(const std::string& name);
  /// The value a particle whose emitter does not declare `column` shows there: 1 for Cd and
  /// Alpha, 1 for pscale (Houdini's default scale), 0 for custom attributes.
  static float defaultValue(const std::string& column);

  /// Component `c` at normalised age `nage` (clamped to [0, 1]; NaN reads as 0) for a particle
  /// whose random draw for this attribute is `u` in [0, 1) (unitFromBits()). Pure: the same bits
  /// for the same arguments on every thread and platform.
  float evaluate(int c, float nage, float u) const;  // inline below: a frame calls it per value

  /// What the settings refuse (empty: none), keys relative to the attribute's table: "ramp",
  /// "ramp.<i>", "value", "random". Colours must be in [0, ∞), Alpha in [0, 1], pscale in
  /// [0, ∞), every value finite; ramp keys rising in [0, 1].
  SettingProblems validate() const;
};

/// The three float columns a vector attribute is held in, in the pool and in caches: `Cd_r`,
/// `Cd_g`, `Cd_b` for Houdini's colour, `<name>_x`, `_y`, `_z` for any other (hitpos).
std::array<std::string, 3> vectorColumnNames(const std::string& name);

/// A particle's uniform in [0, 1) for an attribute, from 64 random bits: the top 24 bits, exact
/// in float (no double on the way).
inline float unitFromBits(std::uint64_t bits) {
  return static_cast<float>(static_cast<std::uint32_t>(bits >> 40)) * 0x1.0p-24f;
}

/// nage = age / lifetime in float, clamped to [0, 1]; 0 for an immortal particle (lifetime +∞)
/// and for NaN.
inline float normalisedAge(float age, float lifetime) {
  const float nage = age / lifetime;  // +∞ lifetime: 0
  if (!(nage > 0.0f)) return 0.0f;    // NaN, negative
  return std::min(nage, 1.0f);
}

inline float LifeAttributeSettings::evaluate(int c, float nage, float u) const {
  const auto k = static_cast<std::size_t>(c);
  switch (kind) {
    case Kind::Constant:
      return value[k];
    case Kind::Random:
      return value[k] + (high[k] - value[k]) * u;
    case Kind::Ramp:
      break;
  }
  if (!(nage >= 0.0f)) nage = 0.0f;
  nage = std::min(nage, 1.0f);
  // The last key at or before nage; before the first key, the first key's value.
  std::size_t i = 0;
  while (i + 1 < keys.size() && keys[i + 1].nage <= nage) ++i;
  const RampKey& a = keys[i];
  if (i + 1 == keys.size() || nage <= a.nage || interpolation == RampInterpolation::Constant) {
    return a.value[k];
  }
  const RampKey& b = keys[i + 1];
  float w = (nage - a.nage) / (b.nage - a.nage);
  if (interpolation == RampInterpolation::Smooth) w = w * w * (3.0f - 2.0f * w);
  return a.value[k] + (b.value[k] - a.value[k]) * w;
}

}  // namespace tickfx
