// Internal to the effect parser (not installed): [[forces]] entries.
#pragma once

#include <cstddef>
#include <optional>

#include <toml++/toml.h>

#include "io/effect/EffectSettings.h"
#include "io/effect/TableReader.h"

namespace tickfx::io::detail {

// Entry `index` of [[forces]], by its `type` (gravity, drag, wind, anchor_spring or vector_field,
// see ParseVectorFields.h). Returns nothing when the type is missing or unknown; then only the
// table's unknown keys are reported. A force read with errors is returned all the same (its
// refused values left at their defaults).
std::optional<ForceSettings> readForce(Context& cx, const toml::table& table, std::size_t index);

}  // namespace tickfx::io::detail
