// Reading effect files: TOML text → validated EffectSettings, or every error in the file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/effect/Diagnostics.h"
#include "io/effect/EffectSettings.h"

namespace tickfx::io {

/// What a load produced: the effect when the file (with its overrides) has no error, and every
/// error found, sorted by position (see sortDiagnostics). Lint warnings are not included: run
/// lintEffect() on the effect for those.
struct LoadResult {
  std::optional<EffectSettings> effect;
  std::vector<Diagnostic> diagnostics;
  /// effectFingerprint() of the very text parsed and the overrides, whether or not it loaded
  /// (0 when the file could not be read): the effect's identity for checkpoints, caches and hash
  /// logs, from the same bytes as the effect, so an edit between the two cannot split them.
  std::uint64_t fingerprint = 0;

  bool ok() const { return effect.has_value(); }
};

/// Reads, overrides and validates the effect file at `path`. Diagnostics name the file as `path`
/// is written. A file that cannot be read gives one error without a position.
LoadResult loadEffectFile(const std::filesystem::path& path,
                          const std::vector<std::string>& overrides = {});

/// The same for effect text already in memory; `fileName` is what diagnostics call the file.
///
/// The steps, in order: parse the TOML (malformed TOML gives one error at toml++'s position: the
/// parser stops there); read `format_version` and migrate a document of an older version to the
/// current one in place (overrides are written against the current schema); apply the overrides
/// (see applyOverrides); validate the whole document, so that every error of the file is
/// reported at once.
LoadResult parseEffect(std::string_view text, std::string_view fileName,
                       const std::vector<std::string>& overrides = {});

}  // namespace tickfx::io
