// EffectSettings → a running ParticleSystem. The only part of io/ that knows the simulation.
#pragma once

#include <memory>
#include <optional>
#include <stdexcept>
#include <vector>

#include "fields/ColliderSet.h"
#include "fields/ForceSet.h"
#include "fields/PeriodicWind.h"
#include "io/effect/Diagnostics.h"
#include "io/effect/EffectSettings.h"
#include "particles/ParticleSystem.h"

namespace tickfx::io {

/// A valid effect that cannot be built because of something outside the file: a vector field's
/// .vdb file missing or unreadable (loading happens here, not in the parser). Holds one error
/// at the force's key, e.g. `fx.toml:9:8: error: forces.1.file: fields/wind.vdb: grid 'vel': no
/// such file`; what() is its format(). Bad input like an effect error: `tickfx run` exits 2.
class BuildError : public std::runtime_error {
 public:
  explicit BuildError(Diagnostic diagnostic);
  const Diagnostic& diagnostic() const { return diagnostic_; }

 private:
  Diagnostic diagnostic_;
};

/// The wind module's settings for `wind`: values rounded from double to float once (the module
/// works in float), as buildForces() makes them.
PeriodicWind::Settings windModuleSettings(const WindSettings& wind);

/// What the modules buildForces() would make of `force` refuse (empty: they accept it), keyed
/// within the force's table as the modules' validate() functions give them: a wind direction
/// too short to normalise in float once rounded to it ("direction"), a bake's axis, direction or
/// gradient too short to normalise in double ("bake.axis"). parseEffect() reports these at load.
SettingProblems forceProblems(const ForceSettings& force);

/// The force modules of `forces`, in order. Values are rounded from double to float once, here
/// (the modules work in float). Vector fields are loaded from their files (or baked) now. Throws
/// BuildError (without a position: key path "forces.<i>.file" or ".bake") when a field cannot be
/// loaded, and std::invalid_argument for settings the modules refuse (forceProblems()): settings
/// from parseEffect() never are.
ForceSet buildForces(const std::vector<ForceSettings>& forces);

/// The colliders of `colliders`, in order. Level sets are read (a .vdb file, a mesh) or baked
/// now. Throws BuildError (without a position: key path "colliders.<i>.file", ".mesh" or
/// ".bake") when a level set cannot be made, and std::invalid_argument for settings the colliders
/// refuse (ColliderSettings::validate()): settings from parseEffect() never are.
ColliderSet buildColliders(const std::vector<ColliderSettings>& colliders);

/// A new system for `effect`: its [simulation] settings (with `threadsOverride`, when given, in
/// place of simulation.threads), its emitters, its structures, its forces and its colliders. The
/// caller owns the system; the effect is not referenced after the call. Throws BuildError, located
/// through effect.sources, when a vector field or a level set cannot be loaded;
/// std::invalid_argument as ParticleSystem does for settings out of range: settings from
/// parseEffect() never are.
std::unique_ptr<ParticleSystem> buildSystem(const EffectSettings& effect,
                                            std::optional<int> threadsOverride = std::nullopt);

/// buildSystem() for an offline run (caches, determinism checks): no wall clock to keep up with,
/// so max_ticks_per_frame is lifted and every tick a frame covers runs.
std::unique_ptr<ParticleSystem> buildOfflineSystem(const EffectSettings& effect,
                                                   std::optional<int> threadsOverride);

}  // namespace tickfx::io
