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
constexpr std::size_t kMaxBursts = 100'000;  // per emitter
constexpr std::int64_t kMaxFrameRatePart = 1'000'000;

const std::vector<std::string> kShapes = {"point", "sphere", "box", "disc"};
const std::vector<std::string> kOverrunPolicies = {"drop", "fall_behind"};
const std::vector<std::string> kCacheFormats = [] {
  std::vector<std::string> names;
  for (const CacheFormat f : kCacheFormatList) names.emplace_back(cacheFormatName(f));
  return names;
}();

// The keys of a file emitter (type "file"): a particle emitter's, with `file` for the shape.
const std::vector<std::string>& fileEmitterKeys() {
  static const std::vector<std::string> keys = {
      "type",         "name",   "file",     "position",        "rate",
      "start",        "stop",   "bursts",   "direction",       "speed",
      "speed_jitter", "spread", "lifetime", "lifetime_jitter", "mass"};
  return keys;
}

// Parameters of each shape and each force type, to tell "does not apply here" from "unknown".
const std::map<std::string, std::vector<std::string>>& shapeKeys() {
  static const std::map<std::string, std::vector<std::string>> keys = {
      {"point", {}},
      {"sphere", {"radius", "surface"}},
      {"box", {"size"}},
      {"disc", {"radius", "normal"}}};
  return keys;
}

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

// Keys every structure type reads, then each type's own, in the order "expected for" lists
// them.
const std::vector<std::string>& structureCommonKeys() {
  static const std::vector<std::string> keys = {"name",    "time",        "mass",     "stiffness",
                                                "damping", "break_ratio", "velocity", "lifetime"};
  return keys;
}

const std::map<std::string, std::vector<std::string>>& structureKeys() {
  static const std::map<std::string, std::vector<std::string>> keys = {
      {"rope", {"start", "end", "count", "pin_start", "pin_end"}},
      {"cloth",
       {"origin", "axis_u", "axis_v", "width", "height", "spacing", "pins", "shear_scale",
        "bend_scale"}},
      {"cluster", {"center", "radius", "count", "link_radius"}}};
  return keys;
}

// The keys of a particle emitter (type "particles"), its shapes' parameters included.
const std::vector<std::string>& particleEmitterKeys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> k = {"type",         "name",   "position", "shape",           "rate",
                                  "start",        "stop",   "bursts",   "direction",       "speed",
                                  "speed_jitter", "spread", "lifetime", "lifetime_jitter", "mass"};
    for (const auto& [shape, own] : shapeKeys()) {
      for (const std::string& key : own) {
        if (std::find(k.begin(), k.end(), key) == k.end()) k.push_back(key);
      }
    }
    return k;
  }();
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

void readBursts(Context& cx, TableReader& r, EmitterSettings& e, std::int64_t maxParticles) {
  const toml::node* node = r.take("bursts");
  if (node == nullptr) return;
  const std::string path = r.pathOf("bursts");
  const std::string expected = "an array of bursts {time = seconds, count = particles}";
  const toml::array* array = node->as_array();
  if (array == nullptr) {
    cx.error(cx.at(*node), path, describe(*node) + " (expected " + expected + ")");
    return;
  }
  if (array->size() > kMaxBursts) {
    cx.error(cx.at(*node), path,
             std::to_string(array->size()) + " bursts are too many (expected at most 100000)");
    return;
  }
  cx.record(path, *node);
  const std::string countText =
      "particles, an integer from 1 to simulation.max_particles = " + std::to_string(maxParticles);
  for (std::size_t i = 0; i < array->size(); ++i) {
    const toml::node& entry = *array->get(i);
    const toml::table* table = entry.as_table();
    if (table == nullptr) {
      cx.error(cx.at(entry), childPath(path, i),
               describe(entry) + " (expected a burst {time = seconds, count = particles})");
      continue;
    }
    TableReader br(cx, *table, childPath(path, i));
    Burst burst;
    const bool timeOk = br.number("time", burst.time, kSecondsText, Range{0.0, kBig}, true);
    const bool countOk = br.integer("count", burst.count, countText, 1, maxParticles, true);
    br.finish();
    if (timeOk && countOk) e.bursts.push_back(burst);
  }
}

void readShape(TableReader& r, EmitterSettings& e) {
  std::string shape = "point";
  const bool known =
      r.choice("shape", shape, kShapes, "shape") || r.table().get("shape") == nullptr;
  if (!known) {
    // The shape could not be read: its parameters cannot be judged either.
    for (const auto& [name, keys] : shapeKeys()) r.allow(keys);
    return;
  }
  const std::string radiusText = "metres, a number from 0 to 1e9";
  if (shape == "sphere") {
    SphereShape s;
    r.number("radius", s.radius, radiusText, Range{0.0, kBig});
    r.boolean("surface", s.surface);
    e.shape = s;
  } else if (shape == "box") {
    BoxShape s;
    r.vec3("size", s.size, "[x, y, z] edge lengths in metres, each from 0 to 1e9",
           Range{0.0, kBig});
    e.shape = s;
  } else if (shape == "disc") {
    DiscShape s;
    r.number("radius", s.radius, radiusText, Range{0.0, kBig});
    r.vec3("normal", s.normal, kDirectionText, Range{-kBig, kBig}, /*nonZero=*/true);
    e.shape = s;
  } else {
    e.shape = PointShape{};
  }
}

std::map<std::string, std::string> notForShape(const std::string& shape) {
  const std::vector<std::string>& own = shapeKeys().at(shape);
  const std::string expected = own.empty()
                                   ? "(expected no parameters for a point)"
                                   : "(expected for a " + shape + ": " + joinWords(own) + ")";
  std::map<std::string, std::string> out;
  for (const auto& [other, keys] : shapeKeys()) {
    for (const std::string& k : keys) {
      if (std::find(own.begin(), own.end(), k) == own.end()) {
        out[k] = "does not apply to shape " + quote(shape) + " " + expected;
      }
    }
  }
  return out;
}

std::map<std::string, std::string> notForStructureKeys();

// The keys every particle emitter reads after its shape: when, how fast, how long, how heavy.
void readEmission(Context& cx, const toml::table& table, TableReader& r, std::int64_t maxParticles,
                  EmitterSettings& e) {
  r.number("rate", e.rate, "particles per second, a number from 0 to 1e9", Range{0.0, kBig});
  r.number("start", e.start, kSecondsText, Range{0.0, kBig});
  double stop = 0.0;
  if (r.number("stop", stop, "seconds, a number from start to 1e9", Range{0.0, kBig})) {
    if (stop < e.start) {
      cx.error(cx.at(*table.get("stop")), r.pathOf("stop"),
               formatNumber(stop) + " is before start = " + formatNumber(e.start) +
                   " (expected seconds, a number from start to 1e9)");
    } else {
      e.stop = stop;
    }
  }
  readBursts(cx, r, e, maxParticles);
  r.vec3("direction", e.direction, kDirectionText, Range{-kBig, kBig}, /*nonZero=*/true);
  r.number("speed", e.speed, "metres per second, a number from 0 to 1e9", Range{0.0, kBig});
  r.number("speed_jitter", e.speedJitter, "a fraction from 0 to 1", Range{0.0, 1.0});
  r.number("spread", e.spreadDegrees, "degrees, a number from 0 to 180", Range{0.0, 180.0});
  r.number("lifetime", e.lifetime, "seconds, a number > 0 and <= 1e9", Range{0.0, kBig, true});
  r.number("lifetime_jitter", e.lifetimeJitter, "a fraction >= 0 and < 1",
           Range{0.0, 1.0, false, true});
  r.number("mass", e.mass, "kilograms, a number > 0 and <= 1e9", Range{0.0, kBig, true});
}

void readEmitter(Context& cx, const toml::table& table, std::size_t index,
                 std::int64_t maxParticles, EmitterSettings& e) {
  TableReader r(cx, table, childPath("emitters", index));
  r.take("type");  // "particles" or absent: judged by readEmitterEntry
  e.name = "emitter_" + std::to_string(index);
  r.string("name", e.name, "a name: a non-empty string, unique among the emitters");
  r.vec3("position", e.position, kPositionText, Range{-kBig, kBig});
  readShape(r, e);
  readEmission(cx, table, r, maxParticles, e);

  std::string shape = "point";
  if (const toml::node* s = table.get("shape")) shape = s->value_or<std::string>("");
  std::map<std::string, std::string> notHere = notForStructureKeys();
  if (shapeKeys().count(shape) != 0) notHere.merge(notForShape(shape));
  r.finish(notHere);
}

// ---- file emitters: [[emitters]] of type "file" -------------------------------------------------

const std::string kPointFileText =
    "a points file relative to the effect file: .vdb (OpenVDB points, grid \"points\") or .csv "
    "(a tickfx CSV cache)";

// "[x, y, z]" with the shortest digits that read back to each float ("1e+30", not the double's
// "1.0000000150474662e+30").
std::string vectorText(const Eigen::Vector3f& v) {
  std::string out = "[";
  for (int c = 0; c < 3; ++c) {
    char digits[32];
    const auto end = std::to_chars(digits, digits + sizeof digits, v[c]).ptr;
    out += std::string(digits, end) + (c < 2 ? ", " : "]");
  }
  return out;
}

// Reads the points of the file `name` (the value of `node`, at `path`) into `out`: positions
// and, when the file has them, velocities. Reports what is wrong at the node.
bool readPointFile(Context& cx, const toml::node& node, const std::string& path,
                   const std::string& name, PointListShape& out) {
  const std::filesystem::path file = cx.directory() / name;
  const std::string shown = "\"" + file.string() + "\"";
  const auto fail = [&](const std::string& what, const std::string& expected = kPointFileText) {
    cx.error(cx.at(node), path, what + " (expected " + expected + ")");
    return false;
  };
  std::string extension = file.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension != ".vdb" && extension != ".csv") {
    return fail(shown + " is neither a .vdb nor a .csv file");
  }
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) return fail("no such file " + shown);
  if (std::filesystem::is_directory(file, ec)) return fail(shown + " is a directory");
  FrameData points;
  bool hasVelocity = true;  // a CSV cache always has vx, vy, vz
  try {
    if (extension == ".vdb") {
      VdbCacheContents contents;
      points = readVdbPointCache(file, &contents);
      hasVelocity = contents.hasVelocity;
    } else {
      points = readCsvCache(file);
    }
  } catch (const std::exception& e) {
    return fail(shown + " cannot be read: " + e.what());
  }
  if (points.size() == 0) return fail(shown + " holds no points", kPointFileText + ", not empty");
  out.positions.resize(points.size());
  out.velocities.resize(hasVelocity ? points.size() : 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto row = static_cast<Eigen::Index>(i);
    const Eigen::Vector3f x(points.position[0][row], points.position[1][row],
                            points.position[2][row]);
    const Eigen::Vector3f v(points.velocity[0][row], points.velocity[1][row],
                            points.velocity[2][row]);
    const std::string which = shown + ": the point of id " + std::to_string(points.id[i]);
    const std::string expected = "points and velocities with every coordinate from -1e9 to 1e9";
    if (!(x.array().abs() <= kBig).all()) return fail(which + " is at " + vectorText(x), expected);
    if (hasVelocity && !(v.array().abs() <= kBig).all()) {
      return fail(which + " has the velocity " + vectorText(v), expected);
    }
    out.positions[i] = x;
    if (hasVelocity) out.velocities[i] = v;
  }
  return true;
}

// Keys of particle emitters (shapes) and of structures, on a file emitter.
std::map<std::string, std::string> notForFileEmitter() {
  const std::vector<std::string>& own = fileEmitterKeys();
  const std::string message =
      "does not apply to an emitter of type \"file\" (expected for a file emitter: " +
      joinWords(own) + ")";
  std::map<std::string, std::string> out;
  const auto add = [&](const std::vector<std::string>& keys) {
    for (const std::string& k : keys) {
      if (std::find(own.begin(), own.end(), k) == own.end()) out[k] = message;
    }
  };
  add(particleEmitterKeys());
  add(structureCommonKeys());
  for (const auto& [type, keys] : structureKeys()) add(keys);
  return out;
}

// A particle emitter whose particles are born at the points of a file, in turn (PointListShape).
void readFileEmitter(Context& cx, const toml::table& table, std::size_t index,
                     std::int64_t maxParticles, EmitterSettings& e) {
  TableReader r(cx, table, childPath("emitters", index));
  r.take("type");
  e.name = "file_" + std::to_string(index);
  r.string("name", e.name, "a name: a non-empty string, unique among the emitters");
  std::string name;
  const bool named = r.string("file", name, kPointFileText);
  if (table.get("file") == nullptr) r.missing("file", kPointFileText);
  r.vec3("position", e.position, kPositionText, Range{-kBig, kBig});
  readEmission(cx, table, r, maxParticles, e);
  PointListShape points;
  if (named && readPointFile(cx, *table.get("file"), r.pathOf("file"), name, points)) {
    if (!points.velocities.empty()) {
      // The file says how each particle starts: the emitter's velocity keys would be ignored.
      const std::string shown = "\"" + (cx.directory() / name).string() + "\"";
      for (const char* key : {"direction", "speed", "speed_jitter", "spread"}) {
        if (const toml::node* node = table.get(key)) {
          cx.error(cx.at(*node), r.pathOf(key),
                   "does not apply: " + shown +
                       " gives every point its velocity (expected direction, speed, "
                       "speed_jitter and spread only with a .vdb file without v)");
        }
      }
    }
    const auto count = static_cast<std::int64_t>(points.positions.size());
    if (table.get("rate") == nullptr && table.get("bursts") == nullptr) {
      // Neither rate nor bursts: one burst of every point at `start`.
      if (count > maxParticles) {
        cx.error(cx.at(*table.get("file")), r.pathOf("file"),
                 std::to_string(count) + " points are more than simulation.max_particles = " +
                     std::to_string(maxParticles) +
                     " (expected at most max_particles points for the burst of every point, or "
                     "a rate or bursts)");
      }
      e.bursts = {Burst{e.start, static_cast<std::uint64_t>(count)}};
    }
    e.shape = std::move(points);
  }
  r.finish(notForFileEmitter());
}

// ---- structures: [[emitters]] of type "rope", "cloth" or "cluster" ----------------------------

// The bound on springs one structure may make (a cloth of 10⁶ particles has about 6·10⁶).
constexpr double kMaxSprings = 1e7;

// Keys a particle emitter does not have, with the structure types that do.
std::map<std::string, std::string> notForStructureKeys() {
  const std::vector<std::string>& own = particleEmitterKeys();
  std::map<std::string, std::vector<std::string>> owners;
  for (const std::string& type : emitterTypeNames()) {
    if (type == "particles") continue;
    std::vector<std::string> keys = type == "file" ? fileEmitterKeys() : structureCommonKeys();
    if (type != "file") {
      const std::vector<std::string>& extra = structureKeys().at(type);
      keys.insert(keys.end(), extra.begin(), extra.end());
    }
    for (const std::string& k : keys) {
      if (std::find(own.begin(), own.end(), k) == own.end()) owners[k].push_back(type);
    }
  }
  std::map<std::string, std::string> out;
  for (const auto& [key, types] : owners) {
    std::string list;
    for (std::size_t i = 0; i < types.size(); ++i) {
      list += (i == 0 ? "" : (i + 1 == types.size() ? " or " : ", ")) + quote(types[i]);
    }
    out[key] = "does not apply to an emitter of type \"particles\" (expected type = " + list +
               " for " + key + ")";
  }
  return out;
}

// The keys of structure type `type`, "type" first.
std::vector<std::string> structureOwnKeys(const std::string& type) {
  std::vector<std::string> keys = {"type"};
  keys.insert(keys.end(), structureCommonKeys().begin(), structureCommonKeys().end());
  const std::vector<std::string>& extra = structureKeys().at(type);
  keys.insert(keys.end(), extra.begin(), extra.end());
  return keys;
}

// Keys of particle emitters and of the other structure types, on a structure of `type`.
std::map<std::string, std::string> notForStructure(const std::string& type) {
  const std::vector<std::string> own = structureOwnKeys(type);
  const std::string message = "does not apply to an emitter of type " + quote(type) +
                              " (expected for a " + type + ": " + joinWords(own) + ")";
  std::map<std::string, std::string> out;
  const auto add = [&](const std::vector<std::string>& keys) {
    for (const std::string& k : keys) {
      if (std::find(own.begin(), own.end(), k) == own.end()) out[k] = message;
    }
  };
  add(particleEmitterKeys());
  add(fileEmitterKeys());
  for (const auto& [other, keys] : structureKeys()) add(keys);
  return out;
}

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

// One [[emitters]] entry: a particle emitter or, by its `type`, a structure.
void readEmitterEntry(Context& cx, const toml::table& table, std::size_t index,
                      std::int64_t maxParticles, EffectSettings& effect,
                      std::map<std::string, std::size_t>& names) {
  const std::size_t errorsBefore = cx.diagnostics().size();
  const std::string path = childPath("emitters", index);
  std::string type = "particles";
  if (const toml::node* node = table.get("type")) {
    const std::optional<std::string> known =
        checkChoice(cx, *node, childPath(childPath("emitters", index), "type"), emitterTypeNames(),
                    "emitter type");
    if (!known) {
      // Without a type no key can be judged but the unknown ones.
      TableReader r(cx, table, childPath("emitters", index));
      for (const std::string& k : particleEmitterKeys()) r.take(k);
      for (const std::string& t : emitterTypeNames()) {
        if (t == "file") r.allow(fileEmitterKeys());
        if (t != "particles" && t != "file") r.allow(structureOwnKeys(t));
      }
      r.finish();
      return;
    }
    type = *known;
  }
  std::string name;
  if (type == "particles" || type == "file") {
    EmitterSettings e;
    if (type == "file") {
      readFileEmitter(cx, table, index, maxParticles, e);
    } else {
      readEmitter(cx, table, index, maxParticles, e);
    }
    if (cx.diagnostics().size() == errorsBefore) reportProblems(cx, path, e.validate());
    name = e.name;
    effect.emitters.push_back(std::move(e));
  } else {
    StructureSettings s;
    readStructure(cx, table, index, type, maxParticles, s);
    if (cx.diagnostics().size() == errorsBefore) reportProblems(cx, path, s.validate());
    name = s.name;
    effect.structures.push_back(std::move(s));
    effect.structureEntries.push_back(index);
  }
  if (const auto [it, fresh] = names.emplace(name, index); !fresh) {
    const toml::node* nameNode = table.get("name");
    cx.error(nameNode ? cx.at(*nameNode) : cx.at(table),
             childPath(childPath("emitters", index), "name"),
             quote(name) + " is already the name of emitters." + std::to_string(it->second) +
                 " (expected a name unique among the emitters)");
  }
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
