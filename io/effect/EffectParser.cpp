#include "io/effect/EffectParser.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include <toml++/toml.h>

#include "integrators/Integrator.h"
#include "io/cache/CsvCache.h"
#include "io/cache/VdbPointCache.h"
#include "io/effect/EditDistance.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/ParseEmitters.h"
#include "io/effect/SettingOverrides.h"
#include "io/effect/TableReader.h"
#include "io/effect/VectorFieldSource.h"
#include "io/util/Fingerprint.h"

#if !TOML_EXCEPTIONS
#error "tickfx_io reads parse errors from toml::parse_error: build toml++ with exceptions"
#endif

namespace tickfx::io {
namespace detail {
namespace {

constexpr std::int64_t kMaxStepRate = 1'000'000;
constexpr std::int64_t kMaxParticles = 1'000'000'000;
constexpr std::int64_t kMaxTicksPerFrame = 100'000;
constexpr std::size_t kMaxEntries = 10'000;  // emitters, forces
constexpr std::int64_t kMaxFrameRatePart = 1'000'000;

const std::vector<std::string> kOverrunPolicies = {"drop", "fall_behind"};
const std::vector<std::string> kCacheFormats = [] {
  std::vector<std::string> names;
  for (const CacheFormat f : kCacheFormatList) names.emplace_back(cacheFormatName(f));
  return names;
}();

const std::map<std::string, std::vector<std::string>>& forceKeys() {
  static const std::map<std::string, std::vector<std::string>> keys = {
      {"gravity", {"acceleration"}},
      {"drag", {"k", "air_velocity"}},
      {"wind", {"direction", "base", "amplitude", "frequency", "phase"}},
      {"anchor_spring", {"rest", "stiffness", "damping"}},
      {"vector_field",
       {"file", "bake", "grid", "mode", "scale", "interpolation", "outside", "fps", "first_frame",
        "last_frame", "frame_padding"}}};
  return keys;
}

// ---- the sections of a version-1 document ----------------------------------------------------

void readSimulation(Context& cx, const toml::table& table, SystemSettings& s) {
  TableReader r(cx, table, "simulation");
  r.integer("step_rate", s.stepRateHz, "ticks per second (Hz), an integer from 1 to 1000000", 1,
            kMaxStepRate, /*required=*/true);
  r.choice("integrator", s.integrator, integratorNames(), "integrator");
  r.integer("seed", s.seed, "an integer from 0 to 9223372036854775807", 0,
            std::numeric_limits<std::int64_t>::max());
  r.integer("max_particles", s.maxParticles, "an integer from 1 to 1000000000", 1, kMaxParticles);
  r.integer("max_ticks_per_frame", s.maxTicksPerFrame, "an integer from 1 to 100000", 1,
            kMaxTicksPerFrame);
  std::string overrun;
  if (r.choice("overrun", overrun, kOverrunPolicies, "overrun policy")) {
    s.overrunPolicy = overrun == "drop" ? OverrunPolicy::DropExcess : OverrunPolicy::FallBehind;
  }
  r.integer("threads", s.threads, "worker threads, an integer from 0 (all cores) to 1024", 0,
            kMaxThreads);
  std::string nonfinite;
  if (r.choice("nonfinite", nonfinite, nonfinitePolicyNames(), "nonfinite policy")) {
    s.nonfinite = nonfinitePolicyNamed(nonfinite);
  }
  r.finish();
}

// ---- vector fields: [[forces]] of type "vector_field" -----------------------------------------

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

void readVectorField(Context& cx, TableReader& r, VectorFieldSettings& f) {
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

  const auto notForBake = [&](std::string_view key, const std::string& why) {
    if (bakeNode == nullptr) return false;
    if (const toml::node* node = table.get(key)) {
      cx.error(cx.at(*node), r.pathOf(key),
               "does not apply to a baked field (expected " + why + ")");
      return true;
    }
    return false;
  };
  if (!notForBake("grid", "grid only with file: a bake makes its own grid")) {
    r.string("grid", f.grid, "a grid name, a non-empty string");
  }
  r.take("grid");

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

  // Sequences: fps makes one; the frame keys mean nothing without it.
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
    if (!notForBake("frame_padding", "frame_padding only with a file pattern")) {
      r.integer("frame_padding", f.framePadding, "digits, an integer from 1 to 10", 1, 10);
    }
    r.take("frame_padding");
  }
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
  if (f.bake && (hasFps || fpsNode == nullptr)) {
    checkBakeSize(cx, r.pathOf("bake"), *f.bake, frames);
  }
}

// Advection prescribes velocity: next to it, every acceleration (forces, a structure's springs)
// would be silently dropped, so an effect may not mix them (ForceSet would refuse too). Several
// advect fields are fine: their velocities add. `entries` holds the [[forces]] entry of each of
// effect.forces.
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

std::optional<ForceSettings> readForce(Context& cx, const toml::table& table, std::size_t index) {
  TableReader r(cx, table, childPath("forces", index));
  std::string type;
  if (!r.choice("type", type, forceTypeNames(), "force type", /*required=*/true)) {
    for (const auto& [name, keys] : forceKeys()) r.allow(keys);
    r.finish();
    return std::nullopt;
  }
  const Range any{-kBig, kBig};
  const std::string accelerationText = "m/s², a number from -1e9 to 1e9";
  std::optional<ForceSettings> force;
  bool ok = true;
  if (type == "gravity") {
    GravitySettings g;
    r.vec3("acceleration", g.acceleration, "[x, y, z] in m/s², each from -1e9 to 1e9", any);
    force = g;
  } else if (type == "drag") {
    DragSettings d;
    ok = r.number("k", d.k, "a rate in 1/s, a number from 0 to 1e9", Range{0.0, kBig}, true) && ok;
    r.vec3("air_velocity", d.airVelocity, "[x, y, z] in m/s, each from -1e9 to 1e9", any);
    force = d;
  } else if (type == "wind") {
    WindSettings w;
    r.vec3("direction", w.direction, kDirectionText, any, /*nonZero=*/true);
    r.number("base", w.base, accelerationText, any);
    ok = r.number("amplitude", w.amplitude, accelerationText, any, true) && ok;
    ok = r.number("frequency", w.frequency, "hertz, a number from 0 to 1000000", Range{0.0, 1e6},
                  true) &&
         ok;
    r.number("phase", w.phase, "radians, a number from -1e9 to 1e9", any);
    force = w;
  } else if (type == "vector_field") {
    VectorFieldSettings v;
    readVectorField(cx, r, v);
    force = v;
  } else {
    AnchorSpringSettings a;
    r.vec3("rest", a.rest, kPositionText, any);
    ok = r.number("stiffness", a.stiffness, "N/m, a number > 0 and <= 1e9", Range{0.0, kBig, true},
                  true) &&
         ok;
    r.number("damping", a.damping, "N·s/m, a number from 0 to 1e9", Range{0.0, kBig});
    force = a;
  }
  const std::vector<std::string>& own = forceKeys().at(type);
  std::map<std::string, std::string> notHere;
  for (const auto& [other, keys] : forceKeys()) {
    for (const std::string& k : keys) {
      if (std::find(own.begin(), own.end(), k) == own.end()) {
        notHere[k] = "does not apply to a force of type " + quote(type) + " (expected for " + type +
                     ": type, " + joinWords(own) + ")";
      }
    }
  }
  r.finish(notHere);
  return force;
}

// "30000/1001" or "24" as a frame rate.
std::optional<FrameRate> parseRatio(std::string_view text) {
  const auto readPart = [](std::string_view part) -> std::optional<std::int64_t> {
    std::int64_t v = 0;
    const auto [end, ec] = std::from_chars(part.data(), part.data() + part.size(), v);
    if (ec != std::errc() || end != part.data() + part.size() || part.empty()) return std::nullopt;
    return v;
  };
  const std::size_t slash = text.find('/');
  const auto num = readPart(text.substr(0, slash));
  const auto den = slash == std::string_view::npos ? std::optional<std::int64_t>(1)
                                                   : readPart(text.substr(slash + 1));
  if (!num || !den) return std::nullopt;
  return FrameRate{*num, *den};
}

void readFps(Context& cx, TableReader& r, OutputSettings& out) {
  const toml::node* node = r.take("fps");
  if (node == nullptr) return;
  const std::string path = r.pathOf("fps");
  const std::string expected =
      "frames per second, an integer from 1 to 1000000 or a ratio string like \"30000/1001\"";
  std::optional<FrameRate> rate;
  std::string shown;
  if (const auto s = node->value_exact<std::string>()) {
    rate = parseRatio(*s);
    shown = quote(*s);
    if (!rate) {
      cx.error(cx.at(*node), path, shown + " is not a frame rate (expected " + expected + ")");
      return;
    }
  } else if (const auto i = node->value_exact<std::int64_t>()) {
    rate = FrameRate{*i, 1};
    shown = std::to_string(*i);
  } else {
    cx.error(cx.at(*node), path, describe(*node) + " (expected " + expected + ")");
    return;
  }
  if (rate->numerator < 1 || rate->numerator > kMaxFrameRatePart || rate->denominator < 1 ||
      rate->denominator > kMaxFrameRatePart) {
    cx.error(cx.at(*node), path, shown + " is out of range (expected " + expected + ")");
    return;
  }
  try {
    frameDuration(*rate);
  } catch (const std::invalid_argument&) {
    cx.error(cx.at(*node), path,
             shown +
                 " frames per second do not last a whole number of flicks (expected a rate "
                 "whose frame is a whole number of 1/705600000 s, such as 24, 25, 30, 60, 120 "
                 "or \"30000/1001\")");
    return;
  }
  cx.record(path, *node);
  out.fps = *rate;
}

void readOutput(Context& cx, const toml::table& table, OutputSettings& out) {
  TableReader r(cx, table, "output");
  readFps(cx, r, out);
  const bool hasSeconds = r.number("seconds", out.seconds, "seconds, a number > 0 and <= 1e9",
                                   Range{0.0, kMaxRunSeconds, true});
  std::int64_t frames = 0;
  if (r.integer("frames", frames, "an integer from 1 to 1000000000", 1, kMaxRunFrames)) {
    if (hasSeconds || table.get("seconds") != nullptr) {
      cx.error(cx.at(*table.get("frames")), r.pathOf("frames"),
               "given together with output.seconds (expected either seconds or frames)");
    } else {
      out.frames = frames;
    }
  }
  if (const toml::node* node = r.take("formats")) {
    const std::string path = r.pathOf("formats");
    if (const toml::array* array = node->as_array()) {
      std::vector<CacheFormat> formats;
      bool ok = true;
      for (std::size_t i = 0; i < array->size(); ++i) {
        const std::string entryPath = childPath(path, i);
        const auto name = checkChoice(cx, *array->get(i), entryPath, kCacheFormats, "cache format");
        if (!name) {
          ok = false;
          continue;
        }
        const CacheFormat f = *cacheFormatFromName(*name);  // checkChoice took a known name
        if (std::find(formats.begin(), formats.end(), f) != formats.end()) {
          cx.error(cx.at(*array->get(i)), entryPath,
                   quote(*name) + " is listed twice (expected each format at most once)");
          ok = false;
          continue;
        }
        formats.push_back(f);
      }
      if (ok) {
        cx.record(path, *node);
        out.formats = formats;
      }
    } else {
      cx.error(
          cx.at(*node), path,
          describe(*node) + " (expected an array of cache formats, such as [\"csv\", \"ply\"])");
    }
  }
  r.string("directory", out.directory, "a directory path, a non-empty string");
  std::string name;
  if (r.choice("vdb_compression", name, vdbCompressionNames(), "VDB compression"))
    out.vdb.compression = *vdbCompressionNamed(name);
  if (r.choice("vdb_positions", name, vdbPositionsNames(), "VDB positions"))
    out.vdb.positions = *vdbPositionsNamed(name);
  r.finish();
}

// An array of tables ([[emitters]], [[forces]]): each entry handed to `read`.
template <typename Read>
void readEntries(Context& cx, TableReader& top, std::string_view key, bool required, Read read) {
  const toml::node* node = top.take(key);
  const std::string path(key);
  const std::string expected = "an array of tables, written [[" + path + "]]";
  if (node == nullptr) {
    if (required) top.missing(key, "at least one [[" + path + "]] table");
    return;
  }
  const toml::array* array = node->as_array();
  if (array == nullptr) {
    cx.error(cx.at(*node), path, describe(*node) + " (expected " + expected + ")");
    return;
  }
  if (array->empty() && required) {
    cx.error(cx.at(*node), path,
             "got an empty array (expected at least one [[" + path + "]] table)");
    return;
  }
  if (array->size() > kMaxEntries) {
    cx.error(cx.at(*node), path,
             std::to_string(array->size()) + " entries are too many (expected at most 10000)");
    return;
  }
  cx.record(path, *node);
  for (std::size_t i = 0; i < array->size(); ++i) {
    const toml::node& entry = *array->get(i);
    if (const toml::table* table = entry.as_table()) {
      read(*table, i);
    } else {
      cx.error(cx.at(entry), childPath(path, i), describe(entry) + " (expected a table)");
    }
  }
}

// Validates a document of the current version (format_version was handled by the migration).
EffectSettings readCurrentVersion(Context& cx, const toml::table& document) {
  EffectSettings effect;
  TableReader top(cx, document, "");
  if (const toml::node* version = top.take("format_version");
      version && cx.origins().labelOf(*version)) {
    cx.error(cx.at(*version), "format_version",
             "cannot be changed by an override (expected the version the file is written in)");
  }

  if (const toml::node* node = top.take("simulation")) {
    if (const toml::table* table = node->as_table()) {
      readSimulation(cx, *table, effect.simulation);
    } else {
      cx.error(cx.at(*node), "simulation", describe(*node) + " (expected a [simulation] table)");
    }
  } else {
    top.missing("simulation", "a [simulation] table with at least step_rate");
  }

  const auto maxParticles = static_cast<std::int64_t>(effect.simulation.maxParticles);
  std::map<std::string, std::size_t> names;
  readEntries(cx, top, "emitters", /*required=*/true, [&](const toml::table& table, std::size_t i) {
    readEmitterEntry(cx, table, i, maxParticles, effect, names);
  });
  std::vector<std::size_t> forceEntries;
  readEntries(cx, top, "forces", /*required=*/false, [&](const toml::table& table, std::size_t i) {
    const std::size_t errorsBefore = cx.diagnostics().size();
    if (auto force = readForce(cx, table, i)) {
      if (cx.diagnostics().size() == errorsBefore) {
        reportProblems(cx, childPath("forces", i), forceProblems(*force));
      }
      effect.forces.push_back(*force);
      forceEntries.push_back(i);
    }
  });
  checkAdvection(cx, effect, forceEntries);

  if (const toml::node* node = top.take("output")) {
    if (const toml::table* table = node->as_table()) {
      readOutput(cx, *table, effect.output);
    } else {
      cx.error(cx.at(*node), "output", describe(*node) + " (expected an [output] table)");
    }
  }
  top.finish();
  return effect;
}

// Turns a document of version `from` into version from + 1 in place. Each change of the format
// adds a case (renamed keys, new required keys given the values that keep the old behaviour), so
// files of every earlier version keep loading.
void migrateOneVersion(toml::table& /*document*/, std::int64_t from) {
  switch (from) {
    default:
      throw std::logic_error("no migration from format_version " + std::to_string(from));
  }
}

// Reads format_version and brings an older document up to the current version. Returns false
// when the document is of a version this build cannot read (nothing else is worth reporting).
bool migrateToCurrent(Context& cx, toml::table& document) {
  const std::string expected = "format_version = " + std::to_string(kEffectFormatVersion);
  const toml::node* node = document.get("format_version");
  if (node == nullptr) {
    cx.error(cx.at(document), "format_version", "missing (expected " + expected + ")");
    return true;  // read it as the current version, to report everything else too
  }
  const auto version = node->value_exact<std::int64_t>();
  if (!version) {
    cx.error(cx.at(*node), "format_version", describe(*node) + " (expected " + expected + ")");
    return true;
  }
  if (*version < 1 || *version > kEffectFormatVersion) {
    const std::string known = kEffectFormatVersion == 1
                                  ? std::string("1")
                                  : "1 to " + std::to_string(kEffectFormatVersion);
    cx.error(cx.at(*node), "format_version",
             "version " + std::to_string(*version) + " is not one this build reads (expected " +
                 known + ")");
    return false;
  }
  cx.record("format_version", *node);
  for (std::int64_t from = *version; from < kEffectFormatVersion; ++from)
    migrateOneVersion(document, from);
  return true;
}

}  // namespace
}  // namespace detail

LoadResult parseEffect(std::string_view text, std::string_view fileName,
                       const std::vector<std::string>& overrides) {
  LoadResult result;
  result.fingerprint = effectFingerprint(text, overrides);
  const std::string file(fileName);
  toml::table document;
  try {
    document = toml::parse(text, std::string_view(file));
  } catch (const toml::parse_error& e) {
    const toml::source_position& begin = e.source().begin;
    result.diagnostics.push_back(Diagnostic{Severity::Error, file, static_cast<int>(begin.line),
                                            static_cast<int>(begin.column), "",
                                            std::string(e.description())});
    return result;
  }

  OverrideOrigins origins;
  detail::Context cx(file, origins);
  if (detail::migrateToCurrent(cx, document)) {
    const std::vector<Diagnostic> overrideErrors = applyOverrides(document, overrides, origins);
    cx.diagnostics().insert(cx.diagnostics().end(), overrideErrors.begin(), overrideErrors.end());
    EffectSettings effect = detail::readCurrentVersion(cx, document);
    if (!hasErrors(cx.diagnostics())) {
      effect.sources = std::move(cx.sources());
      result.effect = std::move(effect);
    }
  }
  result.diagnostics = std::move(cx.diagnostics());
  // Findings about overrides in command-line order, then the file's by position.
  std::map<std::string, std::size_t> rank;
  for (std::size_t i = 0; i < overrides.size(); ++i) rank.emplace(overrideLabel(overrides[i]), i);
  std::stable_sort(result.diagnostics.begin(), result.diagnostics.end(),
                   [&](const Diagnostic& a, const Diagnostic& b) {
                     const auto ra = rank.find(a.file), rb = rank.find(b.file);
                     return (ra == rank.end() ? overrides.size() : ra->second) <
                            (rb == rank.end() ? overrides.size() : rb->second);
                   });
  sortDiagnostics(result.diagnostics);
  return result;
}

LoadResult loadEffectFile(const std::filesystem::path& path,
                          const std::vector<std::string>& overrides) {
  const std::string file = path.string();
  std::error_code ec;
  std::string problem;
  if (!std::filesystem::exists(path, ec)) {
    problem = "no such file";
  } else if (std::filesystem::is_directory(path, ec)) {
    problem = "is a directory";
  }
  std::ifstream in;
  if (problem.empty()) {
    in.open(path, std::ios::binary);
    if (!in) problem = "cannot be opened";
  }
  if (!problem.empty()) {
    LoadResult result;
    result.diagnostics.push_back(Diagnostic{Severity::Error, file, 0, 0, "",
                                            problem + " (expected a readable effect file)"});
    return result;
  }
  std::ostringstream text;
  text << in.rdbuf();
  return parseEffect(text.str(), file, overrides);
}

}  // namespace tickfx::io
