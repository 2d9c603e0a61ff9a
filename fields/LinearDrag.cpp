#include "fields/LinearDrag.h"

namespace tickfx {

void LinearDrag::accumulate(const ForceInput& in, RowRange rows, Vec3Rows& a) const {
  const ConstVec3Rows v = in.velocity.rows(rows);
  a.x += k_ * (air_.x() - v.x);
  a.y += k_ * (air_.y() - v.y);
  a.z += k_ * (air_.z() - v.z);
}

}  // namespace tickfx
