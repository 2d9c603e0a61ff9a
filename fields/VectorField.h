// A force module that samples a vector grid from an OpenVDB file (one grid, or a sequence of
// frames). OpenVDB stays inside VectorField.cpp: this header includes none of it.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>

#include "fields/ForceModule.h"

namespace tickfx {

/// Samples a Vec3 grid (vec3s or vec3d) in world space through the grid's own transform.
///
/// Interpolation: trilinear (openvdb::tools::BoxSampler) by default, triquadratic on request;
/// a grid whose class is GRID_STAGGERED (MAC) is sampled with the staggered variants. Samples
/// are computed in the grid's precision and rounded to float once.
///
/// Modes: Force, a += scale·u(x); Drag, a += scale·(u(x) − v) (scale is the rate k, 1/s).
/// "Advect" (v := u) is not a mode: an acceleration-based module cannot set a velocity, and
/// the drag limit k = 1/dt only gives v = u for semi-implicit Euler. For a steady field the
/// equivalent force is the material acceleration (u·∇)u with v(0) = u(x(0)) (see
/// AnalyticField::materialAcceleration and bakeField); a true advect needs an integrator hook.
///
/// Outside the active voxels (the voxel nearest to x is inactive): Background samples as
/// OpenVDB does (the grid's background where nothing is stored); Zero adds nothing. Killing
/// particles there needs a writable flag channel, which ForceInput (a const pool) does not
/// give: flagOutside() computes the flags for a caller that owns the pool.
///
/// Sequences: with `fps > 0`, `file` holds "{frame}", replaced by the frame number zero-padded
/// to `framePadding` digits, for frames firstFrame..lastFrame (all loaded on construction).
/// Frame f is at time (f − firstFrame)/fps seconds; between frames the two samples are
/// interpolated linearly at in.time; before the first and after the last frame, clamped.
///
/// Loading errors (missing file, missing grid, wrong value type, unreadable data) throw
/// std::runtime_error naming the file and the grid. Thread safety: accumulate() builds its own
/// value accessors per call; the grids are immutable after construction.
class VectorField final : public ForceModule {
 public:
  enum class Mode { Force, Drag };
  enum class Interpolation { Linear, Quadratic };
  enum class Outside { Background, Zero };

  struct Settings {
    std::string file;
    std::string grid = "vel";
    Mode mode = Mode::Force;
    float scale = 1.0f;  // Force: unit of the field → m/s²; Drag: k in 1/s
    Interpolation interpolation = Interpolation::Linear;
    Outside outside = Outside::Background;
    // Sequences (fps > 0 only).
    double fps = 0.0;
    int firstFrame = 0;
    int lastFrame = 0;
    int framePadding = 4;
  };

  explicit VectorField(const Settings& settings);
  ~VectorField() override;
  VectorField(const VectorField&) = delete;
  VectorField& operator=(const VectorField&) = delete;

  std::string_view typeName() const override { return "vdb_field"; }
  void accumulate(const ForceInput& in, RowRange rows, Vec3Rows& acceleration) const override;

  /// The field value (after the outside policy, before scale) at world position `x`, time `t`.
  Eigen::Vector3f sample(const Eigen::Vector3f& x, double t = 0.0) const;
  /// Sets dead[row] = 1 for the rows of `rows` whose position is outside the active voxels (of
  /// the frame at or before in.time); leaves the other flags alone. `dead` is pool-indexed.
  void flagOutside(const ForceInput& in, RowRange rows, std::uint8_t* dead) const;

  /// "vec3s" or "vec3d".
  const std::string& valueType() const;
  bool staggered() const;
  int frameCount() const;
  const Settings& settings() const { return s_; }

  struct Impl;  // OpenVDB lives here (VectorField.cpp)

 private:
  Settings s_;
  std::unique_ptr<const Impl> impl_;
};

}  // namespace tickfx
