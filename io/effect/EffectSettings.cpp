#include "io/effect/EffectSettings.h"

#include <algorithm>
#include <cmath>

namespace tickfx::io {

std::string_view forceTypeName(const ForceSettings& force) {
  struct Name {
    std::string_view operator()(const GravitySettings&) const { return "gravity"; }
    std::string_view operator()(const DragSettings&) const { return "drag"; }
    std::string_view operator()(const WindSettings&) const { return "wind"; }
    std::string_view operator()(const AnchorSpringSettings&) const { return "anchor_spring"; }
    std::string_view operator()(const VectorFieldSettings&) const { return "vector_field"; }
  };
  return std::visit(Name{}, force);
}

const std::vector<std::string>& forceTypeNames() {
  static const std::vector<std::string> names = {"gravity", "drag", "wind", "anchor_spring",
                                                 "vector_field"};
  return names;
}

const std::vector<std::string>& fieldKindNames() {
  static const std::vector<std::string> names = {"uniform", "vortex", "shear", "curl-noise"};
  return names;
}

std::string_view fieldKindName(FieldBakeSettings::Kind kind) {
  return fieldKindNames()[static_cast<std::size_t>(kind)];
}

const std::vector<std::string>& emitterTypeNames() {
  static const std::vector<std::string> names = {"particles", "file", "rope", "cloth", "cluster"};
  return names;
}

std::string_view structureTypeName(const StructureShape& shape) {
  struct Name {
    std::string_view operator()(const RopeShape&) const { return "rope"; }
    std::string_view operator()(const ClothShape&) const { return "cloth"; }
    std::string_view operator()(const ClusterShape&) const { return "cluster"; }
  };
  return std::visit(Name{}, shape);
}

const std::vector<std::string>& clothPinsNames() {
  static const std::vector<std::string> names = {"none", "top_corners", "top_edge", "corners"};
  return names;
}

std::string_view clothPinsName(ClothPins pins) {
  switch (pins) {
    case ClothPins::None:
      return "none";
    case ClothPins::TopCorners:
      return "top_corners";
    case ClothPins::TopEdge:
      return "top_edge";
    case ClothPins::AllCorners:
      return "corners";
  }
  return "none";
}

double clusterNeighbours(const ClusterShape& cluster) {
  const double x = cluster.linkRadius / cluster.radius;
  const double fraction =
      x >= 2.0 ? 1.0 : x * x * x - 9.0 * std::pow(x, 4) / 16.0 + std::pow(x, 6) / 32.0;
  return (cluster.count - 1) * fraction;
}

std::string structureKeyPath(const EffectSettings& effect, std::size_t index) {
  if (index < effect.structureEntries.size())
    return "emitters." + std::to_string(effect.structureEntries[index]);
  return "structures." + std::to_string(index);
}

std::string emitterKeyPath(const EffectSettings& effect, std::size_t index) {
  std::size_t entry = 0;
  for (std::size_t seen = 0;; ++entry) {
    const auto& taken = effect.structureEntries;
    if (std::find(taken.begin(), taken.end(), entry) != taken.end()) continue;
    if (seen++ == index) return "emitters." + std::to_string(entry);
  }
}

std::int64_t OutputSettings::frameCount() const {
  if (frames) return *frames;
  const double exact =
      seconds * static_cast<double>(fps.numerator) / static_cast<double>(fps.denominator);
  // 10 s at 24 fps is 240 frames even if the product comes out as 240.00000000000003.
  const double nearest = std::round(exact);
  const double count =
      std::abs(exact - nearest) <= 1e-9 * std::max(1.0, nearest) ? nearest : std::ceil(exact);
  return std::max<std::int64_t>(1, static_cast<std::int64_t>(count));
}

double OutputSettings::durationSeconds() const {
  return static_cast<double>(frameCount()) * static_cast<double>(fps.denominator) /
         static_cast<double>(fps.numerator);
}

}  // namespace tickfx::io
