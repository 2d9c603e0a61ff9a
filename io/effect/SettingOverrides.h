// `--set key.path=value`: changing an effect from the command line without editing the file.
#pragma once

#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <toml++/toml.h>

#include "io/effect/Diagnostics.h"

namespace tickfx::io {

/// Which nodes of a parsed effect came from an override rather than from the file, so that a
/// finding about such a value names the override ("--set forces.1.frequency") instead of a line.
///
/// Holds addresses of nodes owned by the toml::table it was filled for: it is valid while that
/// table lives and changes only through applyOverrides.
class OverrideOrigins {
 public:
  /// "--set key.path" when `node` was put in the tree by an override (or created on its way to
  /// the key it sets), else nullptr.
  const std::string* labelOf(const toml::node& node) const;

  /// Records `node` and everything under it as coming from `label`.
  void mark(const toml::node& node, const std::string& label);
  /// Forgets `node` and everything under it (before the override replaces it).
  void unmark(const toml::node& node);

 private:
  std::unordered_map<const toml::node*, std::string> labels_;
};

/// What diagnostics about `overrideText` are filed under: "--set key.path" (the text left of '=',
/// trimmed), or "--set " and the whole trimmed text when no key path can be read from it.
std::string overrideLabel(std::string_view overrideText);

/// Applies `overrides`, each "key.path=value", in order, onto `root` (a parsed effect file, before
/// validation). The path is keys and array entry numbers joined by dots, entries counted from 0
/// ("forces.1.frequency", "emitters.0.bursts.0.count"). The value is read as a TOML value
/// (numbers, true/false, "quoted strings", arrays [1, 2, 3], inline tables {time = 1, count = 5});
/// a single word that is not a TOML value is taken as a string, so `simulation.integrator=rk4`
/// needs no quotes.
///
/// A key missing from an existing table is added (tables on the way are created), so defaults
/// can be overridden; validation then judges the key like any other. Array entries must exist.
/// Returns one error per override that could not be applied, its file being "--set key.path"
/// (or "--set " and the whole text when no key path can be read); those overrides are skipped.
std::vector<Diagnostic> applyOverrides(toml::table& root, const std::vector<std::string>& overrides,
                                       OverrideOrigins& origins);

}  // namespace tickfx::io
