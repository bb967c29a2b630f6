// The files a render leaves: linear EXR (rgb + rms + passes), sRGB PNG preview, a false-colour PNG
// of the relative error, and the JSON record of how the image was made.
#pragma once
#include <array>
#include <string>

#include "film/film.h"

namespace bpm {

struct OutputPaths {
  std::string exr, png, error_png, json;
  std::string bias_png;    // written only for a film with a bias estimate (the photon methods)
  std::string checkpoint;  // the state to resume from (render/checkpoint.h), when one is kept
  std::string sensors;     // OUT.sensors.csv: illuminance sensors, when the render has them
};

// The sensors' CSV: a header row whose names carry their units, then per sensor its point, its
// normal, the illuminance (lux), its standard error (eq. 5 over passes), the bias estimate (zero:
// the sensors' estimator is unbiased) and its passes; written atomically.
void write_sensors_csv(const std::string& path, const Film& film,
                       const std::vector<std::array<float, 6>>& sensors);

// OUT.exr -> OUT.png, OUT.error.png, OUT.json, OUT.bias.png, OUT.checkpoint, OUT.sensors.csv.
// Throws Error when the name does not end in .exr.
OutputPaths output_paths(const std::string& exr_path);

// Writes the EXR and the PNGs (the image, its total error, and with a bias estimate its bias),
// each atomically. The caller writes the JSON record last, so that its presence means the set is
// complete.
void write_images(const OutputPaths& paths, const Film& film, float imaging_ratio);

// An error per pixel and channel (R G B), relative to the pixel's value, mapped through a
// blue-to-red ramp; 10% and more is red.
Image relative_false_colour(const Film& film, const std::vector<float>& error_rgb);

}  // namespace bpm
