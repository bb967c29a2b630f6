// The files a render leaves: linear EXR (rgb + rms + passes), sRGB PNG preview, a false-colour PNG
// of the relative error, and the JSON record of how the image was made.
#pragma once
#include <nlohmann/json.hpp>
#include <string>

#include "film/film.h"

namespace bpm {

struct OutputPaths {
  std::string exr, png, error_png, json;
};

// OUT.exr -> OUT.png, OUT.error.png, OUT.json. Throws Error when the name does not end in .exr.
OutputPaths output_paths(const std::string& exr_path);

// Writes every output atomically; the JSON last, so its presence means the set is complete.
void write_outputs(const OutputPaths& paths, const Film& film, float imaging_ratio, const nlohmann::json& record);

// Relative error (RMS / mean) per pixel mapped through a blue-to-red ramp; 10% and more is red.
Image error_false_colour(const Film& film);

}  // namespace bpm
