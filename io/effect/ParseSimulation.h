// Internal to the effect parser (not installed): the [simulation] table.
#pragma once

#include <toml++/toml.h>

#include "io/effect/TableReader.h"
#include "particles/ParticleSystem.h"

namespace tickfx::io::detail {

// The [simulation] table into `s`: step_rate (required), integrator, seed, max_particles,
// max_ticks_per_frame, overrun, threads and nonfinite.
void readSimulation(Context& cx, const toml::table& table, SystemSettings& s);

}  // namespace tickfx::io::detail
