// Text burnt into preview images: a 5×7 pixel font of its own, so labels need no font file and
// have the same pixels everywhere.
#pragma once

#include <string_view>

#include "app/preview/SplatImage.h"

namespace tickfx::preview {

/// Pixels a character advances at scale 1 (5 of glyph, 1 of space), and a line's height.
inline constexpr int kGlyphAdvance = 6;
inline constexpr int kGlyphHeight = 7;

/// Width in pixels of `text` drawn at `scale` (each font pixel a scale × scale square).
int textWidth(std::string_view text, int scale);

/// Draws `text` with its top-left corner at (x, y): lower-case letters, digits, space and
/// . , : ; = - + * _ / ( ) [ ] < > % # ! ? ' "; upper-case letters are drawn as lower-case,
/// anything else as '?'.
/// Pixels outside the image are skipped.
void drawText(SplatImage& image, int x, int y, std::string_view text, Rgb colour, int scale);

/// Fills the rectangle [x0, x1) × [y0, y1) (clipped to the image) with `colour`.
void fillRect(SplatImage& image, int x0, int y0, int x1, int y1, Rgb colour);

}  // namespace tickfx::preview
