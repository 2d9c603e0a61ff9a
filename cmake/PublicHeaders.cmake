# The headers `cmake --install` puts under include/tickfx: what a host includes, and what those
# include. tests/scripts/EmbedTest.cmake compiles each one alone against the install, so a
# public header that includes an internal one fails the embed test.

# Core (tickfx::tickfx): the system, its settings, the force modules and the integrator interface.
set(TICKFX_CORE_PUBLIC_HEADERS
  particles/Assert.h
  particles/Clock.h
  particles/Column.h
  particles/EmissionRate.h
  particles/Emitter.h
  particles/EventEmission.h
  particles/FixedStepDriver.h
  particles/LifeAttribute.h
  particles/LifeAttributeSet.h
  particles/NonfiniteState.h
  particles/ParticleEvent.h
  particles/ParticlePool.h
  particles/ParticleSystem.h
  particles/PhaseProfile.h
  particles/Random.h
  particles/RelaxedFlag.h
  particles/RenderDestination.h
  particles/RowViews.h
  particles/SettingProblem.h
  particles/Shard.h
  particles/Spring.h
  particles/StartsSpan.h
  particles/StateHash.h
  particles/Structure.h
  particles/TaskExecutor.h
  particles/TickInstant.h
  integrators/AdvectionScheme.h
  integrators/Integrator.h
  integrators/StepRows.h
  fields/AnchorSpring.h
  fields/Collider.h
  fields/ColliderMotion.h
  fields/ColliderSet.h
  fields/ForceModule.h
  fields/ForceSet.h
  fields/Gravity.h
  fields/LinearDrag.h
  fields/PeriodicWind.h
  fields/SpringNetwork.h
)

# COMPONENTS vdb (tickfx::vdb): vector fields from OpenVDB grids (their headers include none of
# OpenVDB's).
set(TICKFX_VDB_PUBLIC_HEADERS
  fields/vdb/AnalyticField.h
  fields/vdb/LevelSetCollider.h
  fields/vdb/VectorField.h
)

# COMPONENTS effects (tickfx::effects): effect files, loadEffect(), caches, and the umbrella
# <tickfx/tickfx.h> (installed as include/tickfx/tickfx.h).
set(TICKFX_EFFECTS_PUBLIC_HEADERS
  include/tickfx/tickfx.h
  io/util/AtomicFile.h
  io/util/Fingerprint.h
  io/util/UninitialisedVector.h
  io/cache/BackgroundWriter.h
  io/cache/CacheFormat.h
  io/cache/CsvCache.h
  io/cache/FrameCaches.h
  io/cache/FrameData.h
  io/cache/PlyCache.h
  io/cache/VdbCacheOptions.h
  io/cache/VdbPointCache.h
  io/effect/Diagnostics.h
  io/effect/EffectLint.h
  io/effect/EffectLoader.h
  io/effect/EffectParser.h
  io/effect/EffectSettings.h
  io/effect/SourceMap.h
)
