#include "io/effect/ParseForces.h"

#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include "io/effect/ParseVectorFields.h"

namespace tickfx::io::detail {
namespace {

// Force type → its parameters, to tell "does not apply here" from "unknown".
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

}  // namespace

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

}  // namespace tickfx::io::detail
