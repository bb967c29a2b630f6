// False-colour pictures people read: one value per pixel (or per sensor of a grid) through a
// colour scale, with a legend strip under the picture that names the quantity, its unit and its
// scale (log or linear) and labels the colours, drawn with OpenImageIO's text
// (textures/image_file.h). Used for OUT.luminance.png, OUT.sensors.png and OUT.error.png.
#pragma once
#include <string>
#include <vector>

#include "film/film.h"

namespace bpm {

struct ColourScale {
  enum Ramp { kHeat, kBlueRed };  // black-red-yellow-white, or blue-green-red
  double lo = 0, hi = 1;          // the values at the two ends
  bool log = false;               // log10 between lo and hi (both positive), else linear
  Ramp ramp = kHeat;
  std::string title;     // what the colours show, with the unit and the scale
  bool percent = false;  // tick labels as percentages (of 1)
  // The colour of a value: below lo the first, above hi the last.
  Rgb colour(double value) const;
};

// A log scale over whole decades for values such as luminance: its top the decade above the
// 99.9th percentile of the positive values, its bottom the decade below their 1st percentile, at
// most six decades under the top and at least one.
ColourScale log_scale(const std::vector<float>& values, const std::string& title);
// A linear scale from 0 to a round number (1, 2, 2.5 or 5 times a power of ten) at or above the
// largest value.
ColourScale linear_scale(const std::vector<float>& values, const std::string& title);

// A block of values to draw: width x height values, rows from the top, each drawn as a square of
// `zoom` pixels; with `labels`, each square also shows its value (when the squares are large
// enough for the text).
struct ValueBlock {
  const std::vector<float>* values;
  int width, height, zoom = 1;
  bool labels = false;
};

// The blocks one under the other (a gap between them) and the legend under them, on a canvas at
// least 360 pixels wide. Text that cannot be drawn (no font, no image module) is left out, the
// reason in *warning (empty when all was drawn).
Image false_colour_picture(const std::vector<ValueBlock>& blocks, const ColourScale& scale,
                           std::string* warning);

}  // namespace bpm
