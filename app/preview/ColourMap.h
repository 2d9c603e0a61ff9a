// Perceptual colour maps for preview renders.
#pragma once

#include "app/preview/SplatImage.h"

namespace tickfx::preview {

/// Viridis (matplotlib's default map: perceptually uniform, readable in grey and by colour-blind
/// viewers) at `t` in [0, 1], from dark purple at 0 to yellow at 1; t outside is held to the
/// ends, NaN gives the colour of 0. Interpolated linearly between nine samples of the map.
Rgb viridis(double t);

}  // namespace tickfx::preview
