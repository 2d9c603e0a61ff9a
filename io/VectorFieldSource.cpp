#include "io/VectorFieldSource.h"

#include <algorithm>
#include <cmath>

namespace tickfx::io {

double bakedVoxelCount(double voxelSize, const Eigen::Vector3d& min, const Eigen::Vector3d& max) {
  double count = 1.0;
  for (int c = 0; c < 3; ++c) {
    // The same centres as bakeField: indices ceil(min/h) to floor(max/h).
    const double along = std::floor(max[c] / voxelSize) - std::ceil(min[c] / voxelSize) + 1.0;
    count *= std::max(0.0, along);
  }
  return count;
}

std::string sequenceFramePath(const std::string& pattern, int frame, int padding) {
  const std::string key = "{frame}";
  const std::size_t at = pattern.find(key);
  if (at == std::string::npos) return pattern;
  // As fields/VectorField.cpp names the frames it loads.
  std::string number = std::to_string(frame < 0 ? -static_cast<long long>(frame) : frame);
  if (number.size() < static_cast<std::size_t>(padding)) {
    number.insert(0, static_cast<std::size_t>(padding) - number.size(), '0');
  }
  if (frame < 0) number.insert(0, 1, '-');
  std::string path = pattern;
  path.replace(at, key.size(), number);
  return path;
}

AnalyticField analyticField(const FieldBakeSettings& bake) {
  switch (bake.kind) {
    case FieldBakeSettings::Kind::Uniform:
      return AnalyticField::uniform(bake.velocity);
    case FieldBakeSettings::Kind::Vortex:
      return AnalyticField::vortex(bake.centre, bake.axis, bake.omega);
    case FieldBakeSettings::Kind::Shear:
      return AnalyticField::shear(bake.origin, bake.direction, bake.gradient, bake.rate);
    case FieldBakeSettings::Kind::CurlNoise:
      break;
  }
  return AnalyticField::curlNoise(bake.seed, bake.frequency, bake.amplitude, bake.octaves,
                                  bake.evolution);
}

BakeSettings bakeSettings(const FieldBakeSettings& bake, const std::string& gridName) {
  BakeSettings s;
  s.gridName = gridName;
  s.voxelSize = bake.voxelSize;
  s.min = bake.min;
  s.max = bake.max;
  s.background = bake.background.cast<float>();
  s.staggered = bake.staggered;
  return s;
}

std::unique_ptr<VectorField> loadVectorField(const VectorFieldSettings& field) {
  VectorField::Settings s;
  s.grid = field.grid;
  s.mode = field.mode;
  s.scale = static_cast<float>(field.scale);
  s.interpolation = field.interpolation;
  s.outside = field.outside;
  s.fps = field.fps;
  s.firstFrame = field.firstFrame;
  s.lastFrame = field.fps > 0.0 ? field.lastFrame : field.firstFrame;
  s.framePadding = field.framePadding;
  if (!field.bake) {
    s.file = field.path;
    return std::make_unique<VectorField>(s);
  }
  // A baked field has no file: the name only labels VectorField's messages, and a sequence's
  // label needs the {frame} a sequence of files would have.
  s.file = "baked " + std::string(fieldKindName(field.bake->kind)) + " field" +
           (field.fps > 0.0 ? " {frame}" : "");
  return bakeVectorField(analyticField(*field.bake), bakeSettings(*field.bake, field.grid), s);
}

}  // namespace tickfx::io
