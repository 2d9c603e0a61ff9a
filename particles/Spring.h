// A spring between two particles: the plain settings that structures build and the spring
// network (fields/SpringNetwork) applies.
#pragma once

#include <cstdint>

namespace tickfx {

/// A spring between the particles with ids `a` and `b`. Units: metres, N/m, N·s/m.
struct Spring {
  std::uint64_t a = 0;
  std::uint64_t b = 0;
  float restLength = 1.0f;  // metres
  float stiffness = 1.0f;   // k, N/m
  float damping = 0.0f;     // c, N·s/m, along the spring
  /// The spring breaks, for good, at the start of a tick where its length exceeds
  /// breakRatio · restLength; 0 means it never breaks.
  float breakRatio = 0.0f;
};

}  // namespace tickfx
