#include "app/preview/ColourBy.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "app/preview/ColourMap.h"

namespace tickfx::preview {
namespace {

constexpr const char* kCdChannels[] = {"Cd_r", "Cd_g", "Cd_b"};

std::ptrdiff_t attributeIndex(const io::FrameData& frame, const std::string& name) {
  const auto it = std::find(frame.attributeNames.begin(), frame.attributeNames.end(), name);
  return it == frame.attributeNames.end() ? -1 : it - frame.attributeNames.begin();
}

bool hasCd(const io::FrameData& frame) {
  return std::all_of(std::begin(kCdChannels), std::end(kCdChannels),
                     [&](const char* c) { return attributeIndex(frame, c) >= 0; });
}

double row(const FloatColumn& column, std::size_t i) {
  return column[static_cast<Eigen::Index>(i)];
}

}  // namespace

std::vector<std::string> ColourBy::choices(const io::FrameData& frame) {
  std::vector<std::string> names = {"speed", "age", "nage", "id", "life", "mass"};
  names.insert(names.end(), frame.attributeNames.begin(), frame.attributeNames.end());
  if (hasCd(frame)) names.emplace_back("Cd");
  return names;
}

ColourBy ColourBy::parse(const std::string& name, const io::FrameData& frame) {
  const struct {
    const char* name;
    Kind kind;
  } fixed[] = {{"speed", Kind::Speed}, {"age", Kind::Age},   {"nage", Kind::NormalisedAge},
               {"id", Kind::Id},       {"life", Kind::Life}, {"mass", Kind::Mass}};
  for (const auto& f : fixed) {
    if (name == f.name) return {f.kind, ""};
  }
  if (name == "Cd" && hasCd(frame)) return {Kind::Cd, ""};
  if (attributeIndex(frame, name) >= 0) return {Kind::Attribute, name};
  const std::vector<std::string> names = choices(frame);
  std::string list;
  for (std::size_t i = 0; i < names.size(); ++i) {
    list += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  }
  throw std::invalid_argument("'" + name + "' (expected " + list + ")");
}

std::vector<double> ColourBy::values(const io::FrameData& frame) const {
  const std::size_t n = frame.size();
  std::vector<double> v(kind_ == Kind::Cd ? 0 : n);
  for (std::size_t i = 0; i < v.size(); ++i) {
    switch (kind_) {
      case Kind::Speed: {
        const double x = row(frame.velocity.x, i), y = row(frame.velocity.y, i),
                     z = row(frame.velocity.z, i);
        v[i] = std::sqrt(x * x + y * y + z * z);
        break;
      }
      case Kind::Age:
        v[i] = row(frame.age, i);
        break;
      case Kind::NormalisedAge: {
        // An immortal particle (life +inf) is young for ever: 0.
        const double life = row(frame.life, i);
        v[i] = life > 0.0 && std::isfinite(life) ? std::clamp(row(frame.age, i) / life, 0.0, 1.0)
                                                 : 0.0;
        break;
      }
      case Kind::Id:
        v[i] = static_cast<double>(frame.id[i]);
        break;
      case Kind::Life:
        v[i] = row(frame.life, i);
        break;
      case Kind::Mass:
        v[i] = row(frame.mass, i);
        break;
      case Kind::Attribute:
        v[i] =
            row(frame.attributes[static_cast<std::size_t>(attributeIndex(frame, attribute_))], i);
        break;
      case Kind::Cd:
        break;
    }
  }
  return v;
}

std::vector<Rgb> ColourBy::colours(const io::FrameData& frame, double lo, double hi) const {
  std::vector<Rgb> out(frame.size());
  if (kind_ == Kind::Cd) {
    const FloatColumn* channel[3];
    for (int c = 0; c < 3; ++c) {
      channel[c] =
          &frame.attributes[static_cast<std::size_t>(attributeIndex(frame, kCdChannels[c]))];
    }
    for (std::size_t i = 0; i < out.size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        const double v = row(*channel[c], i);
        out[i][static_cast<std::size_t>(c)] = static_cast<std::uint8_t>(
            std::lround(255.0 * (std::isnan(v) ? 0.0 : std::clamp(v, 0.0, 1.0))));
      }
    }
    return out;
  }
  const std::vector<double> v = values(frame);
  const double span = hi - lo;
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = viridis(span > 0.0 ? (v[i] - lo) / span : 0.0);
  return out;
}

std::string ColourBy::title() const {
  switch (kind_) {
    case Kind::Speed:
      return "speed (m/s)";
    case Kind::Age:
      return "age (s)";
    case Kind::NormalisedAge:
      return "nage (age / life)";
    case Kind::Id:
      return "id";
    case Kind::Life:
      return "life (s)";
    case Kind::Mass:
      return "mass (kg)";
    case Kind::Attribute:
      return attribute_ == "pscale" ? "pscale (m)" : attribute_;
    case Kind::Cd:
      return "Cd";
  }
  return "";
}

}  // namespace tickfx::preview
