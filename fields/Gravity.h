// Uniform gravitational acceleration.
#pragma once

#include "fields/ForceModule.h"

namespace tickfx {

/// Adds a constant acceleration `g` (m/s²) to every particle, whatever its mass.
class Gravity final : public ForceModule {
 public:
  explicit Gravity(const Eigen::Vector3f& g = Eigen::Vector3f(0.0f, -9.81f, 0.0f)) : g_(g) {}
  std::string_view typeName() const override { return "gravity"; }
  bool interleavesTicks() const override { return true; }
  bool arithmeticOnly() const override { return g_.allFinite(); }
  bool uniformAcceleration(const ForceInput& in, Eigen::Vector3f& a) const override;
  void accumulate(const ForceInput& in, RowRange rows, Vec3Rows& acceleration) const override;
  const Eigen::Vector3f& acceleration() const { return g_; }

 private:
  Eigen::Vector3f g_;
};

}  // namespace tickfx
