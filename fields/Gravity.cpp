#include "fields/Gravity.h"

namespace tickfx {

bool Gravity::uniformAcceleration(const ForceInput& /*in*/, Eigen::Vector3f& a) const {
  a = g_;
  return true;
}

void Gravity::accumulate(const ForceInput& /*in*/, RowRange /*rows*/, Vec3Rows& a) const {
  a.x += g_.x();
  a.y += g_.y();
  a.z += g_.z();
}

}  // namespace tickfx
