#include "io/EffectBuilder.h"

#include <stdexcept>

#include "fields/AnchorSpring.h"
#include "fields/Gravity.h"
#include "fields/LinearDrag.h"
#include "fields/PeriodicWind.h"

namespace tickfx::io {
namespace {

struct MakeModule {
  std::unique_ptr<ForceModule> operator()(const GravitySettings& g) const {
    return std::make_unique<Gravity>(g.acceleration.cast<float>());
  }
  std::unique_ptr<ForceModule> operator()(const DragSettings& d) const {
    return std::make_unique<LinearDrag>(static_cast<float>(d.k), d.airVelocity.cast<float>());
  }
  std::unique_ptr<ForceModule> operator()(const WindSettings& w) const {
    PeriodicWind::Settings s;
    s.direction = w.direction.cast<float>();
    s.base = static_cast<float>(w.base);
    s.amplitude = static_cast<float>(w.amplitude);
    s.frequency = w.frequency;
    s.phase = w.phase;
    return std::make_unique<PeriodicWind>(s);
  }
  std::unique_ptr<ForceModule> operator()(const AnchorSpringSettings& a) const {
    return std::make_unique<AnchorSpring>(a.rest.cast<float>(), static_cast<float>(a.stiffness),
                                          static_cast<float>(a.damping));
  }
};

}  // namespace

ForceSet buildForces(const std::vector<ForceSettings>& forces) {
  ForceSet set;
  for (const ForceSettings& f : forces) set.add(std::visit(MakeModule{}, f));
  return set;
}

std::unique_ptr<ParticleSystem> buildSystem(const EffectSettings& effect,
                                            std::optional<int> threadsOverride) {
  SystemSettings settings = effect.simulation;
  if (threadsOverride) {
    if (*threadsOverride < 0) throw std::invalid_argument("threads must be >= 0");
    settings.threads = *threadsOverride;
  }
  return std::make_unique<ParticleSystem>(settings, effect.emitters, buildForces(effect.forces),
                                          effect.structures);
}

}  // namespace tickfx::io
