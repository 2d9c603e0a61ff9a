// The embedding API: from an effect file to a running system in one call, errors as values.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "io/effect/Diagnostics.h"
#include "io/effect/EffectSettings.h"
#include "particles/ParticleSystem.h"

namespace tickfx {

/// One setting replaced before validation, as `tickfx run --set KEY=VALUE` replaces it: `key` is
/// a key path ("simulation.step_rate", "emitters.0.rate", entries counted from 0) and `value` a
/// TOML value as text ("240", "[0, 1, 0]", "rk4": a single word needs no quotes).
struct SettingOverride {
  std::string key;
  std::string value;
};

/// How loadEffect() builds the system.
struct LoadOptions {
  /// Worker threads in place of the effect's simulation.threads (0: all cores).
  std::optional<int> threads;
  /// false (a host advancing in real time: a game engine, a viewport): simulation.
  /// max_ticks_per_frame caps the ticks of one advance(), and what it drops is reported by
  /// advance(). true (a cache bake, a farm job): no cap, every tick a frame covers runs, as in
  /// `tickfx run`.
  bool offline = false;
  /// Run the effect's lint as `tickfx check` does and return its warnings too.
  bool lint = false;
};

/// What loadEffect() made: a system ready to advance, or why not.
struct LoadedEffect {
  /// The running system, owned by the caller; null when there is an error.
  std::unique_ptr<ParticleSystem> system;
  /// The effect as validated (its [output] fps and length, its seed, ...); empty on errors in
  /// the file.
  std::optional<io::EffectSettings> effect;
  /// Every error (the reason `system` is null) and, with LoadOptions::lint, every warning, in
  /// file order, exactly as `tickfx check` prints them: FILE:LINE:COL: error: key.path: message.
  std::vector<io::Diagnostic> diagnostics;
  /// io::effectFingerprint() of the file and the overrides, the effect's identity that
  /// checkpoints, VDB caches and hash logs record; 0 when there is an error.
  std::uint64_t fingerprint = 0;

  bool ok() const { return system != nullptr; }
  /// diagnostics, one format()ted line each, '\n'-terminated ("" when there are none).
  std::string text() const;
};

/// Reads the effect file at `path`, applies `overrides` in order, validates it and builds its
/// system (loading its vector fields, reading its point files). Never throws: every failure
/// (a missing or malformed file, a bad override, a field file that cannot be read, an
/// allocation failure) comes back as diagnostics in the result. The system gives, tick for tick,
/// the same state hashes as `tickfx run` of the same file and overrides.
LoadedEffect loadEffect(const std::filesystem::path& path,
                        const std::vector<SettingOverride>& overrides = {},
                        const LoadOptions& options = {}) noexcept;

/// `tickfx check` as a call: every error of the effect, or its lint warnings. Never throws.
std::vector<io::Diagnostic> checkEffect(
    const std::filesystem::path& path, const std::vector<SettingOverride>& overrides = {}) noexcept;

}  // namespace tickfx
