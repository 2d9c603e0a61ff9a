// Vector fields given by a formula (uniform, vortex, shear, curl noise), their force module, and
// baking one into an OpenVDB grid on disk (what `tickfx bake-field` will call).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "fields/ForceModule.h"
#include "fields/vdb/VectorField.h"
#include "particles/SettingProblem.h"

namespace tickfx {

/// A steady vector field u(x), evaluated in double. Two families:
///  - affine: u(x) = u0 + M·(x − c) (uniform, vortex, shear are special cases);
///  - curl noise: u = ∇×ψ with ψ a seeded sum of sinusoids, so div u = 0 exactly; the parameters
///    are a pure function of the seed.
/// Copyable value type; evaluation is const and thread-safe.
class AnalyticField {
 public:
  /// u(x) = u.
  static AnalyticField uniform(const Eigen::Vector3d& u);
  /// Rigid rotation at `omega` rad/s about the line through `centre` along `axis` (normalised):
  /// u(x) = ω · â × (x − c). Throws std::invalid_argument for an axis validateVortex() refuses.
  static AnalyticField vortex(const Eigen::Vector3d& centre, const Eigen::Vector3d& axis,
                              double omega);
  /// Simple shear: u(x) = rate · (n̂·(x − origin)) · d̂, with d̂ the flow direction and n̂ the
  /// direction the speed grows along (both normalised; throws for vectors validateShear() refuses).
  static AnalyticField shear(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                             const Eigen::Vector3d& gradient, double rate);
  /// Divergence-free noise: ψ_i(x) = Σ_k a_ik · sin(k_ik·x + φ_ik) over `octaves` terms per
  /// component, wave numbers of length `frequency` (rad/m), amplitudes scaled so that |u| is of
  /// the order of `amplitude`. Deterministic: the same seed gives the same field on every build.
  /// With `evolution` ω > 0 (rad/s) the noise changes in time: each term's phase drifts at a
  /// seeded rate in [−ω, ω], so the field at time t is still divergence-free and its pattern
  /// renews over about 1/ω seconds.
  static AnalyticField curlNoise(std::uint64_t seed, double frequency, double amplitude,
                                 int octaves = 4, double evolution = 0.0);

  /// What vortex(), shear() and curlNoise() refuse (empty: they accept the parameters), keyed as
  /// bake tables write them: an `axis`, `direction` or `gradient` too short to normalise in
  /// double (normalisable()), a `frequency` that is not > 0, fewer than one of `octaves`. The
  /// factories throw std::invalid_argument with the first.
  static SettingProblems validateVortex(const Eigen::Vector3d& axis);
  static SettingProblems validateShear(const Eigen::Vector3d& direction,
                                       const Eigen::Vector3d& gradient);
  static SettingProblems validateCurlNoise(double frequency, int octaves);

  /// The field at `x` (metres → the field's unit) and time `time` (seconds; only evolving curl
  /// noise depends on it).
  Eigen::Vector3d at(const Eigen::Vector3d& x, double time = 0.0) const;

  /// True for the affine family (uniform, vortex, shear).
  bool isAffine() const { return terms_.empty(); }
  /// For an affine field, its material acceleration (u·∇)u = M·u0 + M²·(x − c), again affine.
  /// A particle with v(0) = u(x(0)) under this acceleration follows the streamline of u
  /// exactly: this is how advection by a steady affine field is expressed as a force. Throws
  /// std::logic_error for curl noise.
  AnalyticField materialAcceleration() const;
  /// An upper bound of Σ_d |∂²u_i/∂x_d²| over all x and components i: the trilinear
  /// interpolation error on a grid of spacing h is at most h²/8 times this. 0 for affine fields.
  double curvatureBound() const;

 private:
  struct Term {  // a · sin(k·x + φ) in component `component` of ψ
    int component = 0;
    double a = 0.0;
    Eigen::Vector3d k = Eigen::Vector3d::Zero();
    double phase = 0.0;
    double omega = 0.0;  // phase drift, rad/s
  };
  Eigen::Vector3d u0_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d m_ = Eigen::Matrix3d::Zero();
  Eigen::Vector3d c_ = Eigen::Vector3d::Zero();
  std::vector<Term> terms_;
};

/// A force module from an analytic field: a += scale·u(x, t) ("force"), a += k·(u(x, t) − v)
/// ("drag"), or v := scale·u(x, t) ("advect", see VectorField). u is evaluated in double and
/// rounded to float once per particle.
class AnalyticForce final : public ForceModule {
 public:
  enum class Mode { Force, Drag, Advect };
  AnalyticForce(AnalyticField field, Mode mode, float gain);
  std::string_view typeName() const override { return "analytic_field"; }
  bool interleavesTicks() const override { return true; }
  void accumulate(const ForceInput& in, RowRange rows, Vec3Rows& acceleration) const override;
  bool prescribesVelocity() const override { return mode_ == Mode::Advect; }
  void accumulateVelocity(const ForceInput& in, RowRange rows, Vec3Rows& velocity) const override;

 private:
  void add(const ForceInput& in, RowRange rows, Vec3Rows& out) const;

  AnalyticField field_;
  Mode mode_;
  float gain_;
};

/// Where and how to bake a field.
struct BakeSettings {
  std::string gridName = "vel";
  double voxelSize = 0.1;  // metres
  /// World-space box; every voxel whose centre i·h lies in [min, max] is written (active).
  Eigen::Vector3d min = Eigen::Vector3d::Constant(-1.0);
  Eigen::Vector3d max = Eigen::Vector3d::Constant(1.0);
  /// Value outside the baked voxels.
  Eigen::Vector3f background = Eigen::Vector3f::Zero();
  /// Writes a staggered (MAC) grid: component c of voxel ijk is u_c at the centre of its face
  /// on the −c side, (ijk − ½·e_c)·h; the grid class says so and VectorField samples it so.
  bool staggered = false;
};

/// The voxels bakeField() writes for the box [min, max] (metres) at `voxelSize` (metres): per
/// axis, the voxel centres i·voxelSize inside the box. A double, since bad input can make it
/// astronomically large; 0 when the box holds no centre on some axis.
double bakedVoxelCount(double voxelSize, const Eigen::Vector3d& min, const Eigen::Vector3d& max);

/// Bakes `field` at time `time` into an openvdb::Vec3fGrid (values rounded to float once) and
/// writes it to `path` under `settings.gridName`, replacing the file (written beside it and
/// renamed, so a failure leaves no partial file). Throws std::invalid_argument for a
/// non-positive voxel size, an empty box, or an empty grid name, and std::runtime_error (naming
/// the file) when the file cannot be written.
void bakeField(const AnalyticField& field, const BakeSettings& settings, const std::string& path,
               double time = 0.0);

/// Bakes `field` in memory and returns a VectorField sampling it with `settings` (file names
/// are then only labels): one grid, or with settings.fps > 0 one grid a frame, frame f baked at
/// (f − firstFrame)/fps seconds. The same bits as baking to files and loading them.
std::unique_ptr<VectorField> bakeVectorField(const AnalyticField& field, const BakeSettings& bake,
                                             const VectorField::Settings& settings);

}  // namespace tickfx
