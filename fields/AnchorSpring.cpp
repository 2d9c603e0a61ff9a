#include "fields/AnchorSpring.h"

namespace tickfx {

void AnchorSpring::accumulate(const ForceInput& in, RowRange rows, Vec3Column& a) const {
  const Eigen::Index b = rows.offset(), n = rows.count();
  const auto invMass = in.pool.inverseMass().segment(b, n);
  a.x.segment(b, n) -= (k_ * (in.position.x.segment(b, n) - rest_.x()) + c_ * in.velocity.x.segment(b, n)) * invMass;
  a.y.segment(b, n) -= (k_ * (in.position.y.segment(b, n) - rest_.y()) + c_ * in.velocity.y.segment(b, n)) * invMass;
  a.z.segment(b, n) -= (k_ * (in.position.z.segment(b, n) - rest_.z()) + c_ * in.velocity.z.segment(b, n)) * invMass;
}

}  // namespace tickfx
