// A gusting wind that is the same everywhere and periodic in time.
#pragma once

#include <cmath>

#include "fields/ForceModule.h"
#include "particles/SettingProblem.h"

namespace tickfx {

/// a = direction · (base + amplitude · sin(2π · frequency · t + phase)), in m/s².
///
/// The sine is det::sin in double, evaluated once per call and rounded to float once, so every
/// build gives the same bits. Sampling: a frequency above half the step rate aliases (the effect
/// linter warns); integrators that evaluate at t + dt/2 see the wind there too.
class PeriodicWind final : public ForceModule {
 public:
  struct Settings {
    Eigen::Vector3f direction = Eigen::Vector3f(1.0f, 0.0f, 0.0f);  // normalised on construction
    float base = 0.0f;                                              // m/s²
    float amplitude = 1.0f;                                         // m/s²
    double frequency = 1.0;                                         // Hz
    double phase = 0.0;                                             // radians

    /// What PeriodicWind refuses (empty: it accepts them): a `direction` too short to normalise
    /// in float, the precision the wind keeps it in (normalisable<float>: at least 1.1e-19 long;
    /// [1e-50, 0, 0] is zero once rounded to float).
    SettingProblems validate() const;
  };

  /// Throws std::invalid_argument with the first of settings.validate().
  explicit PeriodicWind(const Settings& settings);
  std::string_view typeName() const override { return "wind"; }
  bool interleavesTicks() const override { return true; }
  bool arithmeticOnly() const override {
    return s_.direction.allFinite() && std::isfinite(s_.base) && std::isfinite(s_.amplitude) &&
           std::isfinite(s_.frequency) && std::isfinite(s_.phase);
  }
  bool uniformAcceleration(const ForceInput& in, Eigen::Vector3f& a) const override;
  void accumulate(const ForceInput& in, RowRange rows, Vec3Rows& acceleration) const override;
  /// The scalar strength (m/s²) at time `t` seconds.
  float strength(double t) const;

 private:
  Settings s_;
};

}  // namespace tickfx
