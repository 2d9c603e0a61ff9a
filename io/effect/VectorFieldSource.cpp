#include "io/effect/VectorFieldSource.h"

#include <algorithm>
#include <cmath>

namespace tickfx::io {

BakeSize measureBake(const FieldBakeSettings& bake, std::int64_t frames) {
  BakeSize size;
  const double h = bake.voxelSize;
  const double reach = std::max(bake.min.cwiseAbs().maxCoeff(), bake.max.cwiseAbs().maxCoeff());
  size.reachVoxels = std::ceil(reach / h);
  size.minVoxelSize = reach / kMaxBakedIndex;
  if (reach / h > kMaxBakedIndex) {
    size.problem = BakeSize::Problem::IndexReach;
    return size;
  }
  size.perFrame = bakedVoxelCount(h, bake.min, bake.max);
  size.total = size.perFrame * static_cast<double>(frames);
  if (size.perFrame < 1.0) {
    size.problem = BakeSize::Problem::EmptyBox;
  } else if (size.total > kMaxBakedVoxels) {
    size.problem = BakeSize::Problem::TooManyVoxels;
  }
  return size;
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

SettingProblems analyticFieldProblems(const FieldBakeSettings& bake) {
  switch (bake.kind) {
    case FieldBakeSettings::Kind::Uniform:
      return {};
    case FieldBakeSettings::Kind::Vortex:
      return AnalyticField::validateVortex(bake.axis);
    case FieldBakeSettings::Kind::Shear:
      return AnalyticField::validateShear(bake.direction, bake.gradient);
    case FieldBakeSettings::Kind::CurlNoise:
      break;
  }
  return AnalyticField::validateCurlNoise(bake.frequency, bake.octaves);
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
