#include <stdexcept>
#include <string>

#include "integrators/ExplicitEuler.h"
#include "integrators/Midpoint.h"
#include "integrators/PositionVerlet.h"
#include "integrators/RungeKutta4.h"
#include "integrators/SemiImplicitEuler.h"
#include "integrators/VelocityVerlet.h"

namespace tickfx {

const std::vector<std::string>& integratorNames() {
  static const std::vector<std::string> names = {"explicit_euler",  "semi_implicit_euler",
                                                 "midpoint",        "position_verlet",
                                                 "velocity_verlet", "rk4"};
  return names;
}

std::unique_ptr<Integrator> makeIntegrator(std::string_view name) {
  if (name == "explicit_euler") return std::make_unique<ExplicitEuler>();
  if (name == "semi_implicit_euler") return std::make_unique<SemiImplicitEuler>();
  if (name == "midpoint") return std::make_unique<Midpoint>();
  if (name == "position_verlet") return std::make_unique<PositionVerlet>();
  if (name == "velocity_verlet") return std::make_unique<VelocityVerlet>();
  if (name == "rk4") return std::make_unique<RungeKutta4>();
  throw std::invalid_argument("unknown integrator '" + std::string(name) + "'");
}

}  // namespace tickfx
