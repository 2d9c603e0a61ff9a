// Internal to the effect parser (not installed): reading [[emitters]] entries. Particle
// emitters are read here; file emitters (ParseFileEmitters.h) and structures
// (ParseStructures.h) are told apart by their `type`.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

#include <toml++/toml.h>

#include "io/effect/EffectSettings.h"
#include "io/effect/TableReader.h"

namespace tickfx::io::detail {

// The keys every particle emitter reads after its shape (rate, start, stop, bursts, direction,
// speed, speed_jitter, spread, lifetime, lifetime_jitter, mass), through `r` over `table`, into
// `e`. A burst holds at most `maxParticles` particles.
void readEmission(Context& cx, const toml::table& table, TableReader& r, std::int64_t maxParticles,
                  EmitterSettings& e);

// Entry `index` of [[emitters]]: by its `type` a particle emitter, a file emitter or a structure,
// appended to effect.emitters or effect.structures (its entry to effect.structureEntries), and
// checked by the core's validate() when read without errors. An entry of an unknown type adds
// nothing and reports only its unknown keys. `names` maps each emitter name taken to its entry,
// to report a name given twice.
void readEmitterEntry(Context& cx, const toml::table& table, std::size_t index,
                      std::int64_t maxParticles, EffectSettings& effect,
                      std::map<std::string, std::size_t>& names);

}  // namespace tickfx::io::detail
