#include "integrator/sensors.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "base/error.h"
#include "base/sampling.h"
#include "base/text.h"
#include "integrator/direct_light.h"
#include "integrator/path_radiance.h"

namespace bpm {
namespace {

constexpr double kMostSensors = 1e7;

Vec3 vec(const std::vector<double>& v, size_t at) {
  return {float(v[at]), float(v[at + 1]), float(v[at + 2])};
}

// The grid form: corner, edges u and v, cell counts; a sensor at each cell's centre.
void add_grid(const std::vector<double>& v, const FileLoc& loc, std::vector<Sensor>* out) {
  if (v.size() != 11)
    throw Error(loc, "a grid needs 11 numbers (x y z, ux uy uz, vx vy vz, nu nv); it has " +
                         std::to_string(v.size()));
  const Vec3 corner = vec(v, 0), u = vec(v, 3), w = vec(v, 6);
  const double nu = v[9], nv = v[10];
  if (nu != std::floor(nu) || nv != std::floor(nv) || nu < 1 || nv < 1)
    throw Error(loc, "a grid's cell counts must be whole numbers from 1");
  if (double(out->size()) + nu * nv > kMostSensors)
    throw Error(loc, "more than 10^7 sensors in the file");
  const Vec3 n = cross(u, w);
  if (!(length(n) > 0)) throw Error(loc, "a grid's edges u and v must not be parallel or zero");
  const float cell = float(std::min(length(u) / nu, length(w) / nv));
  for (int j = 0; j < int(nv); ++j)
    for (int i = 0; i < int(nu); ++i)
      out->push_back({corner + u * float((i + 0.5) / nu) + w * float((j + 0.5) / nv), normalize(n),
                      cell, uint32_t(nu), uint32_t(nv), uint32_t(j * int(nu) + i)});
}

}  // namespace

std::vector<Sensor> parse_sensors(const std::string& text, const std::string& path) {
  std::vector<Sensor> out;
  std::istringstream in(text);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    const std::vector<Word> words = split_words(line);
    if (words.empty()) continue;  // blank, or white space of any kind (\v, \f) only
    const bool grid = words[0].text == "grid";
    std::vector<double> v;
    for (size_t k = grid ? 1 : 0; k < words.size(); ++k) {
      v.push_back(0);
      if (!parse_number(words[k].text, &v.back()))
        throw Error(FileLoc{path, number, words[k].column},
                    "\"" + words[k].text + "\" is not a number (a sensor is \"x y z nx ny nz\")");
    }
    const FileLoc loc{path, number, words[0].column};
    if (grid) {
      add_grid(v, loc, &out);
      continue;
    }
    if (v.size() != 6)
      throw Error(loc, "a sensor needs 6 numbers, x y z nx ny nz; this line has " +
                           std::to_string(v.size()));
    const Vec3 n = vec(v, 3);
    if (!(length(n) > 0)) throw Error(loc, "a sensor's normal must not be zero");
    if (double(out.size()) + 1 > kMostSensors)
      throw Error(loc, "more than 10^7 sensors in the file");
    out.push_back({vec(v, 0), normalize(n), 0});
  }
  if (out.empty()) throw Error(FileLoc{path, 1, 1}, "the sensor file holds no sensor");
  return out;
}

std::vector<Sensor> read_sensors(const std::string& path) {
  return parse_sensors(read_text_file(path, "sensor file"), path);
}

namespace {

// Next-event estimation at a white Lambertian surface (f = 1 / pi) standing for the sensor: pi
// times its radiance is the illuminance. The light sample's distance and angle are the sensor's
// own (sp.error: the rays leave from the lifted point).
Spectrum sensor_light_sample(const RenderScene& scene, const Sensor& s,
                             const WavelengthMaterials& wm, Rng& rng, PathCounters& counters) {
  SurfacePoint sp;
  sp.p = s.p;
  sp.ng = sp.ns = s.n;
  sp.error = sensor_lift(scene);
  const Material white = DiffuseMaterial{Spectrum(1.0f)};
  return sample_direct_light(scene, sp, -1, s.medium, white, Frame::from_z(s.n), Vec3(0, 0, 1),
                             true, wm, rng, counters) *
         kPi;
}

}  // namespace

void locate_sensor_media(const RenderScene& scene, int outer, std::vector<Sensor>* sensors) {
  for (Sensor& s : *sensors)
    s.medium = medium_at(scene, s.p + s.n * sensor_lift(scene), s.n, outer);
}

Spectrum sensor_irradiance(const RenderScene& scene, const Sensor& s, int max_depth,
                           const Wavelengths& wl, Rng& rng, PathCounters& counters,
                           bool caustics_elsewhere) {
  const WavelengthMaterials wm = WavelengthMaterials::resolved_per_point(scene, wl);
  Spectrum E = sensor_light_sample(scene, s, wm, rng, counters);
  // A cosine-distributed direction: E = pi L, the emission it finds weighted against the light
  // sample, and the light beyond found as a camera path finds it.
  const Vec3 origin = s.p + s.n * sensor_lift(scene);
  const Vec3 local = sample_cosine_hemisphere({rng.uniform(), rng.uniform()});
  const Vec3 wi = Frame::from_z(s.n).to_world(local);
  const EmitterWeight first = EmitterWeight::mis(local.z * kInvPi, origin);
  E += path_radiance(scene, Ray{origin, wi, kInf}, PathSettings{max_depth, caustics_elsewhere}, wl,
                     rng, counters, first, s.medium) *
       kPi;
  return E;
}

}  // namespace bpm
