#include "io/effect/ParseEmitters.h"

#include <algorithm>
#include <optional>
#include <utility>
#include <vector>

#include "io/effect/EmitterKeys.h"
#include "io/effect/ParseFileEmitters.h"
#include "io/effect/ParseStructures.h"
#include "io/effect/ParseSubEmitters.h"

namespace tickfx::io::detail {
namespace {

constexpr std::size_t kMaxBursts = 100'000;  // per emitter

const std::vector<std::string> kShapes = {"point", "sphere", "box", "disc"};

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

void readEmitter(Context& cx, const toml::table& table, std::size_t index,
                 std::int64_t maxParticles, EmitterSettings& e) {
  TableReader r(cx, table, childPath("emitters", index));
  r.take("type");  // "particles" or absent: judged by readEmitterEntry
  e.name = "emitter_" + std::to_string(index);
  r.string("name", e.name, "a name: a non-empty string, unique among the emitters");
  r.vec3("position", e.position, kPositionText, Range{-kBig, kBig});
  readShape(r, e);
  readSubEmitter(cx, r, e);
  readEmission(cx, table, r, maxParticles, e);

  std::string shape = "point";
  if (const toml::node* s = table.get("shape")) shape = s->value_or<std::string>("");
  std::map<std::string, std::string> notHere = notForStructureKeys();
  if (shapeKeys().count(shape) != 0) notHere.merge(notForShape(shape));
  r.finish(notHere);
}

}  // namespace

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
  if (!readNormalDirection(cx, r, e))
    r.vec3("direction", e.direction, kDirectionText, Range{-kBig, kBig}, /*nonZero=*/true);
  r.number("speed", e.speed, "metres per second, a number from 0 to 1e9", Range{0.0, kBig});
  r.number("speed_jitter", e.speedJitter, "a fraction from 0 to 1", Range{0.0, 1.0});
  r.number("spread", e.spreadDegrees, "degrees, a number from 0 to 180", Range{0.0, 180.0});
  r.number("lifetime", e.lifetime, "seconds, a number > 0 and <= 1e9", Range{0.0, kBig, true});
  r.number("lifetime_jitter", e.lifetimeJitter, "a fraction >= 0 and < 1",
           Range{0.0, 1.0, false, true});
  r.number("mass", e.mass, "kilograms, a number > 0 and <= 1e9", Range{0.0, kBig, true});
  readLifeAttributes(cx, r, e);
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

}  // namespace tickfx::io::detail
