// Internal to the effect parser (not installed): the [output] table.
#pragma once

#include <toml++/toml.h>

#include "io/effect/EffectSettings.h"
#include "io/effect/TableReader.h"

namespace tickfx::io::detail {

// The [output] table into `out`: fps (an integer or a ratio string, a whole number of flicks a
// frame), seconds or frames (not both), formats (each cache format at most once), directory and
// the VDB options.
void readOutput(Context& cx, const toml::table& table, OutputSettings& out);

}  // namespace tickfx::io::detail
