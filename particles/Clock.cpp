#include "particles/Clock.h"

#include <cmath>
#include <string>

namespace tickfx {

Flicks frameDuration(FrameRate rate) {
  if (rate.numerator <= 0 || rate.denominator <= 0) {
    throw std::invalid_argument("frame rate must be positive");
  }
  const __int128 scaled = static_cast<__int128>(kFlicksPerSecond) * rate.denominator;
  if (scaled % rate.numerator != 0) {
    throw std::invalid_argument("frame rate " + std::to_string(rate.numerator) + "/" +
                                std::to_string(rate.denominator) +
                                " is not a whole number of flicks per frame");
  }
  return static_cast<Flicks>(scaled / rate.numerator);
}

Flicks flicksFromSeconds(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0.0 || seconds > 1.0e9) {
    throw std::invalid_argument("duration must be a finite number of seconds >= 0");
  }
  return static_cast<Flicks>(std::llround(seconds * static_cast<double>(kFlicksPerSecond)));
}

}  // namespace tickfx
