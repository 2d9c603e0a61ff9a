#include "app/preview/ColourMap.h"

#include <algorithm>
#include <cmath>

namespace tickfx::preview {

Rgb viridis(double t) {
  // Viridis at 0, 1/8, ..., 1.
  static constexpr Rgb kSamples[] = {{68, 1, 84},    {71, 44, 122},  {59, 81, 139},
                                     {44, 113, 142}, {33, 144, 141}, {39, 173, 129},
                                     {92, 200, 99},  {170, 220, 50}, {253, 231, 37}};
  constexpr int kLast = 8;
  t = std::isnan(t) ? 0.0 : std::clamp(t, 0.0, 1.0);
  const double at = t * kLast;
  const int i = std::min(static_cast<int>(at), kLast - 1);
  const double f = at - i;
  Rgb out{};
  for (int c = 0; c < 3; ++c) {
    const double v = kSamples[i][c] + (kSamples[i + 1][c] - kSamples[i][c]) * f;
    out[c] = static_cast<std::uint8_t>(std::lround(v));
  }
  return out;
}

}  // namespace tickfx::preview
