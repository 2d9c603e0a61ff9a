// The smallest program built against an installed tickfx: one ball dropped for one second.
#include <cstdio>
#include <memory>

#include <tickfx/fields/Gravity.h>
#include <tickfx/particles/ParticleSystem.h>
#include <tickfx/particles/StateHash.h>

int main() {
  tickfx::SystemSettings settings;
  settings.stepRateHz = 60;
  settings.integrator = "velocity_verlet";

  tickfx::EmitterSettings ball;
  ball.bursts = {{0.0, 1}};  // one particle at t = 0, at rest at the origin

  tickfx::ForceSet forces;
  forces.add(std::make_unique<tickfx::Gravity>(Eigen::Vector3f(0.0f, -9.81f, 0.0f)));

  tickfx::ParticleSystem system(settings, {ball}, std::move(forces));
  for (int frame = 0; frame < 24; ++frame) system.advance(tickfx::frameDuration({24, 1}));

  // Velocity Verlet is exact for constant acceleration: y(1 s) = −9.81/2 m.
  const float y = system.pool().position().y[0];
  std::printf("ticks: %lld\n", static_cast<long long>(system.tickCount()));
  std::printf("y after 1 s: %.4f m (exact -4.9050)\n", y);
  std::printf("state-hash: %s\n", tickfx::hashToHex(tickfx::stateHash(system.pool())).c_str());
  return (y > -4.9051f && y < -4.9049f) ? 0 : 1;
}
