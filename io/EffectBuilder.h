// EffectSettings → a running ParticleSystem. The only part of io/ that knows the simulation.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "fields/ForceSet.h"
#include "io/EffectSettings.h"
#include "particles/ParticleSystem.h"

namespace tickfx::io {

/// The force modules of `forces`, in order. Values are rounded from double to float once, here
/// (the modules work in float). Throws std::invalid_argument for settings the modules refuse (a
/// zero wind direction): settings from parseEffect() never are.
ForceSet buildForces(const std::vector<ForceSettings>& forces);

/// A new system for `effect`: its [simulation] settings (with `threadsOverride`, when given, in
/// place of simulation.threads), its emitters, its structures and its forces. The caller owns the
/// system; the effect is not referenced after the call. Throws std::invalid_argument as
/// ParticleSystem does for settings out of range: settings from parseEffect() never are.
std::unique_ptr<ParticleSystem> buildSystem(const EffectSettings& effect,
                                            std::optional<int> threadsOverride = std::nullopt);

}  // namespace tickfx::io
