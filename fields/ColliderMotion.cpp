#include "fields/ColliderMotion.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

#include "particles/DetMath.h"
#include "particles/ExactTime.h"

namespace tickfx {
namespace {

// Rodrigues' rotation by `angle` about the unit `axis`, in double from det::sincos, rounded to
// float once: the same bits on every build.
Eigen::Matrix3f rotationAbout(const Eigen::Vector3d& axis, double angle) {
  double s = 0.0, c = 1.0;
  det::sincos(angle, s, c);
  Eigen::Matrix3d k;
  k << 0.0, -axis.z(), axis.y(), axis.z(), 0.0, -axis.x(), -axis.y(), axis.x(), 0.0;
  const Eigen::Matrix3d r =
      Eigen::Matrix3d::Identity() * c + k * s + (axis * axis.transpose()) * (1.0 - c);
  return r.cast<float>();
}

}  // namespace

SettingProblems ColliderMotionSettings::validate() const {
  SettingProblems out;
  checkFinite(velocity, "velocity", out);
  if (!keys.empty() && !velocity.isZero(0.0)) {
    out.push_back({"keys", "is given with a velocity", "either velocity or keys"});
  }
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const std::string at = "keys." + std::to_string(i);
    const double t = keys[i].time;
    if (!(std::isfinite(t) && t >= 0.0 && t <= 1.0e9)) {
      out.push_back({at + ".time", "is " + settingNumber(t), "seconds in [0, 1e9]"});
    } else if (i > 0 && !(t > keys[i - 1].time)) {
      out.push_back({at + ".time",
                     "is not after the key before it (" + settingNumber(keys[i - 1].time) + ")",
                     "key times strictly increasing"});
    }
    checkFinite(keys[i].translate, at + ".translate", out);
  }
  if (!std::isfinite(spinRate)) {
    out.push_back({"spin.rate", "is " + settingNumber(spinRate), "a finite number of rad/s"});
  }
  checkFinite(spinCenter, "spin.center", out);
  if (spinRate != 0.0) checkDirection(spinAxis, "spin.axis", out);
  return out;
}

ColliderMotion::ColliderMotion(const ColliderMotionSettings& settings) : s_(settings) {
  throwIfAny("collider motion", s_.validate());
  axis_ = s_.spinRate != 0.0 ? Eigen::Vector3d(s_.spinAxis / s_.spinAxis.norm())
                             : Eigen::Vector3d::UnitY();
}

Eigen::Vector3d ColliderMotion::translationAt(std::int64_t tick, std::int64_t stepRateHz) const {
  const double t = static_cast<double>(tick) / static_cast<double>(stepRateHz);
  if (s_.keys.empty()) return s_.velocity * t;
  // Which keys the tick lies between is decided exactly (the key's first tick at or after its
  // time); the weight between them is one rounded double expression.
  std::size_t next = 0;
  while (next < s_.keys.size() && exact::tickAtOrAfter(s_.keys[next].time, stepRateHz) <= tick) {
    ++next;
  }
  if (next == 0) return s_.keys.front().translate;
  if (next == s_.keys.size()) return s_.keys.back().translate;
  const ColliderKey& a = s_.keys[next - 1];
  const ColliderKey& b = s_.keys[next];
  const double w = std::clamp((t - a.time) / (b.time - a.time), 0.0, 1.0);
  return a.translate + (b.translate - a.translate) * w;
}

ColliderPose ColliderMotion::poseAt(std::int64_t tick, std::int64_t stepRateHz,
                                    double& angle) const {
  ColliderPose pose;
  angle = s_.spinRate * (static_cast<double>(tick) / static_cast<double>(stepRateHz));
  if (s_.spinRate != 0.0) pose.rotation = rotationAbout(axis_, angle);
  pose.pivot = s_.spinCenter.cast<float>();
  pose.translation = translationAt(tick, stepRateHz).cast<float>();
  return pose;
}

ColliderTickMotion ColliderMotion::overTick(std::int64_t tick, std::int64_t stepRateHz) const {
  ColliderTickMotion m;
  m.moving = moves();
  if (!m.moving) return m;
  m.start = poseAt(tick, stepRateHz, m.startAngle);
  m.end = poseAt(tick + 1, stepRateHz, m.endAngle);
  const auto rate = static_cast<float>(stepRateHz);
  m.linearVelocity = (m.end.translation - m.start.translation) * rate;
  m.spinAxis = axis_;
  m.angularVelocity = (axis_ * s_.spinRate).cast<float>();
  return m;
}

ColliderPose ColliderTickMotion::at(float f) const {
  if (f == 0.0f) return start;
  if (f == 1.0f) return end;
  ColliderPose pose = start;
  pose.translation = start.translation + (end.translation - start.translation) * f;
  if (startAngle != endAngle) {
    pose.rotation = rotationAbout(spinAxis, startAngle + (endAngle - startAngle) * f);
  }
  return pose;
}

Eigen::Vector3f ColliderTickMotion::surfaceVelocity(const Eigen::Vector3f& x, float f) const {
  if (!moving) return Eigen::Vector3f::Zero();
  const Eigen::Vector3f centre =
      start.pivot + start.translation + (end.translation - start.translation) * f;
  return linearVelocity + angularVelocity.cross(x - centre);
}

}  // namespace tickfx
