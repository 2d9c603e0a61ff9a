// Internal to the effect parser (not installed): [[colliders]] entries.
#pragma once

#include <cstddef>
#include <optional>

#include <toml++/toml.h>

#include "fields/Collider.h"
#include "io/effect/TableReader.h"

namespace tickfx::io::detail {

// Entry `index` of [[colliders]], by its `type` (plane, sphere or box). Returns nothing when the
// type is missing or unknown (then only the table's unknown keys are reported). A collider read
// with errors is returned all the same, its refused values left at their defaults; one read
// without errors has had ColliderSettings::validate() reported too.
std::optional<ColliderSettings> readCollider(Context& cx, const toml::table& table,
                                             std::size_t index);

}  // namespace tickfx::io::detail
