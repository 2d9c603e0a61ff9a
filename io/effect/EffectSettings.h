// An effect file as plain data: what the parser produces and the builder consumes. Nothing here
// simulates; the structs of the core (SystemSettings, EmitterSettings) are reused as they are.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "fields/Collider.h"
#include "fields/ForceSet.h"
#include "fields/vdb/VectorField.h"
#include "io/cache/CacheFormat.h"
#include "io/cache/VdbCacheOptions.h"
#include "io/effect/SourceMap.h"
#include "particles/Clock.h"
#include "particles/Emitter.h"
#include "particles/ParticleSystem.h"
#include "particles/Structure.h"

namespace tickfx::io {

/// The effect-file format this build reads and writes. Older versions are migrated on load.
inline constexpr std::int64_t kEffectFormatVersion = 1;

/// `type = "gravity"`: a constant acceleration.
struct GravitySettings {
  Eigen::Vector3d acceleration{0.0, -9.81, 0.0};  // m/s²
};

/// `type = "drag"`: a = k · (air_velocity − v).
struct DragSettings {
  double k = 0.0;                                         // 1/s
  Eigen::Vector3d airVelocity = Eigen::Vector3d::Zero();  // m/s
};

/// `type = "wind"`: a = direction · (base + amplitude · sin(2π · frequency · t + phase)).
struct WindSettings {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  // any length but zero
  double base = 0.0;                                     // m/s²
  double amplitude = 0.0;                                // m/s²
  double frequency = 0.0;                                // Hz
  double phase = 0.0;                                    // radians
};

/// `type = "anchor_spring"`: a = −(stiffness · (p − rest) + damping · v) / m.
struct AnchorSpringSettings {
  Eigen::Vector3d rest = Eigen::Vector3d::Zero();  // metres
  double stiffness = 0.0;                          // N/m
  double damping = 0.0;                            // N·s/m
};

/// The `bake` table of a vector field: an analytic field (fields/vdb/AnalyticField.h) baked into
/// grids in memory when the effect is built, so that an effect needs no .vdb file. Only the
/// parameters of `kind` are used; the others keep their defaults.
struct FieldBakeSettings {
  enum class Kind { Uniform, Vortex, Shear, CurlNoise };
  Kind kind = Kind::Uniform;
  double voxelSize = 0.1;                                 // metres
  Eigen::Vector3d min = Eigen::Vector3d::Constant(-1.0);  // metres: every voxel whose centre
  Eigen::Vector3d max = Eigen::Vector3d::Constant(1.0);   // i·voxelSize is in [min, max] is baked
  bool staggered = false;                                 // a MAC grid (face-centred components)
  Eigen::Vector3d background = Eigen::Vector3d::Zero();   // field units, outside the baked box
  // uniform: u = velocity
  Eigen::Vector3d velocity = Eigen::Vector3d::UnitX();  // field units (m/s)
  // vortex: u = omega · axis × (x − centre)
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // metres
  Eigen::Vector3d axis = Eigen::Vector3d::UnitY();   // any length but zero
  double omega = 1.0;                                // rad/s
  // shear: u = rate · (gradient·(x − origin)) · direction (both normalised)
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();      // metres
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  // any length but zero
  Eigen::Vector3d gradient = Eigen::Vector3d::UnitY();   // any length but zero
  double rate = 1.0;                                     // 1/s
  // curl-noise (AnalyticField::curlNoise)
  std::uint64_t seed = 0;
  double frequency = 3.0;  // rad/m
  double amplitude = 1.0;  // field units (m/s), the order of |u|
  int octaves = 4;
  double evolution = 0.0;  // rad/s: how fast the noise changes in time
};

/// The `kind` of a bake as written: "uniform", "vortex", "shear" or "curl-noise".
std::string_view fieldKindName(FieldBakeSettings::Kind kind);
/// Every bake kind, in the order of FieldBakeSettings::Kind.
const std::vector<std::string>& fieldKindNames();

/// `type = "vector_field"`: a Vec3 grid sampled in world space (fields/vdb/VectorField.h), from a
/// .vdb file (or a {frame} sequence of them) or baked in memory from `bake`. Exactly one of
/// `file` and `bake` is set.
struct VectorFieldSettings {
  std::string file;  // as written; may hold {frame}. Empty when baked
  std::string path;  // `file` resolved against the effect file's directory: what is loaded
  std::optional<FieldBakeSettings> bake;
  std::string grid = "vel";
  VectorField::Mode mode = VectorField::Mode::Force;
  /// Force: m/s² per field unit; Drag: the rate k in 1/s; Advect: m/s per field unit.
  double scale = 1.0;
  VectorField::Interpolation interpolation = VectorField::Interpolation::Linear;
  VectorField::Outside outside = VectorField::Outside::Background;
  // A sequence when fps > 0: frames firstFrame..lastFrame, frame f at (f − firstFrame)/fps s.
  double fps = 0.0;
  int firstFrame = 1;
  int lastFrame = 1;
  int framePadding = 4;  // digits {frame} is zero-padded to (files only)
};

/// One entry of [[forces]], in file order (the order the forces are summed in).
using ForceSettings = std::variant<GravitySettings, DragSettings, WindSettings,
                                   AnchorSpringSettings, VectorFieldSettings>;

/// The `type` of a force as written in effect files ("gravity", "drag", "wind", "anchor_spring",
/// "vector_field").
std::string_view forceTypeName(const ForceSettings& force);
/// Every force type, in the order above.
const std::vector<std::string>& forceTypeNames();

/// The `type` of an [[emitters]] entry: "particles" (an EmitterSettings, the default when `type`
/// is absent), "file" (an EmitterSettings whose shape is the PointListShape of a points file),
/// "rope", "cloth" or "cluster" (a StructureSettings).
const std::vector<std::string>& emitterTypeNames();
/// "rope", "cloth" or "cluster".
std::string_view structureTypeName(const StructureShape& shape);
/// The `pins` of a cloth as written: "none", "top_corners", "top_edge" or "corners".
std::string_view clothPinsName(ClothPins pins);
/// Every cloth `pins` value, in the order of ClothPins.
const std::vector<std::string>& clothPinsNames();

/// The mean number of neighbours of a particle of `cluster`: the other count − 1 particles times
/// the fraction of pairs of points uniform in a ball of radius R that lie within the link radius
/// s of each other, x³ − 9x⁴/16 + x⁶/32 with x = s/R (1 for x >= 2). A cluster has about
/// count · clusterNeighbours / 2 springs.
double clusterNeighbours(const ClusterShape& cluster);

/// Limits of a run, the same in effect files and on the command line.
inline constexpr double kMaxRunSeconds = 1e9;
inline constexpr std::int64_t kMaxRunFrames = 1'000'000'000;
inline constexpr std::int64_t kMaxThreads = 1024;

/// The [output] table: what `tickfx run` writes.
struct OutputSettings {
  FrameRate fps{24, 1};  // frames per second, an exact ratio
  /// The output's length: `frames` when the file gives it, else ⌈seconds · fps⌉ frames.
  double seconds = 10.0;
  std::optional<std::int64_t> frames;
  std::vector<CacheFormat> formats{CacheFormat::Csv};  // may be empty: simulate, write nothing
  VdbCacheOptions vdb;            // vdb_compression, vdb_positions: how VDB caches are stored
  std::string directory = "out";  // as written; relative to the working directory of the command
  /// Every collider records Houdini's hit attributes (ColliderSettings::recordHits), which the
  /// caches then carry.
  bool hits = false;

  /// Frames to write (>= 1).
  std::int64_t frameCount() const;
  /// frameCount() / fps, in seconds.
  double durationSeconds() const;
};

/// A whole effect file, validated: every field is in range for the builder.
struct EffectSettings {
  std::int64_t formatVersion = kEffectFormatVersion;  // after migration: always the current one
  SystemSettings simulation;
  /// The [[emitters]] entries of type "particles" and "file", in file order; an emitter's place
  /// here is its index in the random keys (ParticleSystem numbers them so). A file emitter's
  /// points are read when the effect is loaded: its shape holds them, not the file's name.
  std::vector<EmitterSettings> emitters;
  /// The [[emitters]] entries of type "rope", "cloth" or "cluster", in file order; a structure's
  /// place here is its index among the structures (the core derives its random keys from it).
  /// A file has at least one [[emitters]] entry of either kind.
  std::vector<StructureSettings> structures;
  /// The [[emitters]] entry each structure was read from (its key paths are "emitters.<entry>"),
  /// one per structure; empty for settings made in code (see structureKeyPath).
  std::vector<std::size_t> structureEntries;
  std::vector<ForceSettings> forces;
  /// [[colliders]], in file order (earlier colliders win a tie between contacts).
  std::vector<ColliderSettings> colliders;
  OutputSettings output;
  /// Where each value was written (for lint findings); defaults are not recorded.
  SourceMap sources;
};

/// The key path of structure `index` of `effect`: "emitters.<entry>" when structureEntries says
/// which entry it was read from, else "structures.<index>" (settings made in code).
std::string structureKeyPath(const EffectSettings& effect, std::size_t index);

/// The key path of emitter `index` of `effect.emitters`: "emitters.<entry>", the entries of
/// structures (structureEntries) skipped.
std::string emitterKeyPath(const EffectSettings& effect, std::size_t index);

}  // namespace tickfx::io
