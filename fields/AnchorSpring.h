// Every particle tied to one fixed point by a damped spring.
#pragma once

#include <cmath>

#include "fields/ForceModule.h"

namespace tickfx {

/// a = −(k · (p − rest) + c · v) / m: a damped harmonic oscillator about `rest` (metres), with
/// stiffness `k` (N/m) and damping `c` (N·s/m). Pinned particles (inverse mass 0) feel nothing.
/// With k = m = 1 and no damping this is the oscillator of the integrator study.
class AnchorSpring final : public ForceModule {
 public:
  AnchorSpring(const Eigen::Vector3f& rest, float stiffness, float damping = 0.0f)
      : rest_(rest), k_(stiffness), c_(damping) {}
  std::string_view typeName() const override { return "anchor_spring"; }
  bool interleavesTicks() const override { return true; }
  bool arithmeticOnly() const override {
    return rest_.allFinite() && std::isfinite(k_) && std::isfinite(c_);
  }
  void accumulate(const ForceInput& in, RowRange rows, Vec3Rows& acceleration) const override;
  float stiffness() const { return k_; }
  float damping() const { return c_; }

 private:
  Eigen::Vector3f rest_;
  float k_;
  float c_;
};

}  // namespace tickfx
