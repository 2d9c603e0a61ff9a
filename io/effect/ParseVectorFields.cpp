#include "io/effect/ParseVectorFields.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include <toml++/toml.h>

#include "io/effect/VectorFieldSource.h"

namespace tickfx::io::detail {
namespace {

constexpr std::int64_t kMaxFrameNumber = kMaxFieldFrameNumber;
constexpr std::int64_t kMaxSequenceFrames = kMaxFieldFrames;

const std::vector<std::string> kFieldModes = {"force", "drag", "advect"};
const std::vector<std::string> kFieldInterpolations = {"linear", "quadratic"};
const std::vector<std::string> kFieldOutside = {"background", "zero", "kill"};

// Keys every bake table reads, then each kind's own, in the order "expected for" lists them.
const std::vector<std::string>& bakeCommonKeys() {
  static const std::vector<std::string> keys = {"kind", "voxel_size", "bounds", "staggered",
                                                "background"};
  return keys;
}

const std::map<std::string, std::vector<std::string>>& bakeKindKeys() {
  static const std::map<std::string, std::vector<std::string>> keys = {
      {"uniform", {"velocity"}},
      {"vortex", {"centre", "axis", "omega"}},
      {"shear", {"origin", "direction", "gradient", "rate"}},
      {"curl-noise", {"seed", "frequency", "amplitude", "octaves", "evolution"}}};
  return keys;
}

// `bounds = [x0, y0, z0, x1, y1, z1]`: the box a bake fills, its lower corner first.
void readBounds(Context& cx, TableReader& r, FieldBakeSettings& bake) {
  const toml::node* node = r.take("bounds");
  if (node == nullptr) return;
  const std::string path = r.pathOf("bounds");
  const std::string expected =
      "[x0, y0, z0, x1, y1, z1] in metres, each from -1e9 to 1e9, with x0 <= x1, y0 <= y1 and "
      "z0 <= z1";
  const toml::array* array = node->as_array();
  if (array == nullptr) {
    cx.error(cx.at(*node), path, describe(*node) + " (expected " + expected + ")");
    return;
  }
  if (array->size() != 6) {
    cx.error(cx.at(*node), path,
             "got " + std::to_string(array->size()) + (array->size() == 1 ? " entry" : " entries") +
                 " (expected " + expected + ")");
    return;
  }
  double v[6] = {};
  bool ok = true;
  for (std::size_t i = 0; i < 6; ++i) {
    const std::optional<double> c =
        checkNumber(cx, *array->get(i), childPath(path, i), expected, Range{-kBig, kBig});
    if (c) v[i] = *c;
    ok = ok && c.has_value();
  }
  if (!ok) return;
  for (int c = 0; c < 3; ++c) {
    if (v[c + 3] < v[c]) {
      const std::string axis(1, "xyz"[c]);
      cx.error(cx.at(*array->get(static_cast<std::size_t>(c + 3))), childPath(path, c + 3),
               axis + "1 = " + formatNumber(v[c + 3]) + " is below " + axis +
                   "0 = " + formatNumber(v[c]) + " (expected " + expected + ")");
      ok = false;
    }
  }
  if (!ok) return;
  cx.record(path, *node);
  bake.min = Eigen::Vector3d(v[0], v[1], v[2]);
  bake.max = Eigen::Vector3d(v[3], v[4], v[5]);
}

// Keys of the other kinds, on a bake of `kind`.
std::map<std::string, std::string> notForKind(const std::string& kind) {
  std::vector<std::string> own = bakeCommonKeys();
  const std::vector<std::string>& extra = bakeKindKeys().at(kind);
  own.insert(own.end(), extra.begin(), extra.end());
  std::map<std::string, std::string> out;
  for (const auto& [other, keys] : bakeKindKeys()) {
    for (const std::string& k : keys) {
      if (std::find(own.begin(), own.end(), k) == own.end()) {
        out[k] = "does not apply to a bake of kind " + quote(kind) + " (expected for " + kind +
                 ": " + joinWords(own) + ")";
      }
    }
  }
  return out;
}

// The `bake` table of a vector field. Returns false when it has errors.
bool readBake(Context& cx, const toml::table& table, const std::string& path,
              FieldBakeSettings& bake) {
  const std::size_t before = cx.diagnostics().size();
  TableReader r(cx, table, path);
  std::string kind;
  if (!r.choice("kind", kind, fieldKindNames(), "field kind", /*required=*/true)) {
    // Without a kind no parameter can be judged, only unknown keys.
    r.allow(bakeCommonKeys());
    for (const auto& [name, keys] : bakeKindKeys()) r.allow(keys);
    r.finish();
    return false;
  }
  for (std::size_t k = 0; k < fieldKindNames().size(); ++k) {
    if (fieldKindNames()[k] == kind) bake.kind = static_cast<FieldBakeSettings::Kind>(k);
  }
  const Range any{-kBig, kBig};
  r.number("voxel_size", bake.voxelSize, "metres, a number > 0 and <= 1e9", Range{0.0, kBig, true});
  readBounds(cx, r, bake);
  r.boolean("staggered", bake.staggered);
  r.vec3("background", bake.background, "[x, y, z] in the field's unit, each from -1e9 to 1e9",
         any);
  const std::string velocityText = "[x, y, z] in m/s, each from -1e9 to 1e9";
  const std::string omegaText = "radians per second, a number from -1e9 to 1e9";
  if (kind == "uniform") {
    r.vec3("velocity", bake.velocity, velocityText, any);
  } else if (kind == "vortex") {
    r.vec3("centre", bake.centre, kPositionText, any);
    r.vec3("axis", bake.axis, kDirectionText, any, /*nonZero=*/true);
    r.number("omega", bake.omega, omegaText, any);
  } else if (kind == "shear") {
    r.vec3("origin", bake.origin, kPositionText, any);
    r.vec3("direction", bake.direction, kDirectionText, any, /*nonZero=*/true);
    r.vec3("gradient", bake.gradient, kDirectionText, any, /*nonZero=*/true);
    r.number("rate", bake.rate, "1/s, a number from -1e9 to 1e9", any);
  } else {
    r.integer("seed", bake.seed, "an integer from 0 to 9223372036854775807", 0,
              std::numeric_limits<std::int64_t>::max());
    r.number("frequency", bake.frequency, "radians per metre, a number > 0 and <= 1e9",
             Range{0.0, kBig, true});
    r.number("amplitude", bake.amplitude, "m/s, a number from 0 to 1e9", Range{0.0, kBig});
    r.integer("octaves", bake.octaves, "an integer from 1 to 16", 1, kMaxCurlOctaves);
    r.number("evolution", bake.evolution, "radians per second, a number from 0 to 1e9",
             Range{0.0, kBig});
  }
  r.finish(notForKind(kind));
  return cx.diagnostics().size() == before;
}

// The grid a bake makes: every frame within kMaxBakedVoxels, voxel indices within
// kMaxBakedIndex, and at least one voxel centre in the box.
void checkBakeSize(Context& cx, const std::string& path, const FieldBakeSettings& bake,
                   std::int64_t frames) {
  const std::string voxelPath = childPath(path, "voxel_size");
  const std::string boundsPath = childPath(path, "bounds");
  const double h = bake.voxelSize;
  const BakeSize size = measureBake(bake, frames);
  switch (size.problem) {
    case BakeSize::Problem::None:
      return;
    case BakeSize::Problem::IndexReach:
      cx.error(cx.sources().find(voxelPath), voxelPath,
               formatNumber(h) + " m puts the bounds " + formatNumber(size.reachVoxels) +
                   " voxels from the origin (expected a voxel_size of at least " +
                   formatNumber(size.minVoxelSize) +
                   " m for these bounds: voxel indices within 1e9)");
      return;
    case BakeSize::Problem::EmptyBox:
      cx.error(cx.sources().find(boundsPath), boundsPath,
               "hold no voxel centre at voxel_size = " + formatNumber(h) +
                   " m (expected a box holding at least one point i*voxel_size on each axis)");
      return;
    case BakeSize::Problem::TooManyVoxels:
      cx.error(cx.sources().find(voxelPath), voxelPath,
               formatNumber(h) + " m makes " + formatNumber(size.perFrame) + " voxels a frame, " +
                   formatNumber(size.total) + " over " + std::to_string(frames) +
                   (frames == 1 ? " frame" : " frames") +
                   " (expected at most 100000000 voxels over all frames: a larger voxel_size, "
                   "smaller bounds or fewer frames)");
      return;
  }
}

// The `file` or `bake` of a vector field (exactly one of them), into `f`. Returns whether `file`
// was read.
bool readFieldSource(Context& cx, TableReader& r, VectorFieldSettings& f) {
  const toml::table& table = r.table();
  const std::string fileText =
      "a .vdb file path relative to the effect file's directory, a non-empty string";
  const bool hasFile = r.string("file", f.file, fileText);
  const toml::node* fileNode = table.get("file");
  const toml::node* bakeNode = r.take("bake");
  bool bakeOk = false;
  FieldBakeSettings bake;
  if (bakeNode != nullptr) {
    if (const toml::table* bakeTable = bakeNode->as_table()) {
      bakeOk = readBake(cx, *bakeTable, r.pathOf("bake"), bake);
    } else {
      cx.error(cx.at(*bakeNode), r.pathOf("bake"),
               describe(*bakeNode) +
                   " (expected a bake table such as { kind = \"vortex\", voxel_size = 0.1 })");
    }
    if (fileNode != nullptr) {
      cx.error(cx.at(*bakeNode), r.pathOf("bake"),
               "given together with file (expected either file or bake)");
    }
  } else if (fileNode == nullptr) {
    r.missing("file", fileText + ", or a bake table");
  }
  if (bakeOk && fileNode == nullptr) f.bake = bake;
  if (hasFile) {
    f.path = (std::filesystem::path(cx.file()).parent_path() / f.file).string();
  }
  return hasFile;
}

// Reports `key` of a baked field (one with a bake table), where `why` says when it applies.
// Returns whether it reported.
bool refusedForBake(Context& cx, TableReader& r, std::string_view key, const std::string& why) {
  if (r.table().get("bake") == nullptr) return false;
  if (const toml::node* node = r.table().get(key)) {
    cx.error(cx.at(*node), r.pathOf(key), "does not apply to a baked field (expected " + why + ")");
    return true;
  }
  return false;
}

// How a vector field acts on the particles: mode, scale, interpolation and outside.
void readFieldSampling(TableReader& r, VectorFieldSettings& f) {
  std::string mode = "force";
  if (r.choice("mode", mode, kFieldModes, "field mode")) {
    f.mode = mode == "drag"     ? VectorField::Mode::Drag
             : mode == "advect" ? VectorField::Mode::Advect
                                : VectorField::Mode::Force;
  }
  if (f.mode == VectorField::Mode::Drag) {
    r.number("scale", f.scale, "a rate k in 1/s for mode \"drag\", a number from 0 to 1e9",
             Range{0.0, kBig});
  } else {
    const std::string unit = f.mode == VectorField::Mode::Advect ? "m/s" : "m/s²";
    r.number(
        "scale", f.scale,
        unit + " per unit of the field for mode " + quote(mode) + ", a number from -1e9 to 1e9",
        Range{-kBig, kBig});
  }
  std::string interpolation;
  if (r.choice("interpolation", interpolation, kFieldInterpolations, "interpolation")) {
    f.interpolation = interpolation == "quadratic" ? VectorField::Interpolation::Quadratic
                                                   : VectorField::Interpolation::Linear;
  }
  std::string outside;
  if (r.choice("outside", outside, kFieldOutside, "outside policy")) {
    f.outside = outside == "kill"   ? VectorField::Outside::Kill
                : outside == "zero" ? VectorField::Outside::Zero
                                    : VectorField::Outside::Background;
  }
}

// The sequence keys: fps makes a sequence; first_frame, last_frame and frame_padding mean nothing
// without it. Returns the number of frames (1 for a single file or bake), or nothing when fps is
// given but could not be read.
std::optional<std::int64_t> readFieldSequence(Context& cx, TableReader& r, VectorFieldSettings& f) {
  const toml::table& table = r.table();
  const bool hasFps =
      r.number("fps", f.fps, "frames per second, a number from 1e-6 to 1000000", Range{1e-6, 1e6});
  const toml::node* fpsNode = table.get("fps");
  const std::string frameText = "a frame number, an integer from -1000000 to 1000000";
  for (const char* key : {"first_frame", "last_frame", "frame_padding"}) {
    const toml::node* node = table.get(key);
    if (node != nullptr && fpsNode == nullptr) {
      r.take(key);
      cx.error(cx.at(*node), r.pathOf(key),
               "given without fps (expected fps, first_frame and last_frame for a sequence)");
    }
  }
  std::int64_t frames = 1;
  if (fpsNode != nullptr) {
    const bool firstOk =
        r.integer("first_frame", f.firstFrame, frameText, -kMaxFrameNumber, kMaxFrameNumber) ||
        table.get("first_frame") == nullptr;
    const toml::node* lastNode = table.get("last_frame");
    if (lastNode == nullptr) {
      r.take("last_frame");
      r.missing("last_frame",
                "the last frame of the sequence, an integer from first_frame to "
                "1000000");
    } else if (r.integer("last_frame", f.lastFrame, frameText, -kMaxFrameNumber, kMaxFrameNumber) &&
               firstOk) {
      const std::int64_t count = std::int64_t{f.lastFrame} - f.firstFrame + 1;
      if (count < 1) {
        cx.error(cx.at(*lastNode), r.pathOf("last_frame"),
                 std::to_string(f.lastFrame) +
                     " is before first_frame = " + std::to_string(f.firstFrame) +
                     " (expected the last frame of the sequence, an integer from first_frame to "
                     "1000000)");
      } else if (count > kMaxSequenceFrames) {
        cx.error(cx.at(*lastNode), r.pathOf("last_frame"),
                 std::to_string(count) +
                     " frames are too many (expected at most 10000 frames in a sequence)");
      } else {
        frames = count;
      }
    }
    if (!refusedForBake(cx, r, "frame_padding", "frame_padding only with a file pattern")) {
      r.integer("frame_padding", f.framePadding, "digits, an integer from 1 to 10", 1, 10);
    }
    r.take("frame_padding");
  }
  if (fpsNode != nullptr && !hasFps) return std::nullopt;
  return frames;
}

}  // namespace

void readVectorField(Context& cx, TableReader& r, VectorFieldSettings& f) {
  const bool hasFile = readFieldSource(cx, r, f);
  if (!refusedForBake(cx, r, "grid", "grid only with file: a bake makes its own grid")) {
    r.string("grid", f.grid, "a grid name, a non-empty string");
  }
  r.take("grid");
  readFieldSampling(r, f);
  const std::optional<std::int64_t> frames = readFieldSequence(cx, r, f);
  const toml::node* fileNode = r.table().get("file");
  const toml::node* fpsNode = r.table().get("fps");
  if (hasFile) {
    const bool pattern = f.file.find("{frame}") != std::string::npos;
    if (fpsNode != nullptr && !pattern) {
      cx.error(cx.at(*fileNode), r.pathOf("file"),
               quote(f.file) +
                   " has no {frame} (expected a file pattern with {frame} for a sequence, since "
                   "fps is given)");
    } else if (fpsNode == nullptr && pattern) {
      cx.error(cx.at(*fileNode), r.pathOf("file"),
               quote(f.file) +
                   " has {frame} but fps is not given (expected fps, first_frame and last_frame "
                   "for a sequence, or a file name without {frame})");
    }
  }
  // A sequence whose fps could not be read has no frame count to judge the bake's size by.
  if (f.bake && frames) checkBakeSize(cx, r.pathOf("bake"), *f.bake, *frames);
}

void checkAdvection(Context& cx, const EffectSettings& effect,
                    const std::vector<std::size_t>& entries) {
  std::vector<std::string> ignored;
  for (std::size_t i = 0; i < effect.forces.size(); ++i) {
    const auto* field = std::get_if<VectorFieldSettings>(&effect.forces[i]);
    if (field != nullptr && field->mode == VectorField::Mode::Advect) continue;
    ignored.push_back(childPath("forces", entries[i]) + " (" +
                      std::string(forceTypeName(effect.forces[i])) + ")");
  }
  for (std::size_t s = 0; s < effect.structures.size(); ++s) {
    ignored.push_back(structureKeyPath(effect, s) + " (the springs of a " +
                      std::string(structureTypeName(effect.structures[s].shape)) + ")");
  }
  if (ignored.empty()) return;
  constexpr std::size_t kListed = 3;
  std::string list;
  for (std::size_t i = 0; i < ignored.size() && i < kListed; ++i) {
    const bool last = i + 1 == ignored.size() || i + 1 == kListed;
    list += (i == 0 ? "" : (last && ignored.size() <= kListed ? " and " : ", ")) + ignored[i];
  }
  if (ignored.size() > kListed) {
    list += " and " + std::to_string(ignored.size() - kListed) + " more";
  }
  const bool one = ignored.size() == 1;
  for (std::size_t i = 0; i < effect.forces.size(); ++i) {
    const auto* field = std::get_if<VectorFieldSettings>(&effect.forces[i]);
    if (field == nullptr || field->mode != VectorField::Mode::Advect) continue;
    const std::string path = childPath(childPath("forces", entries[i]), "mode");
    cx.error(cx.sources().find(path), path,
             "\"advect\" sets the particles' velocity to the field's, so " + list +
                 (one ? " would be" : " would all be") +
                 " ignored (expected mode = \"drag\", which pulls the particles toward the "
                 "field's velocity alongside other forces, or advect fields as the only forces "
                 "of an effect without structures)");
  }
}

}  // namespace tickfx::io::detail
