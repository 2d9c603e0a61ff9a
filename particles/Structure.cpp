#include "particles/Structure.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <tuple>

#include "particles/DetMath.h"
#include "particles/Random.h"

namespace tickfx {
namespace {

// Structures draw random numbers in their own emitter-index space, apart from the emitters'.
constexpr std::uint32_t kStructureKeySpace = 0x80000000u;

void require(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(what);
}

struct Builder {
  const StructureSettings& s;
  StructureBuild out;

  void particle(const Eigen::Vector3d& position, bool pinned) {
    ParticleInit init;
    init.position = position.cast<float>();
    init.velocity = pinned ? Eigen::Vector3f::Zero() : Eigen::Vector3f(s.velocity.cast<float>());
    init.mass = pinned ? std::numeric_limits<float>::infinity() : static_cast<float>(s.mass);
    init.lifetime = static_cast<float>(s.lifetime);
    out.particles.push_back(init);
  }
  // Rest length from the positions as built (in double), so a structure starts unstressed.
  void spring(std::size_t a, std::size_t b, double stiffness, const Eigen::Vector3d& pa,
              const Eigen::Vector3d& pb) {
    out.springs.push_back(Spring{a, b, static_cast<float>((pb - pa).norm()),
                                 static_cast<float>(stiffness), static_cast<float>(s.damping),
                                 static_cast<float>(s.breakRatio)});
  }
};

void buildRope(Builder& b, const RopeShape& rope) {
  require(rope.count >= 2 && rope.count <= 1'000'000, "rope count must be in [2, 1000000]");
  require(rope.start.allFinite() && rope.end.allFinite() && (rope.end - rope.start).norm() > 0.0,
          "rope start and end must be distinct finite points");
  std::vector<Eigen::Vector3d> at;
  for (int i = 0; i < rope.count; ++i) {
    at.push_back(rope.start +
                 (rope.end - rope.start) * (static_cast<double>(i) / (rope.count - 1)));
    b.particle(at.back(), (i == 0 && rope.pinStart) || (i == rope.count - 1 && rope.pinEnd));
  }
  for (int i = 0; i + 1 < rope.count; ++i) b.spring(i, i + 1, b.s.stiffness, at[i], at[i + 1]);
}

void buildCloth(Builder& b, const ClothShape& c) {
  require(c.width >= 2 && c.height >= 2 && static_cast<long long>(c.width) * c.height <= 1'000'000,
          "cloth width and height must be >= 2 with at most 1000000 particles");
  require(c.spacing > 0.0 && std::isfinite(c.spacing), "cloth spacing must be > 0");
  require(
      c.axisU.allFinite() && c.axisV.allFinite() && c.axisU.norm() > 0.0 && c.axisV.norm() > 0.0,
      "cloth axes must not be zero");
  const Eigen::Vector3d u = c.axisU.normalized(), v = c.axisV.normalized();
  require(u.cross(v).norm() > 1e-6, "cloth axes must not be parallel");
  const int w = c.width, h = c.height;
  auto index = [w](int col, int row) { return static_cast<std::size_t>(row) * w + col; };
  std::vector<Eigen::Vector3d> at;
  for (int row = 0; row < h; ++row) {
    for (int col = 0; col < w; ++col) {
      at.push_back(c.origin + u * (col * c.spacing) + v * (row * c.spacing));
      const bool corner = (col == 0 || col == w - 1) && (row == 0 || row == h - 1);
      const bool pinned =
          (c.pins == ClothPins::TopEdge && row == 0) ||
          (c.pins == ClothPins::TopCorners && row == 0 && (col == 0 || col == w - 1)) ||
          (c.pins == ClothPins::AllCorners && corner);
      b.particle(at.back(), pinned);
    }
  }
  const double k = b.s.stiffness, shear = k * c.shearStiffnessScale,
               bend = k * c.bendStiffnessScale;
  auto join = [&](int c0, int r0, int c1, int r1, double stiffness) {
    // Both ends: index(w, row) is a valid index (the next row's first particle), so a spring
    // off the grid's edge would silently wrap instead of failing.
    const bool inside =
        c0 >= 0 && c0 < w && r0 >= 0 && r0 < h && c1 >= 0 && c1 < w && r1 >= 0 && r1 < h;
    if (!inside || stiffness <= 0.0) return;
    b.spring(index(c0, r0), index(c1, r1), stiffness, at[index(c0, r0)], at[index(c1, r1)]);
  };
  // Structural, then shear, then bend, each row by row: the order of the springs is part of the
  // sum each particle forms, so it is fixed here.
  for (int row = 0; row < h; ++row) {
    for (int col = 0; col < w; ++col) {
      join(col, row, col + 1, row, k);
      join(col, row, col, row + 1, k);
    }
  }
  for (int row = 0; row < h; ++row) {
    for (int col = 0; col < w; ++col) {
      join(col, row, col + 1, row + 1, shear);
      join(col + 1, row, col, row + 1, shear);
    }
  }
  for (int row = 0; row < h; ++row) {
    for (int col = 0; col < w; ++col) {
      join(col, row, col + 2, row, bend);
      join(col, row, col, row + 2, bend);
    }
  }
}

void buildCluster(Builder& b, const ClusterShape& c, std::uint64_t seed, std::uint32_t index) {
  require(c.count >= 1 && c.count <= 1'000'000, "cluster count must be in [1, 1000000]");
  require(c.radius > 0.0 && std::isfinite(c.radius), "cluster radius must be > 0");
  require(c.linkRadius > 0.0 && std::isfinite(c.linkRadius), "cluster link radius must be > 0");
  require(c.center.allFinite(), "cluster center must be finite");
  std::vector<Eigen::Vector3d> at;
  for (int i = 0; i < c.count; ++i) {
    auto uniform = [&](RandomPurpose purpose) {
      return randomUniform(RandomKey{seed, kStructureKeySpace | index,
                                     static_cast<std::uint64_t>(i),
                                     static_cast<std::uint32_t>(purpose)});
    };
    const double z = 1.0 - 2.0 * uniform(RandomPurpose::PositionU);
    const double rxy = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = 2.0 * det::kPi * uniform(RandomPurpose::PositionV);
    const double r = c.radius * det::cbrt(uniform(RandomPurpose::PositionW));
    at.push_back(c.center + r * Eigen::Vector3d(rxy * det::cos(phi), rxy * det::sin(phi), z));
    b.particle(at.back(), false);
  }
  // Neighbours through a grid of cells one link radius wide; pairs are sorted so the springs'
  // order does not depend on the map's.
  using Cell = std::tuple<long long, long long, long long>;
  std::map<Cell, std::vector<int>> cells;
  auto cellOf = [&](const Eigen::Vector3d& q) {
    const Eigen::Vector3d t = (q - c.center) / c.linkRadius;
    return Cell{static_cast<long long>(std::floor(t.x())),
                static_cast<long long>(std::floor(t.y())),
                static_cast<long long>(std::floor(t.z()))};
  };
  for (int i = 0; i < c.count; ++i) cells[cellOf(at[i])].push_back(i);
  std::vector<std::pair<int, int>> pairs;
  for (int i = 0; i < c.count; ++i) {
    const auto [cx, cy, cz] = cellOf(at[i]);
    for (long long dx = -1; dx <= 1; ++dx) {
      for (long long dy = -1; dy <= 1; ++dy) {
        for (long long dz = -1; dz <= 1; ++dz) {
          const auto it = cells.find(Cell{cx + dx, cy + dy, cz + dz});
          if (it == cells.end()) continue;
          for (int j : it->second) {
            if (j > i && (at[j] - at[i]).norm() <= c.linkRadius) pairs.emplace_back(i, j);
          }
        }
      }
    }
  }
  std::sort(pairs.begin(), pairs.end());
  for (const auto& [i, j] : pairs) b.spring(i, j, b.s.stiffness, at[i], at[j]);
}

}  // namespace

StructureBuild buildStructure(const StructureSettings& settings, std::uint64_t seed,
                              std::uint32_t index) {
  require(settings.mass > 0.0 && std::isfinite(settings.mass), "structure mass must be > 0");
  require(settings.stiffness >= 0.0 && std::isfinite(settings.stiffness),
          "structure stiffness must be >= 0");
  require(settings.damping >= 0.0 && std::isfinite(settings.damping),
          "structure damping must be >= 0");
  require(settings.breakRatio == 0.0 || settings.breakRatio > 1.0,
          "break ratio must be 0 (never) or > 1");
  require(settings.lifetime > 0.0, "structure lifetime must be > 0");
  require(settings.velocity.allFinite(), "structure velocity must be finite");
  Builder b{settings, {}};
  if (const auto* rope = std::get_if<RopeShape>(&settings.shape)) buildRope(b, *rope);
  if (const auto* cloth = std::get_if<ClothShape>(&settings.shape)) buildCloth(b, *cloth);
  if (const auto* cluster = std::get_if<ClusterShape>(&settings.shape))
    buildCluster(b, *cluster, seed, index);
  return std::move(b.out);
}

}  // namespace tickfx
