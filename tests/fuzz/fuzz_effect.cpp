// libFuzzer target: the effect loader, loadEffect() with lint, as `tickfx run` and `tickfx check`
// call it: TOML text and `--set KEY=VALUE` overrides.
//
// An input is an effect file; each line of it that starts with "#%set " (a TOML comment, so the
// rest of the file parses as written) also becomes an override, "#%set simulation.step_rate=30".
// Any input must give a system or diagnostics, never an exception, a crash or a hang.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "FuzzScratch.h"
#include "io/EffectLoader.h"

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

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = tickfx::fuzz::writeScratch("effect.toml", data, size);
  tickfx::LoadOptions options;
  options.threads = 1;
  options.offline = true;
  options.lint = true;
  const auto loaded = tickfx::loadEffect(
      path, overridesIn(std::string_view(reinterpret_cast<const char*>(data), size)), options);
  // Either a system or the reason there is none: an empty refusal would leave a user guessing.
  if (!loaded.ok() && loaded.diagnostics.empty()) __builtin_trap();
  return 0;
}
