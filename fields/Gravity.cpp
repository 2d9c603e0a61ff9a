#include "fields/Gravity.h"

namespace tickfx {

void Gravity::accumulate(const ForceInput& /*in*/, RowRange rows, Vec3Column& a) const {
  a.x.segment(rows.offset(), rows.count()) += g_.x();
  a.y.segment(rows.offset(), rows.count()) += g_.y();
  a.z.segment(rows.offset(), rows.count()) += g_.z();
}

}  // namespace tickfx
