// tickfx check: validation and lint only; nothing is simulated or written.
#include <cstdio>

#include "app/Commands.h"
#include "app/LoadEffect.h"
#include "io/effect/EffectLint.h"
#include "io/effect/EffectParser.h"

namespace tickfx::app {

int checkCommand(Arguments& args) {
  if (args.flag("--help")) {
    std::fputs(
        "usage: tickfx check EFFECT.toml [--set key.path=value]...\n"
        "\n"
        "Validates EFFECT.toml (with the same overrides `tickfx run` takes) and prints every "
        "error\n"
        "and lint warning as FILE:LINE:COL: severity: key.path: message. Exit code 2 when there "
        "is\n"
        "an error, 0 otherwise (warnings do not fail).\n",
        stdout);
    return kExitOk;
  }
  const std::vector<std::string> overrides = args.values("--set");
  const std::string path = args.positionals(1, "one effect file: tickfx check EFFECT.toml")[0];
  const io::LoadResult load = loadEffectReporting(path, overrides);
  if (!load.ok()) {
    std::fprintf(stderr, "%s: %zu error(s)\n", path.c_str(), load.diagnostics.size());
    return kExitUsage;
  }
  const std::vector<io::Diagnostic> warnings = io::lintEffect(*load.effect);
  for (const io::Diagnostic& d : warnings) std::fprintf(stderr, "%s\n", d.format().c_str());
  std::printf("%s: ok, %zu warning(s)\n", path.c_str(), warnings.size());
  return kExitOk;
}

}  // namespace tickfx::app
