#include "particles/Structure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <utility>

#include "particles/DetMath.h"
#include "particles/NeighbourPairs.h"
#include "particles/Random.h"

namespace tickfx {
namespace {

// Structures draw random numbers in their own emitter-index space, apart from the emitters'.
constexpr std::uint32_t kStructureKeySpace = 0x80000000u;

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
  // Rest length from the particles' stored float positions, by the float arithmetic the spring
  // network measures lengths with, so a structure starts unstressed to the bit wherever it is
  // (from the double positions, a cloth far from the origin started under stress).
  void spring(std::size_t a, std::size_t b, double stiffness) {
    const Eigen::Vector3f& pa = out.particles[a].position;
    const Eigen::Vector3f& pb = out.particles[b].position;
    const float dx = pb.x() - pa.x(), dy = pb.y() - pa.y(), dz = pb.z() - pa.z();
    out.springs.push_back(Spring{a, b, std::sqrt(dx * dx + dy * dy + dz * dz),
                                 static_cast<float>(stiffness), static_cast<float>(s.damping),
                                 static_cast<float>(s.breakRatio)});
  }
};

void buildRope(Builder& b, const RopeShape& rope) {
  std::vector<Eigen::Vector3d> at;
  for (int i = 0; i < rope.count; ++i) {
    at.push_back(rope.start +
                 (rope.end - rope.start) * (static_cast<double>(i) / (rope.count - 1)));
    b.particle(at.back(), (i == 0 && rope.pinStart) || (i == rope.count - 1 && rope.pinEnd));
  }
  for (int i = 0; i + 1 < rope.count; ++i) b.spring(i, i + 1, b.s.stiffness);
}

void buildCloth(Builder& b, const ClothShape& c) {
  const Eigen::Vector3d u = c.axisU.normalized(), v = c.axisV.normalized();
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
    b.spring(index(c0, r0), index(c1, r1), stiffness);
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
  // Every pair born within the link radius, in (i, j) order: the order of the springs is part
  // of the sum each particle forms.
  const std::vector<std::pair<int, int>> pairs = neighbourPairs(at, c.linkRadius);
  for (const auto& [i, j] : pairs) b.spring(i, j, b.s.stiffness);
}

// The problems of each shape, keyed as effect files write them.
void validateShape(const RopeShape& rope, SettingProblems& out) {
  if (rope.count < 2 || rope.count > 1'000'000) {
    out.push_back({"count", std::to_string(rope.count) + " is out of range",
                   "particles, an integer from 2 to 1000000"});
  }
  if (!rope.start.allFinite()) out.push_back({"start", "is not finite", "[x, y, z] in metres"});
  if (!rope.end.allFinite()) {
    out.push_back({"end", "is not finite", "[x, y, z] in metres"});
  } else if (rope.start.allFinite() &&
             (rope.end - rope.start).squaredNorm() < std::numeric_limits<double>::min()) {
    // The positions along the rope are start + (end − start)·t: a length whose square is
    // subnormal in double is no length to build on.
    char length[32];
    std::snprintf(length, sizeof length, "%.3g", (rope.end - rope.start).stableNorm());
    out.push_back(
        {"end",
         "is " + std::string(length) +
             " m from start, too close to give the rope a length in double precision",
         "[x, y, z] in metres, at least " + shortestNormalisable<double>() + " m from start"});
  }
}

void validateShape(const ClothShape& c, SettingProblems& out) {
  for (const auto& [key, side] : {std::pair{"width", c.width}, std::pair{"height", c.height}}) {
    if (side < 2) {
      out.push_back(
          {key, std::to_string(side) + " is out of range", "particles, an integer of at least 2"});
    }
  }
  if (c.width >= 2 && c.height >= 2 && static_cast<long long>(c.width) * c.height > 1'000'000) {
    out.push_back({"height",
                   std::to_string(c.width) + " x " + std::to_string(c.height) + " = " +
                       std::to_string(static_cast<long long>(c.width) * c.height) +
                       " particles are too many",
                   "width x height at most 1000000"});
  }
  if (!(c.spacing > 0.0 && std::isfinite(c.spacing))) {
    out.push_back(
        {"spacing", settingNumber(c.spacing) + " is out of range", "metres, a finite number > 0"});
  }
  if (!c.origin.allFinite()) out.push_back({"origin", "is not finite", "[x, y, z] in metres"});
  checkDirection(c.axisU, "axis_u", out);
  checkDirection(c.axisV, "axis_v", out);
  if (clothAxesParallel(c)) {
    out.push_back(
        {"axis_v", "is parallel to axis_u", "a direction [x, y, z] not parallel to axis_u"});
  }
}

void validateShape(const ClusterShape& c, SettingProblems& out) {
  if (c.count < 1 || c.count > 1'000'000) {
    out.push_back({"count", std::to_string(c.count) + " is out of range",
                   "particles, an integer from 1 to 1000000"});
  }
  if (!(c.radius > 0.0 && std::isfinite(c.radius))) {
    out.push_back(
        {"radius", settingNumber(c.radius) + " is out of range", "metres, a finite number > 0"});
  }
  if (!(c.linkRadius > 0.0 && std::isfinite(c.linkRadius))) {
    out.push_back({"link_radius", settingNumber(c.linkRadius) + " is out of range",
                   "metres, a finite number > 0"});
  }
  if (!c.center.allFinite()) out.push_back({"center", "is not finite", "[x, y, z] in metres"});
}

}  // namespace

bool clothAxesParallel(const ClothShape& cloth) {
  return normalisable(cloth.axisU) && normalisable(cloth.axisV) &&
         cloth.axisU.normalized().cross(cloth.axisV.normalized()).norm() <= 1e-6;
}

SettingProblems StructureSettings::validate() const {
  SettingProblems out;
  const auto check = [&](bool ok, const char* key, double value, const char* expected) {
    if (!ok) out.push_back({key, settingNumber(value) + " is out of range", expected});
  };
  check(std::isfinite(time) && time >= 0.0, "time", time, "seconds, a finite number >= 0");
  check(mass > 0.0 && std::isfinite(mass), "mass", mass,
        "kilograms per particle, a finite number > 0");
  check(stiffness >= 0.0 && std::isfinite(stiffness), "stiffness", stiffness,
        "N/m, a finite number >= 0");
  check(damping >= 0.0 && std::isfinite(damping), "damping", damping,
        "N·s/m, a finite number >= 0");
  check(breakRatio == 0.0 || breakRatio > 1.0, "break_ratio", breakRatio,
        "0 (never breaks) or a ratio of the rest length > 1");
  check(lifetime > 0.0, "lifetime", lifetime, "seconds, a number > 0");
  if (!velocity.allFinite()) out.push_back({"velocity", "is not finite", "[x, y, z] in m/s"});
  std::visit([&](const auto& s) { validateShape(s, out); }, shape);
  return out;
}

namespace {

const char* shapeName(const StructureShape& shape) {
  if (std::holds_alternative<RopeShape>(shape)) return "rope";
  return std::holds_alternative<ClothShape>(shape) ? "cloth" : "cluster";
}

}  // namespace

StructureBuild buildStructure(const StructureSettings& settings, std::uint64_t seed,
                              std::uint32_t index) {
  throwIfAny(shapeName(settings.shape), settings.validate());
  Builder b{settings, {}};
  if (const auto* rope = std::get_if<RopeShape>(&settings.shape)) buildRope(b, *rope);
  if (const auto* cloth = std::get_if<ClothShape>(&settings.shape)) buildCloth(b, *cloth);
  if (const auto* cluster = std::get_if<ClusterShape>(&settings.shape))
    buildCluster(b, *cluster, seed, index);
  return std::move(b.out);
}

}  // namespace tickfx
