// Illuminance sensors: points with a normal where a render measures the illuminance (lux) of the
// light arriving from the normal's hemisphere. A sensor does not block light: a point in mid-air
// (a work plane) counts the light crossing it, a point on a surface the light arriving there.
// Each integrator estimates them its own way (path/sensors.h, photons/sensor_discs.h) in every
// pass; the film keeps each sensor's per-pass estimates, so every sensor has its standard error
// (eq. 5 of the paper) as the pixels do. What every estimator shares is here: the sensors, their
// file, and the path tracer's estimate at a sensor.
#pragma once
#include <string>
#include <vector>

#include "base/rng.h"
#include "base/vec.h"
#include "integrator/counters.h"
#include "scene/render_scene.h"

namespace bpm {

struct Sensor {
  Vec3 p;
  Vec3 n;  // unit length
  // The side of the grid cell the sensor stands for (the shorter edge), 0 for a single point.
  float cell = 0;
  // For a sensor of a grid: the grid's cell counts and the sensor's index in it, j * nu + i (the
  // sensors of a grid are consecutive); zero counts for a single point.
  uint32_t grid_nu = 0, grid_nv = 0, grid_k = 0;
  // The medium the sensor stands in (-1: none), found for a render by locate_sensor_media.
  int medium = -1;
};

// Reads a sensor file: one point a line, "x y z nx ny nz" (the input of Radiance's rtrace -I), or
// a grid, "grid x y z ux uy uz vx vy vz nu nv": the rectangle with corner (x, y, z) and edges u
// and v cut into nu x nv cells, a sensor at each cell's centre facing u x v (a lighting
// program's calculation surface). Blank lines and text after '#' are ignored. Errors name the
// file, line and column.
std::vector<Sensor> read_sensors(const std::string& path);
std::vector<Sensor> parse_sensors(const std::string& text, const std::string& path);

// Sets each sensor's medium: the one on its normal's side (medium_at), `outer` (the camera's)
// where no surface separating two media lies that way.
void locate_sensor_media(const RenderScene& scene, int outer, std::vector<Sensor>* sensors);

// Samples per sensor in each pass of the estimators that sample light at the sensor.
constexpr int kSensorSamplesPerPass = 16;
// Domain separation of the sensors' random streams from the pixels' and the photons'.
constexpr uint64_t kSensorStreams = 0x53454e534f525321ull;

// Rays leave from this far above a sensor (times the scene's bounding radius), so that a sensor on
// a surface does not see that surface.
inline float sensor_lift(const RenderScene& scene) { return 1e-6f * scene.bounds_info.radius; }

// The spectral irradiance at a sensor from one sample (the luminance of it is the illuminance):
// next-event estimation at a white Lambertian point standing for the sensor (on no object, in the
// sensor's medium), weighted by multiple importance sampling against a cosine-distributed
// direction whose path then goes on as a camera path does (path_radiance). With
// caustics_elsewhere, the light that reaches the sensor through traced lobes only is left out:
// the photon methods count it with photons.
Spectrum sensor_irradiance(const RenderScene& scene, const Sensor& s, int max_depth,
                           const Wavelengths& wl, Rng& rng, PathCounters& counters,
                           bool caustics_elsewhere = false);

}  // namespace bpm
