#include "io/effect/ParseColliders.h"

#include <algorithm>
#include <map>
#include <string>
#include <vector>

namespace tickfx::io::detail {
namespace {

const std::vector<std::string> kColliderTypes = {"plane", "sphere", "box", "level_set"};
const std::vector<std::string> kColliderCommonKeys = {"side",     "response",        "restitution",
                                                      "friction", "velocity",        "spin",
                                                      "keys",     "particle_radius", "hits"};

// Collider type → the keys of its shape, to tell "does not apply here" from "unknown". `radius`
// is the particles' collision radius for a plane or a box and the sphere's own radius for a
// sphere (whose particles' radius is `particle_radius`, a name every type accepts).
const std::map<std::string, std::vector<std::string>>& colliderShapeKeys() {
  static const std::map<std::string, std::vector<std::string>> keys = {
      {"plane", {"point", "normal", "radius"}},
      {"sphere", {"center", "radius"}},
      {"box", {"center", "size", "rotation", "radius"}},
      {"level_set", {"file", "grid", "mesh", "voxel_size", "bake", "radius"}}};
  return keys;
}

const char kColliderLengthText[] = "metres, a number from 0 to 1e9";

void readParticleRadius(Context& cx, TableReader& r, const std::string& type, ColliderSettings& c) {
  if (type != "sphere" && r.table().get("radius") != nullptr) {
    if (const toml::node* both = r.take("particle_radius")) {
      r.take("radius");
      cx.error(cx.at(*both), r.pathOf("particle_radius"),
               "is given with radius, its other name (expected one of them)");
      return;
    }
    r.number("radius", c.particleRadius, kColliderLengthText, Range{0.0, kBig});
    return;
  }
  r.number("particle_radius", c.particleRadius, kColliderLengthText, Range{0.0, kBig});
}

void readColliderSpin(Context& cx, TableReader& r, ColliderMotionSettings& m) {
  const toml::node* node = r.take("spin");
  if (node == nullptr) return;
  const toml::table* table = node->as_table();
  if (table == nullptr) {
    cx.error(cx.at(*node), r.pathOf("spin"),
             describe(*node) + " (expected a table { axis = [x, y, z], center = [x, y, z], " +
                 "rate = rad/s })");
    return;
  }
  TableReader s(cx, *table, r.pathOf("spin"));
  s.vec3("axis", m.spinAxis, kDirectionText, Range{}, /*nonZero=*/true);
  s.vec3("center", m.spinCenter, kPositionText, Range{});
  s.number("rate", m.spinRate, "rad/s, a number from -1e9 to 1e9", Range{}, /*required=*/true);
  s.finish();
}

void readColliderKeys(Context& cx, TableReader& r, ColliderMotionSettings& m) {
  const toml::node* node = r.take("keys");
  if (node == nullptr) return;
  const std::string path = r.pathOf("keys");
  const toml::array* array = node->as_array();
  const std::string expected = "an array of { time = seconds, translate = [x, y, z] } tables";
  if (array == nullptr || array->empty() || array->size() > 10'000) {
    cx.error(cx.at(*node), path,
             (array == nullptr ? describe(*node) : std::to_string(array->size()) + " keys") +
                 " (expected " + expected + ", 1 to 10000 of them)");
    return;
  }
  cx.record(path, *node);
  for (std::size_t i = 0; i < array->size(); ++i) {
    const toml::table* key = array->get(i)->as_table();
    if (key == nullptr) {
      cx.error(cx.at(*array->get(i)), childPath(path, i),
               describe(*array->get(i)) + " (expected a { time, translate } table)");
      continue;
    }
    TableReader k(cx, *key, childPath(path, i));
    ColliderKey ck;
    k.number("time", ck.time, kSecondsText, Range{0.0, kBig}, /*required=*/true);
    k.vec3("translate", ck.translate, kPositionText, Range{});
    k.finish();
    m.keys.push_back(ck);
  }
}

const char kVoxelText[] = "metres, a number > 0 and <= 1e9";

void readBake(Context& cx, TableReader& r, LevelSetSettings& l) {
  const toml::node* node = r.take("bake");
  const toml::table* table = node->as_table();
  if (table == nullptr) {
    cx.error(cx.at(*node), r.pathOf("bake"),
             describe(*node) + " (expected a table { shape = \"sphere\", \"box\" or \"torus\", " +
                 "..., voxel_size })");
    return;
  }
  l.source = LevelSetSettings::Source::Bake;
  TableReader b(cx, *table, r.pathOf("bake"));
  std::string shape;
  const Range any{}, positive{0.0, kBig, true};
  const std::map<std::string, std::vector<std::string>> keys = {
      {"sphere", {"radius"}}, {"box", {"size"}}, {"torus", {"major_radius", "minor_radius"}}};
  if (!b.choice("shape", shape, {"sphere", "box", "torus"}, "baked shape", /*required=*/true)) {
    for (const auto& [name, k] : keys) b.allow(k);
    b.allow({"center", "voxel_size"});
    b.finish();
    return;
  }
  b.vec3("center", l.center, kPositionText, any);
  b.number("voxel_size", l.voxelSize, kVoxelText, positive, /*required=*/true);
  if (shape == "sphere") {
    l.shape = LevelSetSettings::Shape::Sphere;
    b.number("radius", l.radius, "metres, a number > 0 and <= 1e9", positive, true);
  } else if (shape == "box") {
    l.shape = LevelSetSettings::Shape::Box;
    b.vec3("size", l.size, "[x, y, z] edge lengths in metres, each > 0 and <= 1e9", positive);
  } else {
    l.shape = LevelSetSettings::Shape::Torus;
    b.number("major_radius", l.majorRadius, "metres, a number > 0 and <= 1e9", positive, true);
    b.number("minor_radius", l.minorRadius, "metres, a number > 0 and <= 1e9", positive, true);
  }
  std::map<std::string, std::string> notHere;
  for (const auto& [name, k] : keys) {
    if (name == shape) continue;
    for (const std::string& key : k) {
      notHere[key] = "does not apply to a baked " + shape + " (expected for a " + shape +
                     ": shape, center, voxel_size, " + joinWords(keys.at(shape)) + ")";
    }
  }
  b.finish(notHere);
}

// Exactly one of `file`, `mesh` and `bake`.
void readLevelSet(Context& cx, TableReader& r, LevelSetSettings& l) {
  const char* names[] = {"file", "mesh", "bake"};
  std::vector<std::string> given;
  for (const char* n : names) {
    if (r.table().get(n) != nullptr) given.emplace_back(n);
  }
  if (given.size() != 1) {
    if (given.empty()) {
      r.missing("file", "one of file (a .vdb level set), mesh (an OBJ or PLY file) or bake");
    } else {
      const toml::node* second = r.table().get(given[1]);
      cx.error(cx.at(*second), r.pathOf(given[1]),
               "is given with " + given[0] + " (expected one of file, mesh and bake)");
    }
    r.allow({"file", "mesh", "bake", "grid", "voxel_size"});
    return;
  }
  const std::string fileText = "a path relative to the effect file's directory, a non-empty string";
  if (given[0] == "bake") {
    readBake(cx, r, l);
  } else if (given[0] == "file") {
    l.source = LevelSetSettings::Source::File;
    if (r.string("file", l.file, "a .vdb " + fileText)) {
      l.path = (cx.directory() / l.file).string();
    }
    r.string("grid", l.grid, "the float grid's name, a non-empty string");
  } else {
    l.source = LevelSetSettings::Source::Mesh;
    if (r.string("mesh", l.mesh, "an OBJ or PLY " + fileText)) {
      l.path = (cx.directory() / l.mesh).string();
    }
    r.number("voxel_size", l.voxelSize, kVoxelText, Range{0.0, kBig, true}, /*required=*/true);
  }
  const std::map<std::string, std::string> onlyWith = {{"grid", "file"}, {"voxel_size", "mesh"}};
  for (const auto& [key, owner] : onlyWith) {
    if (owner == given[0]) continue;
    if (const toml::node* n = r.take(key)) {
      cx.error(cx.at(*n), r.pathOf(key),
               "applies to a level set from " + owner + " only (expected " +
                   (given[0] == "bake" ? "voxel_size inside the bake table" : "no " + key) + ")");
    }
  }
}

void readColliderShape(Context& cx, TableReader& r, const std::string& type, ColliderSettings& c) {
  const Range any{};
  if (type == "plane") {
    c.type = ColliderType::Plane;
    r.vec3("point", c.point, kPositionText, any);
    r.vec3("normal", c.normal, kDirectionText, any, /*nonZero=*/true);
  } else if (type == "sphere") {
    c.type = ColliderType::Sphere;
    r.vec3("center", c.center, kPositionText, any);
    r.number("radius", c.radius, "metres, a number > 0 and <= 1e9", Range{0.0, kBig, true},
             /*required=*/true);
  } else if (type == "level_set") {
    c.type = ColliderType::LevelSet;
    readLevelSet(cx, r, c.levelSet);
  } else {
    c.type = ColliderType::Box;
    r.vec3("center", c.center, kPositionText, any);
    r.vec3("size", c.size, "[x, y, z] edge lengths in metres, each > 0 and <= 1e9",
           Range{0.0, kBig, true}, false);
    r.vec3("rotation", c.rotation,
           "[x, y, z] in degrees, applied x then y then z, each from "
           "-1e9 to 1e9",
           any);
  }
}

}  // namespace

std::optional<ColliderSettings> readCollider(Context& cx, const toml::table& table,
                                             std::size_t index) {
  const std::string path = childPath("colliders", index);
  TableReader r(cx, table, path);
  const std::size_t errorsBefore = cx.diagnostics().size();
  std::string type;
  if (!r.choice("type", type, kColliderTypes, "collider type", /*required=*/true)) {
    for (const auto& [name, keys] : colliderShapeKeys()) r.allow(keys);
    r.allow(kColliderCommonKeys);
    r.finish();
    return std::nullopt;
  }
  ColliderSettings c;
  readColliderShape(cx, r, type, c);
  readParticleRadius(cx, r, type, c);
  std::string word;
  if (r.choice("side", word, {"outside", "inside"}, "collider side")) {
    c.side = word == "inside" ? ColliderSide::Inside : ColliderSide::Outside;
  }
  if (r.choice("response", word, {"bounce", "slide", "stick", "kill"}, "collision response")) {
    c.response = word == "slide"   ? ColliderResponse::Slide
                 : word == "stick" ? ColliderResponse::Stick
                 : word == "kill"  ? ColliderResponse::Kill
                                   : ColliderResponse::Bounce;
  }
  r.number("restitution", c.restitution, "a number from 0 to 1", Range{0.0, 1.0});
  r.number("friction", c.friction, "Coulomb's coefficient, a number from 0 to 1e9",
           Range{0.0, kBig});
  r.vec3("velocity", c.motion.velocity, "[x, y, z] in m/s, each from -1e9 to 1e9", Range{});
  r.boolean("hits", c.recordHits);
  readColliderSpin(cx, r, c.motion);
  readColliderKeys(cx, r, c.motion);

  const std::vector<std::string>& own = colliderShapeKeys().at(type);
  std::map<std::string, std::string> notHere;
  for (const auto& [other, keys] : colliderShapeKeys()) {
    for (const std::string& k : keys) {
      if (std::find(own.begin(), own.end(), k) == own.end()) {
        notHere[k] = "does not apply to a collider of type " + quote(type) + " (expected for " +
                     type + ": type, " + joinWords(own) + ", " + joinWords(kColliderCommonKeys) +
                     ")";
      }
    }
  }
  r.finish(notHere);
  if (cx.diagnostics().size() == errorsBefore) reportProblems(cx, path, c.validate());
  return c;
}

}  // namespace tickfx::io::detail
