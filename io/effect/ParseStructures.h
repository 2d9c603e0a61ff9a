// Internal to the effect parser (not installed): [[emitters]] entries of type "rope", "cloth" or
// "cluster", structures of particles joined by springs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include <toml++/toml.h>

#include "io/effect/EffectSettings.h"
#include "io/effect/TableReader.h"

namespace tickfx::io::detail {

// Entry `index` of [[emitters]], a structure of `type` ("rope", "cloth" or "cluster"), into `s`:
// the keys every structure reads, then its type's. A structure holds at most the smaller of 10⁶
// particles and `maxParticles`, and a cluster at most 10⁷ springs.
void readStructure(Context& cx, const toml::table& table, std::size_t index,
                   const std::string& type, std::int64_t maxParticles, StructureSettings& s);

}  // namespace tickfx::io::detail
