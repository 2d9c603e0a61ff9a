#include "particles/LifeAttribute.h"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace tickfx {
namespace {

// A float as messages show it: the shortest digits that read back to the float ("0.1", not the
// double "0.10000000149011612").
std::string floatText(float v) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, v).ptr;
  return std::string(text, end);
}

}  // namespace

std::array<std::string, 3> vectorColumnNames(const std::string& name) {
  if (name == "Cd") return {"Cd_r", "Cd_g", "Cd_b"};
  return {name + "_x", name + "_y", name + "_z"};
}

std::vector<std::string> LifeAttributeSettings::columnNamesOf(const std::string& name) {
  if (name != "Cd") return {name};
  const std::array<std::string, 3> c = vectorColumnNames(name);
  return {c.begin(), c.end()};
}

float LifeAttributeSettings::defaultValue(const std::string& column) {
  if (column == "Cd_r" || column == "Cd_g" || column == "Cd_b" || column == "Alpha" ||
      column == "pscale") {
    return 1.0f;
  }
  return 0.0f;
}

SettingProblems LifeAttributeSettings::validate() const {
  SettingProblems out;
  const bool colour = name == "Cd";
  const float lo = 0.0f;
  const float hi = name == "Alpha" ? 1.0f : INFINITY;
  const bool bounded = colour || name == "Alpha" || name == "pscale";
  const std::string expected = colour             ? "a linear RGB colour, each channel >= 0"
                               : name == "Alpha"  ? "an opacity from 0 to 1"
                               : name == "pscale" ? "a radius in metres, >= 0"
                                                  : "a finite number";
  const auto checkValue = [&](const std::array<float, 3>& v, const std::string& key) {
    for (int c = 0; c < components(); ++c) {
      const float x = v[static_cast<std::size_t>(c)];
      if (!std::isfinite(x) || (bounded && (x < lo || x > hi))) {
        out.push_back({key, floatText(x) + " is out of range", expected});
        return;
      }
    }
  };
  if (name.empty()) out.push_back({"name", "is empty", "an attribute name"});
  switch (kind) {
    case Kind::Constant:
      checkValue(value, "value");
      break;
    case Kind::Random:
      checkValue(value, "random");
      checkValue(high, "random");
      break;
    case Kind::Ramp:
      if (keys.empty()) out.push_back({"ramp", "is empty", "at least one [nage, value] key"});
      for (std::size_t i = 0; i < keys.size(); ++i) {
        const std::string key = "ramp." + std::to_string(i);
        const float n = keys[i].nage;
        if (!(n >= 0.0f && n <= 1.0f)) {
          out.push_back({key, "nage " + floatText(n) + " is out of range",
                         "nage (age / lifetime) from 0 to 1"});
        } else if (i > 0 && !(n > keys[i - 1].nage)) {
          out.push_back({key,
                         "nage " + floatText(n) + " is not after the previous key's " +
                             floatText(keys[i - 1].nage),
                         "keys in rising order of nage"});
        }
        checkValue(keys[i].value, key);
      }
      break;
  }
  return out;
}

}  // namespace tickfx
