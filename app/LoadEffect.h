// Loading the effect file a command names, as every command does it.
#pragma once

#include <string>
#include <vector>

#include "io/effect/EffectParser.h"

namespace tickfx::app {

/// io::loadEffectFile(path, overrides), every diagnostic (errors and lint warnings) printed to
/// stderr one a line, `FILE:LINE:COL: error: ...`, before the caller looks at the result.
io::LoadResult loadEffectReporting(const std::string& path,
                                   const std::vector<std::string>& overrides);

}  // namespace tickfx::app
