// The first-order scheme an integrator runs when the forces prescribe velocity (advection).
#pragma once

#include <string_view>

namespace tickfx {

/// The explicit Runge–Kutta scheme an integrator uses when the forces prescribe velocity
/// (ForceSet::prescribesVelocity). With v := u(x, t) the second-order equations of motion
/// collapse to x' = u(x, t), and each integrator becomes its first-order counterpart:
///  - Euler (explicit and semi-implicit Euler, position Verlet): x += h·u(x, t). First order.
///  - Midpoint: x += h·u(x + (h/2)·u(x, t), t + h/2). Second order.
///  - Heun (velocity Verlet: the trapezoid of its velocity update): with k1 = u(x, t) and
///    k2 = u(x + h·k1, t + h), x += h·(k1 + k2)/2. Second order.
///  - RungeKutta4 (rk4): the classic four stages at t, t + h/2, t + h/2, t + h. Fourth order.
/// Orders 1, 2 (midpoint) and 4 are evaluated exactly as openvdb::tools::PointAdvect evaluates
/// them in float, so a float grid gives the same bits as PointAdvect (tested).
enum class AdvectionScheme { Euler, Midpoint, Heun, RungeKutta4 };

/// "euler", "midpoint", "heun", "rk4".
std::string_view advectionSchemeName(AdvectionScheme scheme);
/// The global order of the position error for smooth u: 1, 2 or 4.
int advectionOrder(AdvectionScheme scheme);

}  // namespace tickfx
