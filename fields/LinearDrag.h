// Linear drag toward the velocity of the surrounding air.
#pragma once

#include <cmath>

#include "fields/ForceModule.h"

namespace tickfx {

/// a = k · (v_air − v): relaxes each particle's velocity toward `airVelocity` (m/s) at rate `k`
/// (1/s). Mass-independent, like Houdini's POP drag with its default "ignore mass".
class LinearDrag final : public ForceModule {
 public:
  LinearDrag(float k, const Eigen::Vector3f& airVelocity = Eigen::Vector3f::Zero())
      : k_(k), air_(airVelocity) {}
  std::string_view typeName() const override { return "drag"; }
  bool interleavesTicks() const override { return true; }
  bool arithmeticOnly() const override { return std::isfinite(k_) && air_.allFinite(); }
  void accumulate(const ForceInput& in, RowRange rows, Vec3Rows& acceleration) const override;
  bool linearDrag(float& k, Eigen::Vector3f& air) const override {
    k = k_;
    air = air_;
    return true;
  }

 private:
  float k_;
  Eigen::Vector3f air_;
};

}  // namespace tickfx
