// libFuzzer target: the effect loader, loadEffect() with lint, as `tickfx run` and `tickfx check`
// call it: TOML text and `--set KEY=VALUE` overrides.
//
// An input is an effect file; each line of it that starts with "#%set " (a TOML comment, so the
// rest of the file parses as written) also becomes an override, "#%set simulation.step_rate=30".
// Any input must give a system or diagnostics, never an exception, a crash or a hang.
//
// A valid effect may ask for a bake of up to io::kMaxBakedVoxels (10⁸ voxels, minutes of work):
// legitimate, but a fuzzer that ran it would time out on it, as the first campaign did (22 frames
// of curl noise, 1.7·10⁷ voxels). An input whose bakes hold more than kBakeBudget voxels is parsed
// and validated, and not built. The bakes themselves are AnalyticField's, tested on their own.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "FuzzScratch.h"
#include "io/effect/EffectLoader.h"
#include "io/effect/EffectParser.h"
#include "io/effect/VectorFieldSource.h"

namespace {

std::vector<tickfx::SettingOverride> overridesIn(std::string_view text) {
  constexpr std::string_view kMark = "#%set ";
  std::vector<tickfx::SettingOverride> overrides;
  std::size_t at = 0;
  while (at < text.size()) {
    std::size_t end = text.find('\n', at);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(at, end - at);
    if (line.starts_with(kMark)) {
      const std::string_view setting = line.substr(kMark.size());
      const std::size_t eq = setting.find('=');
      if (eq != std::string_view::npos) {
        overrides.push_back(
            {std::string(setting.substr(0, eq)), std::string(setting.substr(eq + 1))});
      }
    }
    at = end + 1;
  }
  return overrides;
}

// vortex_smoke.toml's bake (15,625 voxels) is built; leaves.toml's (1.2·10⁵ over 11 frames) is
// only parsed: with it built, baking took 72 % of the campaign's time, at 170 executions/s.
constexpr double kBakeBudget = 2e4;

double bakedVoxels(const tickfx::io::EffectSettings& effect) {
  double voxels = 0.0;
  for (const tickfx::io::ForceSettings& force : effect.forces) {
    const auto* field = std::get_if<tickfx::io::VectorFieldSettings>(&force);
    if (field == nullptr || !field->bake) continue;
    const std::int64_t frames =
        field->fps > 0.0 ? std::int64_t{field->lastFrame} - field->firstFrame + 1 : 1;
    voxels += tickfx::io::measureBake(*field->bake, frames).total;
  }
  return voxels;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const std::vector<tickfx::SettingOverride> overrides = overridesIn(text);
  std::vector<std::string> assignments;
  for (const tickfx::SettingOverride& o : overrides) assignments.push_back(o.key + "=" + o.value);
  const tickfx::io::LoadResult parsed = tickfx::io::parseEffect(text, "effect.toml", assignments);
  if (parsed.ok() && bakedVoxels(*parsed.effect) > kBakeBudget) return 0;

  const auto path = tickfx::fuzz::writeScratch("effect.toml", data, size);
  tickfx::LoadOptions options;
  options.threads = 1;
  options.offline = true;
  options.lint = true;
  const auto loaded = tickfx::loadEffect(path, overrides, options);
  // Either a system or the reason there is none: an empty refusal would leave a user guessing.
  if (!loaded.ok() && loaded.diagnostics.empty()) __builtin_trap();
  return 0;
}
