#include "io/effect/ColliderLint.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <variant>

#include "fields/vdb/LevelSetCollider.h"
#include "io/effect/EffectBuilder.h"

namespace tickfx::io::detail {
namespace {

Diagnostic warningAt(const EffectSettings& effect, const std::string& keyPath,
                     std::string message) {
  SourceLocation at = effect.sources.find(keyPath);
  if (at.file.empty()) at.file = "<effect>";
  return Diagnostic{Severity::Warning, at.file, at.line, at.column, keyPath, std::move(message)};
}

std::string metres(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", v);
  return text;
}

// Points every particle of the emitter starts within the hull of: its position, and its shape's
// extreme points.
std::vector<Eigen::Vector3f> startPoints(const EmitterSettings& e) {
  const Eigen::Vector3d c = e.position;
  std::vector<Eigen::Vector3d> p{c};
  if (const auto* s = std::get_if<SphereShape>(&e.shape)) {
    for (int a = 0; a < 3; ++a) {
      p.push_back(c + Eigen::Vector3d::Unit(a) * s->radius);
      p.push_back(c - Eigen::Vector3d::Unit(a) * s->radius);
    }
  } else if (const auto* b = std::get_if<BoxShape>(&e.shape)) {
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d sign((k & 1) ? 0.5 : -0.5, (k & 2) ? 0.5 : -0.5, (k & 4) ? 0.5 : -0.5);
      p.push_back(c + sign.cwiseProduct(b->size));
    }
  } else if (const auto* d = std::get_if<DiscShape>(&e.shape)) {
    const Eigen::Vector3d n = d->normal.normalized();
    const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
    for (const Eigen::Vector3d& w : {u, Eigen::Vector3d(-u), v, Eigen::Vector3d(-v)})
      p.push_back(c + w * d->radius);
  } else if (const auto* l = std::get_if<PointListShape>(&e.shape)) {
    p.clear();
    for (std::size_t i = 0; i < l->positions.size() && i < 100'000; ++i)
      p.push_back(c + l->positions[i].cast<double>());
  }
  std::vector<Eigen::Vector3f> out;
  for (const Eigen::Vector3d& q : p) out.push_back(q.cast<float>());
  return out;
}

// The fastest any point of the level set moves (m/s): its translation's fastest speed, plus the
// spin's rate times the farthest corner of its box from the spin's axis.
double fastestSpeed(const ColliderSettings& s, const LevelSetInfo& info) {
  const ColliderMotionSettings& m = s.motion;
  double linear = m.velocity.norm();
  for (std::size_t k = 1; k < m.keys.size(); ++k) {
    linear = std::max(linear, (m.keys[k].translate - m.keys[k - 1].translate).norm() /
                                  (m.keys[k].time - m.keys[k - 1].time));
  }
  double reach = 0.0;
  if (m.spinRate != 0.0) {
    const Eigen::Vector3d axis = m.spinAxis.normalized();
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d corner((k & 1) ? info.hi.x() : info.lo.x(),
                                   (k & 2) ? info.hi.y() : info.lo.y(),
                                   (k & 4) ? info.hi.z() : info.lo.z());
      const Eigen::Vector3d r = corner - m.spinCenter;
      reach = std::max(reach, (r - axis * r.dot(axis)).norm());
    }
  }
  return linear + std::abs(m.spinRate) * reach;
}

void lintLevelSet(const EffectSettings& effect, std::size_t j, const Collider& c,
                  std::vector<Diagnostic>& out) {
  const std::optional<LevelSetInfo> info = levelSetInfo(c);
  if (!info) return;
  const ColliderSettings& s = c.settings();
  const std::string path = "colliders." + std::to_string(j);
  const double voxel = info->voxelSize;
  if (s.particleRadius > 0.0 && voxel > s.particleRadius) {
    out.push_back(warningAt(effect, path,
                            "the level set's voxel (" + metres(voxel) + " m) is coarser than the " +
                                "particles' radius (" + metres(s.particleRadius) +
                                " m): contacts are " +
                                "found to within a voxel (use a voxel_size of at most " +
                                metres(s.particleRadius) + " m)"));
  }
  const double speed = fastestSpeed(s, *info);
  const double rate = static_cast<double>(effect.simulation.stepRateHz);
  if (speed / rate > voxel) {
    auto needed = static_cast<std::int64_t>(std::ceil(speed / voxel));
    while (speed / static_cast<double>(needed) > voxel) ++needed;
    out.push_back(
        warningAt(effect, path,
                  "the level set moves up to " + metres(speed) + " m/s, " + metres(speed / rate) +
                      " m a tick, more than a voxel (" + metres(voxel) +
                      " m): its contacts are found on the tick's straight " +
                      "path only (use a step_rate of at least " + std::to_string(needed) + " Hz)"));
  }
}

}  // namespace

void lintColliders(const EffectSettings& effect, const ColliderSet* built,
                   std::vector<Diagnostic>& out) {
  if (effect.colliders.empty()) {
    if (effect.output.hits) {
      out.push_back(warningAt(effect, "output.hits",
                              "the effect has no [[colliders]]: no particle records a hit"));
    }
    for (std::size_t i = 0; i < effect.emitters.size(); ++i) {
      const EmitterSettings& e = effect.emitters[i];
      if (e.sub.on != EmitterEvent::Collision) continue;
      out.push_back(warningAt(effect, emitterKeyPath(effect, i) + ".on",
                              "the effect has no [[colliders]]: \"" + e.sub.parent +
                                  "\" never collides, and \"" + e.name + "\" never emits"));
    }
    return;
  }
  ColliderSet owned;
  if (built == nullptr) {
    try {
      owned = buildColliders(effect.colliders);
    } catch (const BuildError& e) {
      out.push_back(warningAt(effect, e.diagnostic().keyPath,
                              e.diagnostic().message + " (tickfx run stops at this)"));
      return;
    }
    built = &owned;
  }
  for (std::size_t i = 0; i < effect.emitters.size(); ++i) {
    const std::vector<Eigen::Vector3f> points = startPoints(effect.emitters[i]);
    for (std::size_t j = 0; j < built->size(); ++j) {
      const Collider& c = built->collider(j);
      const bool inside = std::all_of(points.begin(), points.end(), [&](const Eigen::Vector3f& p) {
        return c.clearanceAt(p, 0, effect.simulation.stepRateHz) < 0.0f;  // where they start
      });
      if (!inside) continue;
      out.push_back(warningAt(effect, "emitters." + std::to_string(i) + ".position",
                              "every particle of emitter \"" + effect.emitters[i].name +
                                  "\" starts inside " + "colliders." + std::to_string(j) + " (a " +
                                  std::string(colliderTypeName(c.settings().type)) +
                                  "): its first tick puts them " +
                                  "on the collider's surface (move the emitter or the collider)"));
    }
  }
  for (std::size_t j = 0; j < built->size(); ++j) lintLevelSet(effect, j, built->collider(j), out);
}

}  // namespace tickfx::io::detail
