// The files a render leaves: linear EXR (rgb + rms + passes), sRGB PNG preview, a false-colour PNG
// of the relative error, and the JSON record of how the image was made.
#pragma once
#include <string>

#include "film/film.h"

namespace bpm {

struct OutputPaths {
  std::string exr, png, error_png, json;
};

// OUT.exr -> OUT.png, OUT.error.png, OUT.json. Throws Error when the name does not end in .exr.
OutputPaths output_paths(const std::string& exr_path);

// Writes the EXR and both PNGs, each atomically. The caller writes the JSON record last, so that
// its presence means the set is complete.
void write_images(const OutputPaths& paths, const Film& film, float imaging_ratio);

// Relative error (RMS / mean) per pixel mapped through a blue-to-red ramp; 10% and more is red.
Image error_false_colour(const Film& film);

}  // namespace bpm
