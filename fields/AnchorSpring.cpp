#include "fields/AnchorSpring.h"

namespace tickfx {

void AnchorSpring::accumulate(const ForceInput& in, RowRange rows, Vec3Rows& a) const {
  const ConstVec3Rows p = in.position.rows(rows);
  const ConstVec3Rows v = in.velocity.rows(rows);
  const auto invMass = in.pool.mass().segment(rows.offset(), rows.count()).unaryExpr([](float m) {
    return inverseMassOf(m);
  });
  a.x -= (k_ * (p.x - rest_.x()) + c_ * v.x) * invMass;
  a.y -= (k_ * (p.y - rest_.y()) + c_ * v.y) * invMass;
  a.z -= (k_ * (p.z - rest_.z()) + c_ * v.z) * invMass;
}

}  // namespace tickfx
