// The files a render leaves: linear EXR (rgb + rms + passes), sRGB PNG preview, a false-colour PNG
// of the relative error, and the JSON record of how the image was made.
#pragma once
#include <array>
#include <string>

#include "film/film.h"

namespace bpm {

struct OutputPaths {
  std::string exr, png, error_png, json;
  std::string bias_png;       // written only for a film with a bias estimate (the photon methods)
  std::string checkpoint;     // the state to resume from (render/checkpoint.h), when one is kept
  std::string sensors;        // OUT.sensors.csv: illuminance sensors, when the render has them
  std::string luminance_png;  // false-colour luminance with its legend
  std::string sensors_png;    // the sensor grids' illuminance with its legend, when there are grids
};

// A grid of sensors for OUT.sensors.png: nu x nv sensors from index `first`, j * nu + i.
struct SensorGrid {
  size_t first;
  int nu, nv;
};

// The sensors' CSV: a header row whose names carry their units, then per sensor its point, its
// normal, the illuminance (lux), its standard error (eq. 5 over passes), the bias estimate (zero
// for path), the total error and its passes; written atomically.
void write_sensors_csv(const std::string& path, const Film& film,
                       const std::vector<std::array<float, 6>>& sensors);

// The illuminance of the sensor grids, one under the other (u to the right, v up), on a linear
// scale in lux with its legend; written atomically. Legend text that cannot be drawn is left out
// with a warning. Nothing, and an earlier file of that name removed, without grids.
void write_sensors_png(const std::string& path, const Film& film,
                       const std::vector<SensorGrid>& grids);

// OUT.exr -> OUT.png, OUT.error.png, OUT.json, OUT.bias.png, OUT.checkpoint, OUT.sensors.csv,
// OUT.luminance.png, OUT.sensors.png. Throws Error when the name does not end in .exr.
OutputPaths output_paths(const std::string& exr_path);

// Writes the EXR and the PNGs (the image; the luminance in false colour; its relative total error
// and, with a bias estimate, its relative bias, each with a legend), each atomically. The caller
// writes the JSON record last, so that its presence means the set is complete.
// window: where the film lies in the camera's full image (a crop), kept in the EXR.
void write_images(const OutputPaths& paths, const Film& film, float imaging_ratio,
                  const DisplayWindow& window = {});

// Per pixel, an error (R G B) relative to the pixel's value over the three channels (as eq. 4 per
// pixel).
std::vector<float> relative_error(const Film& film, const std::vector<float>& error_rgb);

}  // namespace bpm
