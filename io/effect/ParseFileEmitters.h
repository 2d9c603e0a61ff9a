// Internal to the effect parser (not installed): [[emitters]] entries of type "file", particle
// emitters whose particles are born at the points of a file.
#pragma once

#include <cstddef>
#include <cstdint>

#include <toml++/toml.h>

#include "io/effect/EffectSettings.h"
#include "io/effect/TableReader.h"

namespace tickfx::io::detail {

// Entry `index` of [[emitters]], of type "file", into `e`: the emission keys of a particle
// emitter, and the points of `file` (relative to the effect file) as its PointListShape, read
// here. Without rate and bursts, one burst of every point at `start`, of at most `maxParticles`.
void readFileEmitter(Context& cx, const toml::table& table, std::size_t index,
                     std::int64_t maxParticles, EmitterSettings& e);

}  // namespace tickfx::io::detail
