#include "fields/LinearDrag.h"

namespace tickfx {

void LinearDrag::accumulate(const ForceInput& in, RowRange rows, Vec3Column& a) const {
  const Eigen::Index b = rows.offset(), n = rows.count();
  a.x.segment(b, n) += k_ * (air_.x() - in.velocity.x.segment(b, n));
  a.y.segment(b, n) += k_ * (air_.y() - in.velocity.y.segment(b, n));
  a.z.segment(b, n) += k_ * (air_.z() - in.velocity.z.segment(b, n));
}

}  // namespace tickfx
