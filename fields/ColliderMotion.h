// How a collider moves: a constant velocity or keyframed translation, and a spin about an axis.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "particles/SettingProblem.h"

namespace tickfx {

/// One key of a keyframed translation: at `time` seconds the collider is moved by `translate`
/// metres from where its settings put it.
struct ColliderKey {
  double time = 0.0;                                    // seconds, >= 0
  Eigen::Vector3d translate = Eigen::Vector3d::Zero();  // metres
};

/// The motion of a collider, as an effect file's `velocity`, `keys` and `spin` write it. At time
/// τ the collider's rest shape is rotated by spinRate·τ radians about the line through
/// spinCenter along spinAxis, then translated by T(τ): velocity·τ, or the keys' translation
/// (linear between keys, the first key's before it and the last key's after it).
struct ColliderMotionSettings {
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();    // m/s; not with keys
  std::vector<ColliderKey> keys;                         // times strictly increasing
  Eigen::Vector3d spinAxis = Eigen::Vector3d::UnitY();   // any length but zero
  Eigen::Vector3d spinCenter = Eigen::Vector3d::Zero();  // metres
  double spinRate = 0.0;                                 // rad/s

  bool moves() const { return !velocity.isZero(0.0) || !keys.empty() || spinRate != 0.0; }
  /// What ColliderMotion refuses: non-finite values, `velocity` with `keys`, key times that are
  /// negative or do not increase, a spin axis too short to normalise.
  SettingProblems validate() const;
};

/// A rigid pose: x_world = rotation · (x_rest − pivot) + pivot + translation. Float, as every
/// per-particle value of a tick.
struct ColliderPose {
  Eigen::Matrix3f rotation = Eigen::Matrix3f::Identity();
  Eigen::Vector3f pivot = Eigen::Vector3f::Zero();
  Eigen::Vector3f translation = Eigen::Vector3f::Zero();
};

/// The collider's pose over one tick. Between the tick's start and end the translation moves
/// linearly and the spin angle grows linearly (the tick's motion as one rigid segment: keys
/// between two ticks are not seen within the tick), so the collider's velocity is constant over
/// the tick: `linearVelocity` plus `angularVelocity` × (x − the moving pivot).
struct ColliderTickMotion {
  bool moving = false;
  ColliderPose start, end;
  double startAngle = 0.0, endAngle = 0.0;  // radians of spin at the tick's start and end
  Eigen::Vector3d spinAxis = Eigen::Vector3d::UnitY();        // unit
  Eigen::Vector3f linearVelocity = Eigen::Vector3f::Zero();   // m/s
  Eigen::Vector3f angularVelocity = Eigen::Vector3f::Zero();  // rad/s (axis · rate)

  /// The pose at fraction `f` of the tick (0: start, 1: end; those two exactly as stored).
  ColliderPose at(float f) const;
  /// The velocity (m/s) of the collider's material point at world position `x`, at fraction `f`.
  Eigen::Vector3f surfaceVelocity(const Eigen::Vector3f& x, float f) const;
};

class ColliderMotion {
 public:
  /// Throws std::invalid_argument with the first of settings.validate().
  explicit ColliderMotion(const ColliderMotionSettings& settings);
  bool moves() const { return s_.moves(); }
  /// The motion over tick `tick` of a step rate of `stepRateHz`, from exact times (tick / rate).
  ColliderTickMotion overTick(std::int64_t tick, std::int64_t stepRateHz) const;

 private:
  ColliderPose poseAt(std::int64_t tick, std::int64_t stepRateHz, double& angle) const;
  Eigen::Vector3d translationAt(std::int64_t tick, std::int64_t stepRateHz) const;
  ColliderMotionSettings s_;
  Eigen::Vector3d axis_;  // unit
};

}  // namespace tickfx
