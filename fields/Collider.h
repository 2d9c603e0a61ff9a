// Colliders: shapes particles do not pass through, found on each tick's whole path.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "fields/ColliderMotion.h"
#include "particles/SettingProblem.h"

namespace tickfx {

namespace collide {
struct RowsJob;
}

enum class ColliderType { Plane, Sphere, Box, LevelSet };
/// Which side of the surface particles stay on: outside an obstacle, inside a container.
enum class ColliderSide { Outside, Inside };
/// What a contact does to the particle's velocity relative to the surface's (see respond()).
enum class ColliderResponse { Bounce, Slide, Stick, Kill };

/// Where a level set collider's signed-distance grid comes from (fields/vdb/LevelSetCollider.h):
/// a float grid of a .vdb file, a closed triangle mesh (OBJ or PLY) turned into a level set, or
/// a shape baked into one when the collider is made. Lengths in metres.
struct LevelSetSettings {
  enum class Source { File, Mesh, Bake };
  enum class Shape { Sphere, Box, Torus };
  Source source = Source::Bake;
  std::string file;              // File: the .vdb file, as written; `path` is where it is read from
  std::string grid = "surface";  // File: the float grid's name
  std::string mesh;  // Mesh: the OBJ or PLY file, as written; `path` is where it is read from
  std::string path;
  double voxelSize = 0.05;                           // Mesh and Bake: the grid's voxel edge, > 0
  Shape shape = Shape::Sphere;                       // Bake
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // Bake
  double radius = 1.0;                               // Bake sphere, > 0
  Eigen::Vector3d size = Eigen::Vector3d::Ones();    // Bake box edges, each > 0
  double majorRadius = 1.0, minorRadius = 0.25;      // Bake torus about y: 0 < minor < major
};

/// One collider, as an effect file's [[colliders]] entry writes it. Lengths in metres.
struct ColliderSettings {
  ColliderType type = ColliderType::Plane;
  // plane: the points x with normal · (x − point) = 0; `normal` points to its outside.
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();  // any length but zero
  // sphere and box
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 1.0;                                 // sphere, > 0
  Eigen::Vector3d size = Eigen::Vector3d::Ones();      // box edges, each > 0
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();  // box, degrees about x, then y, then z
  LevelSetSettings levelSet;                           // level_set

  ColliderSide side = ColliderSide::Outside;
  ColliderResponse response = ColliderResponse::Bounce;
  double restitution = 0.5;     // [0, 1]: the part of the normal speed a bounce keeps
  double friction = 0.0;        // >= 0: Coulomb's μ against the contact's normal impulse
  double particleRadius = 0.0;  // >= 0: the particles' collision radius
  ColliderMotionSettings motion;
  /// Whether the particles' contacts with this collider are recorded in Houdini's hit
  /// attributes (ColliderSet::kHitColumns), columns the pool then has.
  bool recordHits = false;

  /// What the collider refuses (empty: it accepts them): non-finite or out-of-range values, a
  /// normal too short to normalise, a container (side inside) no larger than a particle.
  SettingProblems validate() const;
};

/// A contact on a particle's path within a tick.
struct Contact {
  float fraction = 0.0f;  // of the tick, in [0, 1]: when the particle touches the surface
  Eigen::Vector3f point = Eigen::Vector3f::Zero();    // m: the particle's centre at the contact
  Eigen::Vector3f normal = Eigen::Vector3f::UnitY();  // unit, towards the side particles stay on
  Eigen::Vector3f surfaceVelocity = Eigen::Vector3f::Zero();  // m/s of the surface there
  Eigen::Vector3f restPoint = Eigen::Vector3f::Zero();  // `point` in the collider's rest frame
};

/// A collider (module boundary: one virtual call per particle that reaches it). Thread-safe for
/// concurrent const calls; beginTick() runs alone, before them.
///
/// The particle's path over a tick is the straight segment from where it starts the tick to
/// where the integrator put it; a moving collider is tested in its own frame, on the segment from
/// the start (in the collider's pose at the start) to the end (in its pose at the tick's end).
class Collider {
 public:
  explicit Collider(const ColliderSettings& settings);
  virtual ~Collider() = default;
  const ColliderSettings& settings() const { return settings_; }

  /// The collider's motion over tick `tick` (once per tick, on one thread).
  void beginTick(std::int64_t tick, std::int64_t stepRateHz);

  /// The earliest contact on the path from `a` at fraction `fromFraction` of the tick to `b` at
  /// the tick's end (world positions, metres), if the path goes further into the collider than
  /// margin() past its surface (plus the particles' radius); stores it in `out`. A path that
  /// starts inside gets a contact at its start, placed on the surface.
  virtual bool firstContact(const Eigen::Vector3f& a, float fromFraction, const Eigen::Vector3f& b,
                            Contact& out) const = 0;
  /// Rows [0, n) of paths from (ax, ay, az) at the tick's start to (bx, by, bz) at its end: sets
  /// flags[i] to 1 for every path that may touch the collider (every one firstContact() would
  /// find a contact on, and maybe more), leaving the others' flags as they are. A loop over the
  /// columns with no call a row: most particles are nowhere near most colliders.
  virtual void screen(const float* const a[3], const float* const b[3], std::size_t n,
                      std::uint8_t* flags) const = 0;
  /// A bound of screen() along one axis (0 x, 1 y, 2 z), valid until the next beginTick(): where
  /// it returns true, screen() flags no path whose two ends' coordinates on `axis` are both below
  /// `lo` or both above `hi`, whatever their others. A block's step then stores only that axis's
  /// start for the rows it rules out (ColliderSet::startsSpan()). False: no bound this tick.
  virtual bool screenSpan(int /*axis*/, float& /*lo*/, float& /*hi*/) const { return false; }
  /// ColliderSet's contact loop over a block's flagged rows, this collider the set's only one;
  /// returns the contacts made. The default calls firstContact() a contact; a shape collider
  /// runs the same loop with its test inlined (the same bits).
  virtual std::uint64_t contactRows(const collide::RowsJob& job) const;
  /// How far (m) a particle at world position `x` at the tick's end lies on the allowed side of
  /// the surface, the particles' radius taken off: negative inside. For tests and lints.
  float clearance(const Eigen::Vector3f& x) const;
  /// The same for the collider's pose at the start of tick `tick` of `stepRateHz`.
  float clearanceAt(const Eigen::Vector3f& x, std::int64_t tick, std::int64_t stepRateHz) const;
  /// The same for a point of the collider's rest frame (its shape as the settings place it).
  virtual float restClearance(const Eigen::Vector3f& rest) const = 0;
  /// Where contact `c`'s point is at the tick's end when it moves with the collider (the
  /// point itself for a still one): a particle out of contacts for the tick stays there.
  Eigen::Vector3f carried(const Contact& c) const;

  /// How far inside a surface a path may end without a contact: 8 float ulps of the largest of
  /// 1 m and the coordinates' magnitude. Every particle ends a tick with clearance() above
  /// −margin(); a contact places it at clearance() >= 0 in the collider's frame, and a particle
  /// resting on a surface lies within rounding of it, which is no contact.
  static float margin(float scale) { return std::max(1.0f, scale) * 0x1p-20f; }

  /// `v` after contact `c`: with u the surface's velocity and v_r = v − u split into its normal
  /// part v_n = (v_r · n) n and tangential part v_t, a contact approaching the surface
  /// (v_r · n < 0) gives bounce: u − e·v_n + v_t', slide: u + v_t', stick and kill: u, where v_t'
  /// is v_t shortened by Coulomb friction, |v_t'| = max(0, |v_t| − μ·(1 + e)·|v_r · n|) (e = 0
  /// for slide). A contact leaving the surface keeps v. Only + − × ÷ and √: the same bits on
  /// every build.
  Eigen::Vector3f respond(const Contact& c, const Eigen::Vector3f& v) const;

 protected:
  ColliderSettings settings_;
  ColliderMotion motion_;
  ColliderTickMotion tick_;
  float restitution_, friction_, radius_;  // the settings in the tick's precision
};

/// A plane, sphere or box collider (throws std::invalid_argument with the first of
/// settings.validate(), and for a level set: fields/vdb/LevelSetCollider.h makes those).
std::unique_ptr<Collider> makeCollider(const ColliderSettings& settings);

std::string_view colliderTypeName(ColliderType type);

}  // namespace tickfx
