// Internal to the effect parser (not installed): bringing a document of an older effect format
// up to the current one (kEffectFormatVersion), in place.
#pragma once

#include <toml++/toml.h>

#include "io/effect/TableReader.h"

namespace tickfx::io::detail {

// Reads format_version and brings an older document up to the current version. Returns false
// when the document is of a version this build cannot read (nothing else is worth reporting); a
// missing or non-integer format_version is reported and the document read as the current
// version.
bool migrateToCurrent(Context& cx, toml::table& document);

}  // namespace tickfx::io::detail
