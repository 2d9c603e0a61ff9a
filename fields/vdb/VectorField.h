// A force module that samples a vector grid from an OpenVDB file (one grid, or a sequence of
// frames). OpenVDB stays inside VectorField.cpp: this header includes none of it.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>

#include "fields/ForceModule.h"

namespace tickfx {

/// The file of frame `frame` of the sequence `pattern`: its first "{frame}" replaced by the frame
/// number zero-padded to `padding` digits (a minus sign before the digits of a negative frame).
/// `pattern` unchanged when it has no "{frame}". VectorField loads a sequence from these names;
/// `tickfx bake-field` writes them.
std::string sequenceFramePath(const std::string& pattern, int frame, int padding);

/// Samples a Vec3 grid (vec3s or vec3d) in world space through the grid's own transform.
///
/// Interpolation: trilinear (openvdb::tools::BoxSampler) by default, triquadratic on request;
/// a grid whose class is GRID_STAGGERED (MAC) is sampled with the staggered variants. Samples
/// are computed in the grid's precision and rounded to float once.
///
/// Modes: Force, a += scale·u(x); Drag, a += scale·(u(x) − v) (scale is the rate k, 1/s: pulled
/// toward the field velocity, like Houdini's advect-by-volumes "update velocity"); Advect,
/// v := scale·u(x): the module prescribes velocity (prescribesVelocity()), the integrators then
/// follow x' = u(x, t) with their advection schemes (integrators/Advection.h), and the effect
/// can have no acceleration forces besides.
///
/// Outside the active voxels (the voxel nearest to x is inactive): Background samples as
/// OpenVDB does (the grid's background where nothing is stored); Zero adds nothing; Kill adds
/// nothing during the step and, at the end of each tick (endTick), flags every particle whose new
/// position is outside as dead, so the pool removes it before the next tick.
///
/// Sequences: with `fps > 0`, `file` holds "{frame}", replaced by the frame number zero-padded
/// to `framePadding` digits, for frames firstFrame..lastFrame (all loaded on construction).
/// Frame f is at time (f − firstFrame)/fps seconds; between frames the two samples are
/// interpolated linearly; before the first and after the last frame, clamped. The frames and the
/// weight come from the integer tick clock (framesAt), with fps taken as the exact binary
/// fraction it is: a tick on a frame's time samples that frame alone.
///
/// Loading errors (missing file, missing grid, wrong value type, unreadable data) throw
/// std::runtime_error naming the file and the grid. Thread safety: accumulate() builds its own
/// value accessors per call; the grids are immutable after construction.
class VectorField final : public ForceModule {
 public:
  enum class Mode { Force, Drag, Advect };
  enum class Interpolation { Linear, Quadratic };
  enum class Outside { Background, Zero, Kill };

  struct Settings {
    std::string file;
    std::string grid = "vel";
    Mode mode = Mode::Force;
    float scale = 1.0f;  // Force: unit of the field → m/s²; Drag: k in 1/s; Advect: unit → m/s
    Interpolation interpolation = Interpolation::Linear;
    Outside outside = Outside::Background;
    // Sequences (fps > 0 only; from 1e-6 to 1e6 frames a second).
    double fps = 0.0;
    int firstFrame = 0;
    int lastFrame = 0;
    int framePadding = 4;
  };

  /// Loads the grid (or the frames of a sequence) from settings.file.
  explicit VectorField(const Settings& settings);
  /// Grids already in memory (see VectorFieldGrids.h): one, or one a frame of a sequence
  /// (settings.file is then only a name for messages). Checked as loaded grids are.
  struct Grids;
  VectorField(const Settings& settings, const Grids& grids);
  ~VectorField() override;
  VectorField(const VectorField&) = delete;
  VectorField& operator=(const VectorField&) = delete;

  std::string_view typeName() const override { return "vector_field"; }
  /// Not with `outside = "kill"`, whose endTick() flags particles at each tick's end.
  bool interleavesTicks() const override { return s_.outside != Outside::Kill; }
  void accumulate(const ForceInput& in, RowRange rows, Vec3Rows& acceleration) const override;
  bool prescribesVelocity() const override { return s_.mode == Mode::Advect; }
  void accumulateVelocity(const ForceInput& in, RowRange rows, Vec3Rows& velocity) const override;
  /// In advect mode a sample reads nothing but the position (and the instant).
  bool velocityFromPositionsOnly() const override { return s_.mode == Mode::Advect; }
  /// The leaf nodes of the first frame: the base corner of a trilinear sample, shifted down by the
  /// leaf's log2 size (ordering only: any sampler, any frame).
  bool sampleBlocks(const Vec3View& position, RowRange rows, BlockCoord* out) const override;
  void endTick(ParticlePool& pool, const TickInstant& end) override;

  /// The frames of a sequence around an instant: indices from 0 (frame firstFrame) and the
  /// weight of `second`, the exact fraction t·fps − ⌊t·fps⌋ rounded to float once.
  struct Frames {
    std::size_t first = 0, second = 0;
    float weight = 0.0f;
  };
  /// The frames at `at`, in exact integers (what the simulation samples).
  Frames framesAt(const TickInstant& at) const;

  /// The field value (after the outside policy, before scale) at world position `x`, time `t`
  /// (for inspection: t·fps is computed in double here).
  Eigen::Vector3f sample(const Eigen::Vector3f& x, double t = 0.0) const;
  /// Sets dead[row] = 1 for the rows of `rows` whose position is outside the active voxels (of
  /// the frame at or before in.time); leaves the other flags alone. `dead` is pool-indexed.
  void flagOutside(const ForceInput& in, RowRange rows, std::uint8_t* dead) const;

  /// "vec3s" or "vec3d".
  const std::string& valueType() const;
  bool staggered() const;
  int frameCount() const;
  /// The smallest edge of a voxel of the first frame, in metres.
  double voxelSize() const;
  /// The largest |u| over the active voxels of every frame (before scale), in the field's unit.
  double maxMagnitude() const;
  const Settings& settings() const { return s_; }

  struct Impl;  // OpenVDB lives here (VectorField.cpp)

 private:
  Settings s_;
  // fps = fpsNumerator_ / 2^fpsShift_ exactly (sequences only).
  unsigned __int128 fpsNumerator_ = 0;
  int fpsShift_ = 0;
  std::unique_ptr<const Impl> impl_;
};

}  // namespace tickfx
