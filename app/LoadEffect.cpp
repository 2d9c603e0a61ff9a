#include "app/LoadEffect.h"

#include <cstdio>

namespace tickfx::app {

io::LoadResult loadEffectReporting(const std::string& path,
                                   const std::vector<std::string>& overrides) {
  io::LoadResult load = io::loadEffectFile(path, overrides);
  for (const io::Diagnostic& d : load.diagnostics) std::fprintf(stderr, "%s\n", d.format().c_str());
  return load;
}

}  // namespace tickfx::app
