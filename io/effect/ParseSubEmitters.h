// Internal to the effect parser (not installed): the keys that make an [[emitters]] entry a
// sub-emitter, its attributes over life, and the checks across entries (parents, cycles).
#pragma once

#include <string>
#include <vector>

#include "io/effect/EffectSettings.h"
#include "io/effect/TableReader.h"

namespace tickfx::io::detail {

// The sub-emitter keys of a particle emitter, in the order messages list them.
const std::vector<std::string>& subEmitterKeys();

// parent, on, count, count_range, inherit_velocity, inherit, first_only: into e.sub. Without a
// parent every other of these keys is an error at the key.
void readSubEmitter(Context& cx, TableReader& r, EmitterSettings& e);

// `direction = "normal"`: the collision normal (sets e.sub.alongNormal). Returns whether the
// entry's direction is that string (then the caller does not read it as a vector).
bool readNormalDirection(Context& cx, TableReader& r, EmitterSettings& e);

// The `attributes` table: NAME = constant | {value = v} | {random = [low, high]} |
// {ramp = [[nage, value], ...], interpolation = "linear" | "smooth" | "constant"}, values numbers
// or, for Cd, [r, g, b].
void readLifeAttributes(Context& cx, TableReader& r, EmitterSettings& e);

// After every entry: each parent names an emitter (did-you-mean when close), no cycle, chains
// at most kMaxSubEmitterDepth deep, inherited attributes the parent has. Errors at the entries'
// keys.
void checkSubEmitters(Context& cx, const EffectSettings& effect);

}  // namespace tickfx::io::detail
