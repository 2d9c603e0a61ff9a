#include "fields/vdb/AnalyticField.h"

#include <openvdb/openvdb.h>
#include <unistd.h>
#include <Eigen/Geometry>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>

#include "fields/vdb/RegisteredGrid.h"
#include "fields/vdb/VectorFieldGrids.h"
#include "particles/DetMath.h"
#include "particles/Random.h"

namespace tickfx {

namespace {

// v normalised, once validate*() has made sure it can be.
Eigen::Vector3d unit(const Eigen::Vector3d& v) { return v / v.norm(); }

Eigen::Matrix3d cross(const Eigen::Vector3d& a) {  // [a]×, so that [a]×·x = a × x
  Eigen::Matrix3d m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}

/// A double in [0, 1) from 53 bits.
double uniform01(std::uint64_t seed, std::uint64_t counter) {
  // The noise parameters are a pure function of (seed, counter).
  return static_cast<double>(splitmix64(seed ^ splitmix64(counter)) >> 11) * 0x1p-53;
}

}  // namespace

AnalyticField AnalyticField::uniform(const Eigen::Vector3d& u) {
  AnalyticField f;
  f.u0_ = u;
  return f;
}

SettingProblems AnalyticField::validateVortex(const Eigen::Vector3d& axis) {
  SettingProblems out;
  checkDirection(axis, "axis", out);
  return out;
}

SettingProblems AnalyticField::validateShear(const Eigen::Vector3d& direction,
                                             const Eigen::Vector3d& gradient) {
  SettingProblems out;
  checkDirection(direction, "direction", out);
  checkDirection(gradient, "gradient", out);
  return out;
}

SettingProblems AnalyticField::validateCurlNoise(double frequency, int octaves) {
  SettingProblems out;
  if (!(frequency > 0.0 && std::isfinite(frequency))) {
    out.push_back({"frequency", settingNumber(frequency) + " is out of range",
                   "radians per metre, a finite number > 0"});
  }
  if (octaves < 1) {
    out.push_back(
        {"octaves", std::to_string(octaves) + " is out of range", "an integer of at least 1"});
  }
  return out;
}

AnalyticField AnalyticField::vortex(const Eigen::Vector3d& centre, const Eigen::Vector3d& axis,
                                    double omega) {
  throwIfAny("vortex", validateVortex(axis));
  AnalyticField f;
  f.c_ = centre;
  f.m_ = omega * cross(unit(axis));
  return f;
}

AnalyticField AnalyticField::shear(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                   const Eigen::Vector3d& gradient, double rate) {
  throwIfAny("shear", validateShear(direction, gradient));
  AnalyticField f;
  f.c_ = origin;
  f.m_ = rate * unit(direction) * unit(gradient).transpose();
  return f;
}

AnalyticField AnalyticField::curlNoise(std::uint64_t seed, double frequency, double amplitude,
                                       int octaves, double evolution) {
  throwIfAny("curl noise", validateCurlNoise(frequency, octaves));
  AnalyticField f;
  std::uint64_t counter = 0;
  const double scale = amplitude / (frequency * std::sqrt(3.0 * octaves));
  for (int component = 0; component < 3; ++component) {
    for (int o = 0; o < octaves; ++o) {
      Term t;
      t.component = component;
      const double z = 2.0 * uniform01(seed, counter++) - 1.0;
      const double azimuth = 2.0 * det::kPi * uniform01(seed, counter++);
      const double s = std::sqrt(1.0 - z * z);
      t.k = frequency * Eigen::Vector3d(s * det::cos(azimuth), s * det::sin(azimuth), z);
      t.phase = 2.0 * det::kPi * uniform01(seed, counter++);
      t.a = scale * (0.5 + 0.5 * uniform01(seed, counter++));
      // Drift rates come from a counter space of their own, so that a steady field (evolution
      // 0) keeps the terms it had before fields could evolve.
      t.omega = evolution * (2.0 * uniform01(~seed, f.terms_.size()) - 1.0);
      f.terms_.push_back(t);
    }
  }
  return f;
}

Eigen::Vector3d AnalyticField::at(const Eigen::Vector3d& x, double time) const {
  if (terms_.empty()) return u0_ + m_ * (x - c_);
  // ∇×(ψ_i e_i) = ∇ψ_i × e_i, and ∇ψ_i = a·cos(k·x + φ + ωt)·k.
  Eigen::Vector3d u = Eigen::Vector3d::Zero();
  for (const Term& t : terms_) {
    const double g = t.a * det::cos(t.k.dot(x) + (t.phase + t.omega * time));
    u += g * t.k.cross(Eigen::Vector3d::Unit(t.component));
  }
  return u;
}

AnalyticField AnalyticField::materialAcceleration() const {
  if (!isAffine()) throw std::logic_error("materialAcceleration: only for affine fields");
  AnalyticField f;
  f.u0_ = m_ * u0_;
  f.m_ = m_ * m_;
  f.c_ = c_;
  return f;
}

double AnalyticField::curvatureBound() const {
  double bound = 0.0;
  for (const Term& t : terms_) {
    const double k = t.k.norm();
    bound += std::abs(t.a) * k * k * k;
  }
  return bound;
}

AnalyticForce::AnalyticForce(AnalyticField field, Mode mode, float gain)
    : field_(std::move(field)), mode_(mode), gain_(gain) {}

void AnalyticForce::accumulateVelocity(const ForceInput& in, RowRange rows,
                                       Vec3Rows& velocity) const {
  if (mode_ == Mode::Advect) add(in, rows, velocity);
}

void AnalyticForce::accumulate(const ForceInput& in, RowRange rows, Vec3Rows& a) const {
  if (mode_ != Mode::Advect) add(in, rows, a);
}

void AnalyticForce::add(const ForceInput& in, RowRange rows, Vec3Rows& a) const {
  const ConstVec3Rows p = in.position.rows(rows);
  const ConstVec3Rows v = in.velocity.rows(rows);
  for (Eigen::Index j = 0; j < rows.count(); ++j) {
    // float → double widening is exact; the field value is rounded to float once.
    const Eigen::Vector3d x(p.x[j], p.y[j], p.z[j]);
    const Eigen::Vector3f u = field_.at(x, in.time()).cast<float>();
    if (mode_ != Mode::Drag) {
      a.x[j] += gain_ * u.x();
      a.y[j] += gain_ * u.y();
      a.z[j] += gain_ * u.z();
    } else {
      a.x[j] += gain_ * (u.x() - v.x[j]);
      a.y[j] += gain_ * (u.y() - v.y[j]);
      a.z[j] += gain_ * (u.z() - v.z[j]);
    }
  }
}

namespace {

// The indices of the voxel centres i·h in [lo, hi] along one axis: first to last, none when
// first > last.
std::pair<double, double> centreIndices(double h, double lo, double hi) {
  return {std::ceil(lo / h), std::floor(hi / h)};
}

}  // namespace

double bakedVoxelCount(double voxelSize, const Eigen::Vector3d& min, const Eigen::Vector3d& max) {
  double count = 1.0;
  for (int c = 0; c < 3; ++c) {
    const auto [first, last] = centreIndices(voxelSize, min[c], max[c]);
    count *= std::max(0.0, last - first + 1.0);
  }
  return count;
}

openvdb::Vec3fGrid::Ptr bakeGrid(const AnalyticField& field, const BakeSettings& s, double time) {
  if (!(s.voxelSize > 0.0)) throw std::invalid_argument("bake: voxel size must be positive");
  if (s.gridName.empty()) throw std::invalid_argument("bake: the grid needs a name");
  const double h = s.voxelSize;
  openvdb::Coord lo, hi;
  for (int c = 0; c < 3; ++c) {
    const auto [first, last] = centreIndices(h, s.min[c], s.max[c]);
    lo[c] = static_cast<openvdb::Int32>(first);
    hi[c] = static_cast<openvdb::Int32>(last);
    if (lo[c] > hi[c]) throw std::invalid_argument("bake: the box holds no voxel centre");
  }
  const openvdb::Vec3f background(s.background.x(), s.background.y(), s.background.z());
  openvdb::Vec3fGrid::Ptr grid = newRegisteredGrid<openvdb::Vec3fGrid>(background);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(h));
  grid->setName(s.gridName);
  grid->setGridClass(s.staggered ? openvdb::GRID_STAGGERED : openvdb::GRID_UNKNOWN);
  auto acc = grid->getAccessor();
  const openvdb::math::Transform& xform = grid->transform();
  for (openvdb::Int32 i = lo.x(); i <= hi.x(); ++i) {
    for (openvdb::Int32 j = lo.y(); j <= hi.y(); ++j) {
      for (openvdb::Int32 k = lo.z(); k <= hi.z(); ++k) {
        const openvdb::Coord ijk(i, j, k);
        openvdb::Vec3f value;
        if (s.staggered) {
          for (int c = 0; c < 3; ++c) {
            openvdb::Vec3d face = ijk.asVec3d();
            face[c] -= 0.5;
            const openvdb::Vec3d w = xform.indexToWorld(face);
            value[c] = static_cast<float>(field.at(Eigen::Vector3d(w.x(), w.y(), w.z()), time)[c]);
          }
        } else {
          const openvdb::Vec3d w = xform.indexToWorld(ijk);
          const Eigen::Vector3f u =
              field.at(Eigen::Vector3d(w.x(), w.y(), w.z()), time).cast<float>();
          value = openvdb::Vec3f(u.x(), u.y(), u.z());
        }
        acc.setValueOn(ijk, value);
      }
    }
  }
  return grid;
}

void bakeField(const AnalyticField& field, const BakeSettings& s, const std::string& path,
               double time) {
  const openvdb::Vec3fGrid::Ptr grid = bakeGrid(field, s, time);
  // Written beside the target and renamed over it: a failed bake leaves no half-written file.
  // The temporary's name is the process's and the call's own, so bakes of one file at once (two
  // processes, or two threads) never write into each other's.
  static std::atomic<std::uint64_t> calls{0};
  const std::string partial =
      path + ".partial" + std::to_string(::getpid()) + "-" + std::to_string(calls.fetch_add(1));
  try {
    openvdb::io::File file(partial);
    file.write(openvdb::GridCPtrVec{grid});
    file.close();
    std::filesystem::rename(partial, path);
  } catch (const std::exception& e) {
    std::error_code ec;
    std::filesystem::remove(partial, ec);
    throw std::runtime_error(path + ": cannot write grid '" + s.gridName + "': " + e.what());
  }
}

std::unique_ptr<VectorField> bakeVectorField(const AnalyticField& field, const BakeSettings& bake,
                                             const VectorField::Settings& settings) {
  VectorField::Grids grids;
  const int last = settings.fps > 0.0 ? settings.lastFrame : settings.firstFrame;
  for (int f = settings.firstFrame; f <= last; ++f) {
    const double time = settings.fps > 0.0 ? (f - settings.firstFrame) / settings.fps : 0.0;
    grids.grids.push_back(bakeGrid(field, bake, time));
  }
  return std::make_unique<VectorField>(settings, grids);
}

}  // namespace tickfx
