// What a preview colours its particles by.
#pragma once

#include <string>
#include <vector>

#include "app/preview/SplatImage.h"
#include "io/cache/FrameData.h"

namespace tickfx::preview {

/// A value per particle shown through viridis over a range (speed, age, ...), or the particles'
/// own colour (Cd: the custom attributes Cd_r, Cd_g and Cd_b, each 0 to 1, as tickfx and
/// readVdbPointCache name Houdini's Cd).
class ColourBy {
 public:
  /// `name` is speed (m/s), age (s), nage (age over lifetime, 0 to 1), id, Cd, or a float column
  /// of `frame`: life, mass or a custom attribute (pscale, ...). Throws std::invalid_argument
  /// "'NAME' (expected A, B or C)" listing what `frame` offers when it is none of them.
  static ColourBy parse(const std::string& name, const io::FrameData& frame);

  /// What `frame` can be coloured by, in the order parse's message lists them.
  static std::vector<std::string> choices(const io::FrameData& frame);

  /// Whether the particles bring their own colours (Cd): no value range, no legend.
  bool ownColours() const { return kind_ == Kind::Cd; }

  /// Each particle's value, in `frame`'s row order (empty for Cd).
  std::vector<double> values(const io::FrameData& frame) const;

  /// Each particle's colour: its value through viridis with `lo` at 0 and `hi` at 1 (a range of
  /// no width puts everything at 0), or its Cd.
  std::vector<Rgb> colours(const io::FrameData& frame, double lo, double hi) const;

  /// What the legend calls the value: "speed (m/s)", "age (s)", "nage", "id", "mass (kg)", ...
  std::string title() const;

 private:
  enum class Kind { Speed, Age, NormalisedAge, Id, Life, Mass, Attribute, Cd };
  ColourBy(Kind kind, std::string attribute) : kind_(kind), attribute_(std::move(attribute)) {}
  Kind kind_;
  std::string attribute_;
};

}  // namespace tickfx::preview
