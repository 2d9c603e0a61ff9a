#include "fields/PeriodicWind.h"

#include "particles/DetMath.h"

namespace tickfx {

SettingProblems PeriodicWind::Settings::validate() const {
  SettingProblems out;
  checkDirection(direction, "direction", out);
  return out;
}

PeriodicWind::PeriodicWind(const Settings& settings) : s_(settings) {
  throwIfAny("wind", s_.validate());
  s_.direction /= s_.direction.norm();
}

float PeriodicWind::strength(double t) const {
  // Reduce f·t to a fraction of a period first: 2π·f·t for large t would lose the phase.
  const double cycles = s_.frequency * t;
  const double fraction = cycles - static_cast<double>(static_cast<long long>(cycles));
  const double angle = 2.0 * det::kPi * fraction + s_.phase;
  return static_cast<float>(s_.base + s_.amplitude * det::sin(angle));
}

bool PeriodicWind::uniformAcceleration(const ForceInput& in, Eigen::Vector3f& a) const {
  const float w = strength(in.time());
  a = Eigen::Vector3f(s_.direction.x() * w, s_.direction.y() * w, s_.direction.z() * w);
  return true;
}

void PeriodicWind::accumulate(const ForceInput& in, RowRange /*rows*/, Vec3Rows& a) const {
  const float w = strength(in.time());
  a.x += s_.direction.x() * w;
  a.y += s_.direction.y() * w;
  a.z += s_.direction.z() * w;
}

}  // namespace tickfx
