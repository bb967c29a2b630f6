// Illuminance sensors: points with a normal where a render measures the illuminance (lux) of the
// light arriving from the normal's hemisphere. A sensor does not block light: a point in mid-air
// (a work plane) counts the light crossing it, a point on a surface the light arriving there.
//
// Each pass estimates every sensor's illuminance independently of the image, with the path
// tracer's estimator (the unbiased reference): next-event estimation at the sensor, combined by
// multiple importance sampling with a cosine-distributed direction whose path then goes on as a
// camera path does. The film keeps each sensor's per-pass estimates, so every sensor has its
// standard error (eq. 5 of the paper) as the pixels do.
#pragma once
#include <string>
#include <vector>

#include "base/rng.h"
#include "base/vec.h"
#include "film/film.h"
#include "scene/render_scene.h"

namespace bpm {

struct Sensor {
  Vec3 p;
  Vec3 n;  // unit length
};

// Reads a sensor file: one point a line, "x y z nx ny nz" (the input of Radiance's rtrace -I), or
// a grid, "grid x y z ux uy uz vx vy vz nu nv": the rectangle with corner (x, y, z) and edges u
// and v cut into nu x nv cells, a sensor at each cell's centre facing u x v (a lighting
// program's calculation surface). Blank lines and text after '#' are ignored. Errors name the
// file, line and column.
std::vector<Sensor> read_sensors(const std::string& path);
std::vector<Sensor> parse_sensors(const std::string& text, const std::string& path);

// Samples per sensor in each pass.
constexpr int kSensorSamplesPerPass = 16;

// One pass of every sensor: the mean of kSensorSamplesPerPass estimates each, at wavelengths and
// random numbers keyed by (seed, pass index, sensor), recorded in the film's sensor sums.
void sensor_pass(const RenderScene& scene, const std::vector<Sensor>& sensors, int max_depth,
                 uint64_t seed, int pass_index, Film* film);

// The spectral irradiance at a sensor from one sample (the luminance of it is the illuminance).
Spectrum sensor_irradiance(const RenderScene& scene, const Sensor& s, int max_depth,
                           const Wavelengths& wl, Rng& rng);

}  // namespace bpm
