#include "fields/Collider.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "fields/ColliderShapes.h"
#include "fields/ContactRows.h"
#include "fields/ShapeCollider.h"
#include "particles/DetMath.h"

namespace tickfx {
namespace {

using collide::V3;

void checkRange(double v, double lo, double hi, const char* key, const char* expected,
                SettingProblems& out) {
  if (!(v >= lo && v <= hi)) out.push_back({key, "is " + settingNumber(v), expected});
}

void checkPositive(double v, const std::string& key, SettingProblems& out) {
  if (!(v > 0.0 && std::isfinite(v))) out.push_back({key, "is " + settingNumber(v), "metres > 0"});
}

void validateLevelSet(const LevelSetSettings& l, SettingProblems& out) {
  using Source = LevelSetSettings::Source;
  if (l.source == Source::File) {
    if (l.file.empty()) out.push_back({"file", "is empty", "a .vdb file"});
    if (l.grid.empty()) out.push_back({"grid", "is empty", "a grid name"});
    return;
  }
  const std::string at = l.source == Source::Bake ? "bake." : "";
  if (l.source == Source::Mesh && l.mesh.empty()) {
    out.push_back({"mesh", "is empty", "an OBJ or PLY file"});
  }
  checkPositive(l.voxelSize, at + "voxel_size", out);
  if (l.source != Source::Bake) return;
  checkFinite(l.center, "bake.center", out);
  switch (l.shape) {
    case LevelSetSettings::Shape::Sphere:
      checkPositive(l.radius, "bake.radius", out);
      break;
    case LevelSetSettings::Shape::Box:
      for (int i = 0; i < 3; ++i) checkPositive(l.size[i], "bake.size." + std::to_string(i), out);
      break;
    case LevelSetSettings::Shape::Torus:
      checkPositive(l.minorRadius, "bake.minor_radius", out);
      if (!(l.majorRadius > l.minorRadius && std::isfinite(l.majorRadius))) {
        out.push_back({"bake.major_radius", "is " + settingNumber(l.majorRadius),
                       "metres > minor_radius (" + settingNumber(l.minorRadius) + ")"});
      }
      break;
  }
}

// Rotations about x, then y, then z by the given degrees: Rz · Ry · Rx, in double, rounded once.
Eigen::Matrix3f boxRotation(const Eigen::Vector3d& degrees) {
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  for (int axis = 0; axis < 3; ++axis) {
    double s = 0.0, c = 1.0;
    det::sincos(degrees[axis] * (det::kPi / 180.0), s, c);
    Eigen::Matrix3d q = Eigen::Matrix3d::Identity();
    const int i = (axis + 1) % 3, j = (axis + 2) % 3;
    q(i, i) = c;
    q(i, j) = -s;
    q(j, i) = s;
    q(j, j) = c;
    r = q * r;
  }
  return r.cast<float>();
}

}  // namespace

std::string_view colliderTypeName(ColliderType type) {
  switch (type) {
    case ColliderType::Plane:
      return "plane";
    case ColliderType::Sphere:
      return "sphere";
    case ColliderType::Box:
      return "box";
    case ColliderType::LevelSet:
      return "level_set";
  }
  return "?";
}

SettingProblems ColliderSettings::validate() const {
  SettingProblems out;
  const bool inside = side == ColliderSide::Inside;
  checkRange(restitution, 0.0, 1.0, "restitution", "a number in [0, 1]", out);
  checkRange(friction, 0.0, 1.0e30, "friction", "a number >= 0", out);
  checkRange(particleRadius, 0.0, 1.0e30, "radius", "metres >= 0", out);
  switch (type) {
    case ColliderType::Plane:
      checkFinite(point, "point", out);
      checkDirection(normal, "normal", out);
      break;
    case ColliderType::Sphere:
      checkFinite(center, "center", out);
      if (!(radius > 0.0 && std::isfinite(radius))) {
        out.push_back({"radius", "is " + settingNumber(radius), "metres > 0"});
      } else if (inside && !(radius > particleRadius)) {
        out.push_back(
            {"radius",
             "is no larger than the particles' radius (" + settingNumber(particleRadius) + ")",
             "a container larger than a particle"});
      }
      break;
    case ColliderType::Box:
      checkFinite(center, "center", out);
      checkFinite(rotation, "rotation", out);
      for (int i = 0; i < 3; ++i) {
        const std::string key = "size." + std::to_string(i);
        if (!(size[i] > 0.0 && std::isfinite(size[i]))) {
          out.push_back({key, "is " + settingNumber(size[i]), "metres > 0"});
        } else if (inside && !(0.5 * size[i] > particleRadius)) {
          out.push_back(
              {key, "is no wider than a particle (radius " + settingNumber(particleRadius) + ")",
               "a container wider than a particle"});
        }
      }
      break;
    case ColliderType::LevelSet:
      validateLevelSet(levelSet, out);
      break;
  }
  for (SettingProblem& p : motion.validate()) out.push_back(std::move(p));
  return out;
}

Collider::Collider(const ColliderSettings& settings)
    : settings_(settings),
      motion_((throwIfAny(std::string(colliderTypeName(settings.type)) + " collider",
                          settings.validate()),
               settings.motion)),
      restitution_(static_cast<float>(settings.restitution)),
      friction_(static_cast<float>(settings.friction)),
      radius_(static_cast<float>(settings.particleRadius)) {}

void Collider::beginTick(std::int64_t tick, std::int64_t stepRateHz) {
  tick_ = motion_.overTick(tick, stepRateHz);
}

float Collider::clearance(const Eigen::Vector3f& x) const {
  return restClearance(tick_.moving ? collide::toRest(tick_.end, x) : x);
}

float Collider::clearanceAt(const Eigen::Vector3f& x, std::int64_t tick,
                            std::int64_t stepRateHz) const {
  const ColliderTickMotion m = motion_.overTick(tick, stepRateHz);
  return restClearance(m.moving ? collide::toRest(m.start, x) : x);
}

Eigen::Vector3f Collider::carried(const Contact& c) const {
  if (!tick_.moving) return c.point;
  return collide::toWorld(tick_.end, c.restPoint);
}

std::uint64_t Collider::contactRows(const collide::RowsJob& job) const {
  const Collider* const self[] = {this};
  return collide::contactRows(job,
                              collide::VirtualColliders<const Collider* const*>{self, self + 1});
}

Eigen::Vector3f Collider::respond(const Contact& c, const Eigen::Vector3f& v) const {
  return collide::respondWith(settings_.response, restitution_, friction_, c, v);
}

std::unique_ptr<Collider> makeCollider(const ColliderSettings& s) {
  throwIfAny(std::string(colliderTypeName(s.type)) + " collider", s.validate());
  const bool container = s.side == ColliderSide::Inside;
  const auto r = static_cast<float>(s.particleRadius);
  switch (s.type) {
    case ColliderType::Plane: {
      const Eigen::Vector3d n = s.normal / s.normal.norm();
      collide::PlaneShape shape{s.point.cast<float>(), (container ? -n : n).cast<float>(), r};
      return std::make_unique<collide::ShapeCollider<collide::PlaneShape>>(s, shape);
    }
    case ColliderType::Sphere: {
      const auto rho =
          static_cast<float>(container ? s.radius - s.particleRadius : s.radius + s.particleRadius);
      collide::SphereShape shape{s.center.cast<float>(), rho, container};
      return std::make_unique<collide::ShapeCollider<collide::SphereShape>>(s, shape);
    }
    case ColliderType::Box: {
      const Eigen::Vector3d half =
          (s.size * 0.5).array() + (container ? -s.particleRadius : s.particleRadius);
      collide::BoxShape shape{s.center.cast<float>(), half.cast<float>(), boxRotation(s.rotation),
                              container};
      return std::make_unique<collide::ShapeCollider<collide::BoxShape>>(s, shape);
    }
    case ColliderType::LevelSet:
      throw std::invalid_argument(
          "level_set collider: made by makeLevelSetCollider (fields/vdb/LevelSetCollider.h)");
  }
  throw std::invalid_argument("unknown collider type");
}

}  // namespace tickfx
