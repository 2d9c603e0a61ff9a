// A setting a type refuses, found before anything is built. Each group of settings is validated
// once, by the type that owns it; its constructor and the effect loader both use that check.
#pragma once

#include <Eigen/Core>
#include <string>
#include <string_view>
#include <vector>

namespace tickfx {

/// One setting a type refuses. `key` names it as effect files write it, relative to the settings'
/// own table ("direction", "bursts.2.time", "axis_u"), so that the effect loader can show the
/// problem where the value was written:
///   fx.toml:7:13: error: emitters.0.direction: MESSAGE (expected EXPECTED)
/// `message` says what is wrong with the value, `expected` what would be accepted.
struct SettingProblem {
  std::string key;
  std::string message;
  std::string expected;

  /// "key: message (expected expected)".
  std::string text() const;
};
using SettingProblems = std::vector<SettingProblem>;

/// Throws std::invalid_argument with the first of `problems`, after `owner` ("emitter
/// direction: is too short ... (expected ...)"). Does nothing when there are none.
void throwIfAny(std::string_view owner, const SettingProblems& problems);

/// A number as a message shows it: the shortest digits that read back to it ("0.1", "1e-200").
std::string settingNumber(double value);

/// True when v / |v| is a unit vector computed in T: v is finite and its squared length is a
/// normal, finite T. Below the smallest normal T (|v| under √min, 1.49e-154 in double and
/// 1.08e-19 in float) the squared length is subnormal or zero, and |v| loses bits or vanishes.
template <typename T>
bool normalisable(const Eigen::Matrix<T, 3, 1>& v);

/// The shortest length normalisable() accepts in T, rounded up to two digits as messages show it:
/// "1.5e-154" in double, "1.1e-19" in float.
template <typename T>
std::string shortestNormalisable();

/// Adds "KEY: is not finite (expected three finite numbers)" unless every component of `v` is.
void checkFinite(const Eigen::Vector3d& v, const std::string& key, SettingProblems& out);

/// Adds a problem at `key` unless normalisable(v): v is a direction of any length, normalised in
/// T by its owner (the message names the precision and the shortest length accepted).
template <typename T>
void checkDirection(const Eigen::Matrix<T, 3, 1>& v, const std::string& key, SettingProblems& out);

}  // namespace tickfx
