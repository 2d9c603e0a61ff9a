#include "io/effect/EffectBuilder.h"

#include <limits>
#include <stdexcept>

#include "fields/AnchorSpring.h"
#include "fields/ColliderSet.h"
#include "fields/Gravity.h"
#include "fields/LinearDrag.h"
#include "fields/PeriodicWind.h"
#include "fields/vdb/LevelSetCollider.h"
#include "io/effect/VectorFieldSource.h"
#include "io/mesh/MeshFile.h"

namespace tickfx::io {
namespace {

struct MakeModule {
  std::unique_ptr<ForceModule> operator()(const GravitySettings& g) const {
    return std::make_unique<Gravity>(g.acceleration.cast<float>());
  }
  std::unique_ptr<ForceModule> operator()(const DragSettings& d) const {
    return std::make_unique<LinearDrag>(static_cast<float>(d.k), d.airVelocity.cast<float>());
  }
  std::unique_ptr<ForceModule> operator()(const WindSettings& w) const {
    return std::make_unique<PeriodicWind>(windModuleSettings(w));
  }
  std::unique_ptr<ForceModule> operator()(const AnchorSpringSettings& a) const {
    return std::make_unique<AnchorSpring>(a.rest.cast<float>(), static_cast<float>(a.stiffness),
                                          static_cast<float>(a.damping));
  }
  std::unique_ptr<ForceModule> operator()(const VectorFieldSettings& v) const {
    return loadVectorField(v);
  }
};

}  // namespace

PeriodicWind::Settings windModuleSettings(const WindSettings& wind) {
  PeriodicWind::Settings s;
  s.direction = wind.direction.cast<float>();
  s.base = static_cast<float>(wind.base);
  s.amplitude = static_cast<float>(wind.amplitude);
  s.frequency = wind.frequency;
  s.phase = wind.phase;
  return s;
}

SettingProblems forceProblems(const ForceSettings& force) {
  if (const auto* wind = std::get_if<WindSettings>(&force)) {
    return windModuleSettings(*wind).validate();
  }
  if (const auto* field = std::get_if<VectorFieldSettings>(&force); field && field->bake) {
    SettingProblems problems = analyticFieldProblems(*field->bake);
    for (SettingProblem& p : problems) p.key = "bake." + p.key;
    return problems;
  }
  return {};
}

BuildError::BuildError(Diagnostic diagnostic)
    : std::runtime_error(diagnostic.format()), diagnostic_(std::move(diagnostic)) {}

ForceSet buildForces(const std::vector<ForceSettings>& forces) {
  ForceSet set;
  for (std::size_t i = 0; i < forces.size(); ++i) {
    std::unique_ptr<ForceModule> module;
    try {
      module = std::visit(MakeModule{}, forces[i]);
    } catch (const std::runtime_error& e) {
      // Only loading a field reads anything outside the settings: VectorField's message names
      // the file and the grid.
      const auto* field = std::get_if<VectorFieldSettings>(&forces[i]);
      if (field == nullptr) throw;
      const std::string key = "forces." + std::to_string(i) + (field->bake ? ".bake" : ".file");
      throw BuildError(Diagnostic{Severity::Error, "", 0, 0, key, e.what()});
    }
    set.add(std::move(module));
  }
  return set;
}

ColliderSet buildColliders(const std::vector<ColliderSettings>& colliders) {
  ColliderSet set;
  for (std::size_t i = 0; i < colliders.size(); ++i) {
    const ColliderSettings& c = colliders[i];
    if (c.type != ColliderType::LevelSet) {
      set.add(makeCollider(c));
      continue;
    }
    // A level set reads a file or bakes a grid: its failures name the key that led there.
    using Source = LevelSetSettings::Source;
    const std::string key = "colliders." + std::to_string(i) +
                            (c.levelSet.source == Source::File   ? ".file"
                             : c.levelSet.source == Source::Mesh ? ".mesh"
                                                                 : ".bake");
    try {
      if (c.levelSet.source == Source::Mesh) {
        const TriangleMesh mesh = readMeshFile(c.levelSet.path);
        set.add(makeLevelSetCollider(c, &mesh));
      } else {
        set.add(makeLevelSetCollider(c));
      }
    } catch (const std::runtime_error& e) {
      throw BuildError(Diagnostic{Severity::Error, "", 0, 0, key, e.what()});
    }
  }
  return set;
}

std::unique_ptr<ParticleSystem> buildSystem(const EffectSettings& effect,
                                            std::optional<int> threadsOverride) {
  SystemSettings settings = effect.simulation;
  if (threadsOverride) {
    if (*threadsOverride < 0) throw std::invalid_argument("threads must be >= 0");
    settings.threads = *threadsOverride;
  }
  ForceSet forces;
  ColliderSet colliders;
  try {
    forces = buildForces(effect.forces);
    std::vector<ColliderSettings> colliderSettings = effect.colliders;
    for (ColliderSettings& c : colliderSettings) c.recordHits = c.recordHits || effect.output.hits;
    colliders = buildColliders(colliderSettings);
  } catch (const BuildError& e) {
    // The error at its key's place in the file.
    Diagnostic d = e.diagnostic();
    const SourceLocation at = effect.sources.find(d.keyPath);
    d.file = at.file.empty() ? "<effect>" : at.file;  // "<effect>": settings built in code
    d.line = at.line;
    d.column = at.column;
    throw BuildError(std::move(d));
  }
  return std::make_unique<ParticleSystem>(settings, effect.emitters, std::move(forces),
                                          effect.structures, std::move(colliders));
}

std::unique_ptr<ParticleSystem> buildOfflineSystem(const EffectSettings& effect,
                                                   std::optional<int> threadsOverride) {
  EffectSettings offline = effect;
  offline.simulation.maxTicksPerFrame = std::numeric_limits<std::int64_t>::max();
  return buildSystem(offline, threadsOverride);
}

}  // namespace tickfx::io
