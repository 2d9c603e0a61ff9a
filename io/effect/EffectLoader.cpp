#include "io/effect/EffectLoader.h"

#include <exception>
#include <new>

#include "fields/ForceSet.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectLint.h"
#include "io/effect/EffectParser.h"

namespace tickfx {
namespace {

std::vector<std::string> overrideTexts(const std::vector<SettingOverride>& overrides) {
  std::vector<std::string> texts;
  texts.reserve(overrides.size());
  for (const SettingOverride& o : overrides) texts.push_back(o.key + "=" + o.value);
  return texts;
}

// A failure with no place in the file: the file is named, the position left out.
io::Diagnostic fileError(const std::filesystem::path& path, const std::string& message) {
  io::Diagnostic d;
  d.file = path.string();
  d.message = message;
  return d;
}

// lintEffect() may load fields (BuildError) and the builder may throw what the core throws.
void appendLint(const io::EffectSettings& effect, const ForceSet* built,
                std::vector<io::Diagnostic>& out) {
  std::vector<io::Diagnostic> warnings = io::lintEffect(effect, built);
  out.insert(out.end(), warnings.begin(), warnings.end());
}

}  // namespace

std::string LoadedEffect::text() const {
  std::string all;
  for (const io::Diagnostic& d : diagnostics) all += d.format() + "\n";
  return all;
}

LoadedEffect loadEffect(const std::filesystem::path& path,
                        const std::vector<SettingOverride>& overrides,
                        const LoadOptions& options) noexcept {
  LoadedEffect result;
  try {
    const std::vector<std::string> texts = overrideTexts(overrides);
    io::LoadResult load = io::loadEffectFile(path, texts);
    result.diagnostics = std::move(load.diagnostics);
    if (!load.ok()) return result;
    result.effect = std::move(load.effect);
    try {
      result.system = options.offline ? io::buildOfflineSystem(*result.effect, options.threads)
                                      : io::buildSystem(*result.effect, options.threads);
    } catch (const io::BuildError& e) {
      result.diagnostics.push_back(e.diagnostic());
      return result;
    }
    if (options.lint) appendLint(*result.effect, &result.system->forces(), result.diagnostics);
    io::sortDiagnostics(result.diagnostics);
    result.fingerprint = load.fingerprint;
  } catch (const std::bad_alloc&) {
    result.system.reset();
    result.fingerprint = 0;
    result.diagnostics.push_back(fileError(path, "out of memory while loading the effect"));
  } catch (const std::exception& e) {
    result.system.reset();
    result.fingerprint = 0;
    result.diagnostics.push_back(fileError(path, e.what()));
  }
  return result;
}

std::vector<io::Diagnostic> checkEffect(const std::filesystem::path& path,
                                        const std::vector<SettingOverride>& overrides) noexcept {
  std::vector<io::Diagnostic> diagnostics;
  try {
    const io::LoadResult load = io::loadEffectFile(path, overrideTexts(overrides));
    diagnostics = load.diagnostics;
    if (!load.ok()) return diagnostics;
    try {
      appendLint(*load.effect, nullptr, diagnostics);
    } catch (const io::BuildError& e) {
      diagnostics.push_back(e.diagnostic());
    }
    io::sortDiagnostics(diagnostics);
  } catch (const std::exception& e) {
    diagnostics.push_back(fileError(path, e.what()));
  }
  return diagnostics;
}

}  // namespace tickfx
