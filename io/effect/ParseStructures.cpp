#include "io/effect/ParseStructures.h"

#include <cmath>
#include <cstdio>

#include "io/effect/EmitterKeys.h"
#include "particles/Structure.h"

namespace tickfx::io::detail {
namespace {

// The bound on springs one structure may make (a cloth of 10⁶ particles has about 6·10⁶).
constexpr double kMaxSprings = 1e7;

// A particle count of a structure: from `min` to the smaller of 10⁶ and max_particles.
struct CountLimit {
  std::int64_t max;
  std::string text;
};

CountLimit structureCountLimit(std::int64_t min, std::int64_t maxParticles,
                               const std::string& what) {
  constexpr std::int64_t kMaxStructure = 1'000'000;
  if (maxParticles < kMaxStructure) {
    return {maxParticles, what + ", an integer from " + std::to_string(min) +
                              " to simulation.max_particles = " + std::to_string(maxParticles)};
  }
  return {kMaxStructure, what + ", an integer from " + std::to_string(min) + " to " +
                             std::to_string(kMaxStructure)};
}

void readRope(Context& cx, TableReader& r, std::int64_t maxParticles, RopeShape& rope) {
  const Range any{-kBig, kBig};
  const bool startOk = r.vec3("start", rope.start, kPositionText, any);
  const bool endOk = r.vec3("end", rope.end, kPositionText, any);
  if (r.table().get("end") == nullptr) r.missing("end", kPositionText);
  if (endOk && (startOk || r.table().get("start") == nullptr) && rope.end == rope.start) {
    cx.error(cx.at(*r.table().get("end")), r.pathOf("end"),
             "is the same point as start (expected [x, y, z] in metres, each from -1e9 to 1e9, "
             "apart from start: a rope has a length)");
  }
  const CountLimit count = structureCountLimit(2, maxParticles, "particles");
  r.integer("count", rope.count, count.text, 2, count.max, /*required=*/true);
  r.boolean("pin_start", rope.pinStart);
  r.boolean("pin_end", rope.pinEnd);
}

void readCloth(Context& cx, TableReader& r, std::int64_t maxParticles, ClothShape& cloth) {
  const Range any{-kBig, kBig};
  r.vec3("origin", cloth.origin, kPositionText, any);
  const bool uOk = r.vec3("axis_u", cloth.axisU, kDirectionText, any, /*nonZero=*/true);
  const bool vOk = r.vec3("axis_v", cloth.axisV, kDirectionText, any, /*nonZero=*/true);
  const toml::node* uNode = r.table().get("axis_u");
  const toml::node* vNode = r.table().get("axis_v");
  if ((uOk || uNode == nullptr) && (vOk || vNode == nullptr) && clothAxesParallel(cloth)) {
    // Shown at the later-written axis (the one a default cannot be blamed for).
    const bool atV = vNode != nullptr;
    const std::string other = atV ? "axis_u" : "axis_v";
    cx.error(cx.at(atV ? *vNode : *uNode), r.pathOf(atV ? "axis_v" : "axis_u"),
             "is parallel to " + other + " (expected a direction [x, y, z], each from -1e9 to " +
                 "1e9, not parallel to " + other + ")");
  }
  const std::string sideText = "particles, an integer from 2 to 500000";
  const bool widthOk = r.integer("width", cloth.width, sideText, 2, 500'000, /*required=*/true);
  const bool heightOk = r.integer("height", cloth.height, sideText, 2, 500'000, /*required=*/true);
  const std::int64_t most = structureCountLimit(1, maxParticles, "particles").max;
  const std::int64_t total = static_cast<std::int64_t>(cloth.width) * cloth.height;
  if (widthOk && heightOk && total > most) {
    cx.error(
        cx.at(*r.table().get("height")), r.pathOf("height"),
        std::to_string(cloth.width) + " x " + std::to_string(cloth.height) + " = " +
            std::to_string(total) + " particles are too many (expected width x height at most " +
            (most < 1'000'000 ? "simulation.max_particles = " : "") + std::to_string(most) + ")");
  }
  r.number("spacing", cloth.spacing, "metres, a number > 0 and <= 1e9", Range{0.0, kBig, true},
           /*required=*/true);
  std::string pins;
  if (r.choice("pins", pins, clothPinsNames(), "cloth pins")) {
    for (const ClothPins p :
         {ClothPins::None, ClothPins::TopCorners, ClothPins::TopEdge, ClothPins::AllCorners}) {
      if (clothPinsName(p) == pins) cloth.pins = p;
    }
  }
  const std::string scaleText = "times stiffness, a number from 0 to 100";
  r.number("shear_scale", cloth.shearStiffnessScale, scaleText, Range{0.0, 100.0});
  r.number("bend_scale", cloth.bendStiffnessScale, scaleText, Range{0.0, 100.0});
}

void readCluster(Context& cx, TableReader& r, std::int64_t maxParticles, ClusterShape& cluster) {
  r.vec3("center", cluster.center, kPositionText, Range{-kBig, kBig});
  const std::string lengthText = "metres, a number > 0 and <= 1e9";
  const bool radiusOk =
      r.number("radius", cluster.radius, lengthText, Range{0.0, kBig, true}, /*required=*/true);
  const CountLimit count = structureCountLimit(1, maxParticles, "particles");
  const bool countOk =
      r.integer("count", cluster.count, count.text, 1, count.max, /*required=*/true);
  const bool linkOk = r.number("link_radius", cluster.linkRadius, lengthText,
                               Range{0.0, kBig, true}, /*required=*/true);
  if (!(radiusOk && countOk && linkOk)) return;
  // Expected springs: half the particles' neighbours.
  const double springs = cluster.count * clusterNeighbours(cluster) / 2.0;
  if (springs <= kMaxSprings) return;
  // The largest link radius within the bound (bisection: the neighbours grow with it).
  ClusterShape probe = cluster;
  double lo = 0.0, hi = cluster.linkRadius;
  for (int i = 0; i < 200; ++i) {
    probe.linkRadius = 0.5 * (lo + hi);
    (cluster.count * clusterNeighbours(probe) / 2.0 <= kMaxSprings ? lo : hi) = probe.linkRadius;
  }
  // Three significant digits, rounded down so that the figure given is within the bound.
  const double unit = std::pow(10.0, std::floor(std::log10(lo)) - 2.0);
  char largest[32];
  std::snprintf(largest, sizeof largest, "%.3g", std::floor(lo / unit) * unit);
  cx.error(cx.at(*r.table().get("link_radius")), r.pathOf("link_radius"),
           formatNumber(cluster.linkRadius) + " m would join about " +
               std::to_string(static_cast<std::int64_t>(std::llround(springs))) +
               " pairs of particles (expected at most 10000000 springs: a link_radius of at most " +
               largest + " m for this radius and count)");
}

}  // namespace

void readStructure(Context& cx, const toml::table& table, std::size_t index,
                   const std::string& type, std::int64_t maxParticles, StructureSettings& s) {
  TableReader r(cx, table, childPath("emitters", index));
  r.take("type");
  s.name = type + "_" + std::to_string(index);
  r.string("name", s.name, "a name: a non-empty string, unique among the emitters");
  r.number("time", s.time, kSecondsText, Range{0.0, kBig});
  r.number("mass", s.mass, "kilograms per particle, a number > 0 and <= 1e9",
           Range{0.0, kBig, true});
  r.number("stiffness", s.stiffness, "N/m, a number > 0 and <= 1e9", Range{0.0, kBig, true},
           /*required=*/true);
  r.number("damping", s.damping, "N·s/m, a number from 0 to 1e9", Range{0.0, kBig});
  const std::string ratioText = "0 (never breaks) or a ratio of the rest length > 1 and <= 1e9";
  double ratio = 0.0;
  if (r.number("break_ratio", ratio, ratioText, Range{0.0, kBig})) {
    if (ratio > 0.0 && ratio <= 1.0) {
      cx.error(cx.at(*table.get("break_ratio")), r.pathOf("break_ratio"),
               formatNumber(ratio) + " is out of range (expected " + ratioText + ")");
    } else {
      s.breakRatio = ratio;
    }
  }
  r.vec3("velocity", s.velocity, "[x, y, z] in m/s, each from -1e9 to 1e9", Range{-kBig, kBig});
  r.number("lifetime", s.lifetime, "seconds, a number > 0 and <= 1e9", Range{0.0, kBig, true});
  if (type == "rope") {
    RopeShape rope;
    readRope(cx, r, maxParticles, rope);
    s.shape = rope;
  } else if (type == "cloth") {
    ClothShape cloth;
    readCloth(cx, r, maxParticles, cloth);
    s.shape = cloth;
  } else {
    ClusterShape cluster;
    readCluster(cx, r, maxParticles, cluster);
    s.shape = cluster;
  }
  r.finish(notForStructure(type));
}

}  // namespace tickfx::io::detail
