#include "io/effect/EmitterKeys.h"

#include <algorithm>
#include <cstddef>

#include "io/effect/EffectSettings.h"
#include "io/effect/TableReader.h"

namespace tickfx::io::detail {

const std::vector<std::string>& fileEmitterKeys() {
  static const std::vector<std::string> keys = {
      "type",   "name",      "file",  "position",     "rate",   "start",    "stop",
      "bursts", "direction", "speed", "speed_jitter", "spread", "lifetime", "lifetime_jitter",
      "mass",   "attributes"};
  return keys;
}

const std::map<std::string, std::vector<std::string>>& shapeKeys() {
  static const std::map<std::string, std::vector<std::string>> keys = {
      {"point", {}},
      {"sphere", {"radius", "surface"}},
      {"box", {"size"}},
      {"disc", {"radius", "normal"}}};
  return keys;
}

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

const std::vector<std::string>& particleEmitterKeys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> k = {"type",
                                  "name",
                                  "position",
                                  "shape",
                                  "rate",
                                  "start",
                                  "stop",
                                  "bursts",
                                  "direction",
                                  "speed",
                                  "speed_jitter",
                                  "spread",
                                  "lifetime",
                                  "lifetime_jitter",
                                  "mass",
                                  "attributes",
                                  "parent",
                                  "on",
                                  "count",
                                  "count_range",
                                  "inherit_velocity",
                                  "inherit",
                                  "first_only"};
    for (const auto& [shape, own] : shapeKeys()) {
      for (const std::string& key : own) {
        if (std::find(k.begin(), k.end(), key) == k.end()) k.push_back(key);
      }
    }
    return k;
  }();
  return keys;
}

std::vector<std::string> structureOwnKeys(const std::string& type) {
  std::vector<std::string> keys = {"type"};
  keys.insert(keys.end(), structureCommonKeys().begin(), structureCommonKeys().end());
  const std::vector<std::string>& extra = structureKeys().at(type);
  keys.insert(keys.end(), extra.begin(), extra.end());
  return keys;
}

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

}  // namespace tickfx::io::detail
