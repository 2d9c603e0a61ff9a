#include "io/effect/ParseSubEmitters.h"

#include <algorithm>

#include "fields/ColliderSet.h"
#include "io/effect/EditDistance.h"
#include "particles/EventEmission.h"

namespace tickfx::io::detail {
namespace {

constexpr std::int64_t kMaxChildren = 1'000'000;

const std::vector<std::string> kEvents = {"birth", "death", "collision"};
const std::vector<std::string> kInterpolations = {"linear", "smooth", "constant"};

// A number, or for Cd an [r, g, b] array, into `out`.
bool readValue(Context& cx, const toml::node& node, const std::string& path, bool colour,
               std::array<float, 3>& out) {
  if (!colour) {
    const std::optional<double> v = checkNumber(cx, node, path, "a number", Range{-kBig, kBig});
    if (v) out = {static_cast<float>(*v), 0.0f, 0.0f};
    return v.has_value();
  }
  const toml::array* a = node.as_array();
  if (a == nullptr || a->size() != 3) {
    cx.error(cx.at(node), path, describe(node) + " (expected a colour [r, g, b], linear RGB)");
    return false;
  }
  for (std::size_t c = 0; c < 3; ++c) {
    const std::optional<double> v =
        checkNumber(cx, *a->get(c), childPath(path, c), "a number", Range{-kBig, kBig});
    if (!v) return false;
    out[c] = static_cast<float>(*v);
  }
  cx.record(path, node);
  return true;
}

bool readRamp(Context& cx, const toml::node& node, const std::string& path, bool colour,
              std::vector<RampKey>& keys) {
  const toml::array* a = node.as_array();
  const std::string expected = "an array of keys [nage, value], nage from 0 to 1";
  if (a == nullptr || a->empty()) {
    cx.error(cx.at(node), path, describe(node) + " (expected " + expected + ")");
    return false;
  }
  cx.record(path, node);
  for (std::size_t i = 0; i < a->size(); ++i) {
    const toml::node& entry = *a->get(i);
    const std::string at = childPath(path, i);
    const toml::array* pair = entry.as_array();
    if (pair == nullptr || pair->size() != 2) {
      cx.error(cx.at(entry), at, describe(entry) + " (expected a key [nage, value])");
      return false;
    }
    RampKey key;
    const std::optional<double> nage = checkNumber(cx, *pair->get(0), childPath(at, std::size_t{0}),
                                                   "nage, a number", Range{-kBig, kBig});
    if (!nage || !readValue(cx, *pair->get(1), childPath(at, std::size_t{1}), colour, key.value)) {
      return false;
    }
    key.nage = static_cast<float>(*nage);
    cx.record(at, entry);
    keys.push_back(key);
  }
  return true;
}

void readAttribute(Context& cx, const std::string& name, const toml::node& node,
                   const std::string& path, EmitterSettings& e) {
  LifeAttributeSettings a;
  a.name = name;
  const bool colour = name == "Cd";
  const toml::table* table = node.as_table();
  if (table == nullptr) {
    if (readValue(cx, node, path, colour, a.value)) e.attributes.push_back(std::move(a));
    return;
  }
  TableReader r(cx, *table, path);
  const toml::node* value = r.take("value");
  const toml::node* random = r.take("random");
  const toml::node* ramp = r.take("ramp");
  const int given = (value != nullptr) + (random != nullptr) + (ramp != nullptr);
  bool ok = true;
  if (given != 1) {
    cx.error(cx.at(*table), path,
             (given == 0 ? std::string("has no value")
                         : std::string("has more than one of value, random and ramp")) +
                 " (expected one of value = v, random = [low, high], ramp = [[nage, v], ...])");
    ok = false;
  } else if (value != nullptr) {
    ok = readValue(cx, *value, r.pathOf("value"), colour, a.value);
  } else if (random != nullptr) {
    a.kind = LifeAttributeSettings::Kind::Random;
    const toml::array* pair = random->as_array();
    if (pair == nullptr || pair->size() != 2) {
      cx.error(cx.at(*random), r.pathOf("random"),
               describe(*random) + " (expected [low, high]: a value drawn per particle between)");
      ok = false;
    } else {
      cx.record(r.pathOf("random"), *random);
      ok = readValue(cx, *pair->get(0), childPath(r.pathOf("random"), std::size_t{0}), colour,
                     a.value) &&
           readValue(cx, *pair->get(1), childPath(r.pathOf("random"), std::size_t{1}), colour,
                     a.high);
    }
  } else {
    a.kind = LifeAttributeSettings::Kind::Ramp;
    ok = readRamp(cx, *ramp, r.pathOf("ramp"), colour, a.keys);
  }
  std::string interpolation = "linear";
  if (r.choice("interpolation", interpolation, kInterpolations, "interpolation")) {
    if (ramp == nullptr) {
      cx.error(cx.at(*table->get("interpolation")), r.pathOf("interpolation"),
               "applies to a ramp only (expected ramp = [[nage, value], ...] with it)");
      ok = false;
    }
    a.interpolation = interpolation == "smooth"     ? RampInterpolation::Smooth
                      : interpolation == "constant" ? RampInterpolation::Constant
                                                    : RampInterpolation::Linear;
  }
  r.finish();
  if (ok) e.attributes.push_back(std::move(a));
}

}  // namespace

const std::vector<std::string>& subEmitterKeys() {
  static const std::vector<std::string> keys = {
      "parent", "on", "count", "count_range", "inherit_velocity", "inherit", "first_only"};
  return keys;
}

void readSubEmitter(Context& cx, TableReader& r, EmitterSettings& e) {
  SubEmitterSettings& sub = e.sub;
  r.string("parent", sub.parent, "the name of the emitter whose particles' events emit here");
  if (sub.parent.empty()) {
    // At the key, as any key that does not apply to the entry is shown.
    for (const auto& [key, value] : r.table()) {
      const std::string name(key.str());
      if (name == "parent" || std::find(subEmitterKeys().begin(), subEmitterKeys().end(), name) ==
                                  subEmitterKeys().end()) {
        continue;
      }
      r.take(name);
      cx.error(cx.atKey(key, value), r.pathOf(name),
               name == "count"
                   ? "applies to a sub-emitter or a structure (expected parent = "
                     "\"NAME\" with it, or type = \"rope\" or \"cluster\")"
                   : "applies to a sub-emitter only (expected parent = \"NAME\" with it)");
    }
    return;
  }
  std::string on;
  if (r.choice("on", on, kEvents, "event", /*required=*/true)) {
    sub.on = on == "birth"   ? EmitterEvent::Birth
             : on == "death" ? EmitterEvent::Death
                             : EmitterEvent::Collision;
  }
  const std::string countText = "children per event, an integer from 0 to 1000000";
  std::uint64_t count = 1;
  const bool hasCount = r.integer("count", count, countText, 0, kMaxChildren);
  if (hasCount) sub.countMin = sub.countMax = count;
  if (const toml::node* node = r.take("count_range")) {
    const std::string path = r.pathOf("count_range");
    const toml::array* a = node->as_array();
    if (hasCount || r.table().get("count") != nullptr) {
      cx.error(cx.at(*node), path, "is given with count (expected one of count and count_range)");
    } else if (a == nullptr || a->size() != 2) {
      cx.error(cx.at(*node), path,
               describe(*node) + " (expected [a, b]: children drawn per event from a to b)");
    } else {
      const auto low =
          checkInteger(cx, *a->get(0), childPath(path, std::size_t{0}), countText, 0, kMaxChildren);
      const auto high =
          checkInteger(cx, *a->get(1), childPath(path, std::size_t{1}), countText, 0, kMaxChildren);
      if (low && high) {
        cx.record(path, *node);
        sub.countMin = static_cast<std::uint64_t>(*low);
        sub.countMax = static_cast<std::uint64_t>(*high);
      }
    }
  }
  r.number("inherit_velocity", sub.inheritVelocity, "a fraction from 0 to 1", Range{0.0, 1.0});
  if (const toml::node* node = r.take("inherit")) {
    const std::string path = r.pathOf("inherit");
    const toml::array* a = node->as_array();
    if (a == nullptr) {
      cx.error(cx.at(*node), path,
               describe(*node) + " (expected an array of attribute names, such as [\"Cd\"])");
    } else {
      cx.record(path, *node);
      for (std::size_t i = 0; i < a->size(); ++i) {
        const toml::node& n = *a->get(i);
        const std::optional<std::string> name = n.value<std::string>();
        if (!name || name->empty()) {
          cx.error(cx.at(n), childPath(path, i), describe(n) + " (expected an attribute name)");
          continue;
        }
        cx.record(childPath(path, i), n);
        sub.inherit.push_back(*name);
      }
    }
  }
  r.boolean("first_only", sub.firstOnly);
}

bool readNormalDirection(Context& cx, TableReader& r, EmitterSettings& e) {
  const toml::node* node = r.table().get("direction");
  if (node == nullptr || !node->is_string()) return false;
  r.take("direction");
  if (node->value_or<std::string>("") != "normal") {
    cx.error(cx.at(*node), r.pathOf("direction"),
             describe(*node) + " (expected a direction [x, y, z], or \"normal\" on a collision)");
    return true;
  }
  cx.record(r.pathOf("direction"), *node);
  e.sub.alongNormal = true;
  return true;
}

void readLifeAttributes(Context& cx, TableReader& r, EmitterSettings& e) {
  const toml::node* node = r.take("attributes");
  if (node == nullptr) return;
  const std::string path = r.pathOf("attributes");
  const toml::table* table = node->as_table();
  if (table == nullptr) {
    cx.error(cx.at(*node), path,
             describe(*node) + " (expected a table of attributes, such as {Alpha = 0.5})");
    return;
  }
  cx.record(path, *node);
  for (const auto& [key, value] : *table) {
    const std::string name(key.str());
    readAttribute(cx, name, value, childPath(path, name), e);
  }
}

void checkSubEmitters(Context& cx, const EffectSettings& effect) {
  std::vector<std::string> emitters;
  for (const EmitterSettings& e : effect.emitters) emitters.push_back(e.name);
  std::vector<std::string> columns;
  bool hits = effect.output.hits;
  for (const ColliderSettings& c : effect.colliders) hits |= c.recordHits;
  if (hits) columns.assign(kHitColumns.begin(), kHitColumns.end());
  for (const EmitterSettings& e : effect.emitters) {
    if (e.sub.on == EmitterEvent::Collision) columns.push_back(kContactsColumn);
  }
  // The core's check, placed at the entries' keys; a parent that names no emitter is told apart
  // here from one that names a structure, and gets a suggestion.
  for (const SettingProblem& p : validateSubEmitters(effect.emitters, columns)) {
    const std::size_t dot = p.key.find('.');
    const std::size_t emitter = std::stoul(p.key.substr(0, dot));
    const std::string key = p.key.substr(dot + 1);
    const std::string path = childPath(emitterKeyPath(effect, emitter), key);
    std::string text = p.message + " (expected " + p.expected + ")";
    const std::string& parent = effect.emitters[emitter].sub.parent;
    if (key == "parent" && std::find(emitters.begin(), emitters.end(), parent) == emitters.end()) {
      const bool structure =
          std::any_of(effect.structures.begin(), effect.structures.end(),
                      [&](const StructureSettings& st) { return st.name == parent; });
      const std::optional<std::string> guess = closestMatch(parent, emitters);
      text = structure ? quote(parent) +
                             " is a structure (expected a particle emitter: "
                             "structures have no events)"
             : guess
                 ? p.message + "; did you mean " + quote(*guess) + "? (expected " + p.expected + ")"
                 : text;
    }
    cx.error(cx.sources().find(path), path, text);
  }
}

}  // namespace tickfx::io::detail
