// Structures: particles born together and joined by springs (ropes, cloth, soft clusters).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <string>
#include <variant>
#include <vector>

#include "particles/ParticlePool.h"
#include "particles/SettingProblem.h"
#include "particles/Spring.h"

namespace tickfx {

/// `count` particles evenly spaced from `start` to `end` (metres), each joined to the next.
struct RopeShape {
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  Eigen::Vector3d end = Eigen::Vector3d(1.0, 0.0, 0.0);
  int count = 10;  // >= 2
  bool pinStart = true;
  bool pinEnd = false;
};

/// Which particles of a cloth are pinned. Row 0 (along `axisU` from `origin`) is the top edge.
enum class ClothPins { None, TopCorners, TopEdge, AllCorners };

/// A `width` × `height` grid, `spacing` metres apart, from `origin` along the unit directions
/// `axisU` (columns) and `axisV` (rows). Structural springs join grid neighbours, shear springs
/// the diagonals, bend springs every second particle along rows and columns.
struct ClothShape {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d axisU = Eigen::Vector3d::UnitX();
  Eigen::Vector3d axisV = -Eigen::Vector3d::UnitY();
  int width = 10;   // >= 2
  int height = 10;  // >= 2
  double spacing = 0.1;
  ClothPins pins = ClothPins::TopCorners;
  double shearStiffnessScale = 0.5;  // shear springs' k relative to the structural k
  double bendStiffnessScale = 0.1;   // bend springs' k relative to the structural k
};

/// `count` particles uniform in a ball of `radius` (counter-based random positions), each joined to
/// every other within `linkRadius`, at the distance they were born at (a soft, jelly-like body).
struct ClusterShape {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0.5;
  int count = 100;
  double linkRadius = 0.2;
};

using StructureShape = std::variant<RopeShape, ClothShape, ClusterShape>;

/// A structure as an effect describes it. Units: seconds, kilograms, N/m, N·s/m, m/s.
struct StructureSettings {
  std::string name;
  StructureShape shape = RopeShape{};
  double time = 0.0;         // born at the first tick at or after this time
  double mass = 1.0;         // per particle (pinned particles have infinite mass)
  double stiffness = 100.0;  // k of its springs
  double damping = 0.0;      // c of its springs
  double breakRatio = 0.0;   // springs break past breakRatio · rest length; 0: never
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();         // initial, of every free particle
  double lifetime = std::numeric_limits<double>::infinity();  // seconds

  /// What buildStructure() refuses in these settings (empty: it accepts them), each problem keyed
  /// as effect files write it ("stiffness", "count", "end", "axis_v", "link_radius", ...).
  /// Numbers must be finite and in range; a rope's end at least shortestNormalisable<double>()
  /// from its start (it has a length); a cloth's axes long enough to normalise in double and not
  /// parallel (clothAxesParallel).
  SettingProblems validate() const;
};

/// True when both axes of `cloth` normalise (normalisable()) and are parallel: |û × v̂| <= 1e-6,
/// where the cloth would have no area. validate() refuses such a cloth at "axis_v".
bool clothAxesParallel(const ClothShape& cloth);

/// The particles of a structure and its springs, with spring ends as indices into `particles`.
struct StructureBuild {
  std::vector<ParticleInit> particles;
  std::vector<Spring> springs;  // a, b: indices into particles
};

/// Builds `settings` (a pure function of the settings, the effect seed and the structure's index,
/// which keys its random numbers). Throws std::invalid_argument with the first of
/// settings.validate().
StructureBuild buildStructure(const StructureSettings& settings, std::uint64_t seed,
                              std::uint32_t index);

}  // namespace tickfx
