// tickfx's public face in one include: an effect file to a running system in one call
// (loadEffect), the system and its driver, the pool and the views a host copies from, and the
// errors and events that come back as values. Installed as <tickfx/tickfx.h>; link
// tickfx::effects. Hosts that build a system without an effect file include
// <tickfx/fields/ForceSet.h> and the force modules they use.
//
// Units throughout: metres, seconds, kilograms; velocities in m/s, accelerations in m/s². Time
// is counted in flicks (1/705 600 000 s, particles/Clock.h).
#pragma once

#include "io/effect/Diagnostics.h"
#include "io/effect/EffectLoader.h"
#include "particles/Clock.h"
#include "particles/NonfiniteState.h"
#include "particles/ParticlePool.h"
#include "particles/ParticleSystem.h"
#include "particles/RenderDestination.h"
#include "particles/SettingProblem.h"
#include "particles/StateHash.h"
