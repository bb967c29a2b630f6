#include "path/sensors.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <sstream>

#include "base/error.h"
#include "base/sampling.h"
#include "base/text.h"
#include "integrator/direct_light.h"
#include "path/path_integrator.h"

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
  for (int j = 0; j < int(nv); ++j)
    for (int i = 0; i < int(nu); ++i)
      out->push_back(
          {corner + u * float((i + 0.5) / nu) + w * float((j + 0.5) / nv), normalize(n)});
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
    out.push_back({vec(v, 0), normalize(n)});
  }
  if (out.empty()) throw Error(FileLoc{path, 1, 1}, "the sensor file holds no sensor");
  return out;
}

std::vector<Sensor> read_sensors(const std::string& path) {
  return parse_sensors(read_text_file(path, "sensor file"), path);
}

Spectrum sensor_irradiance(const RenderScene& scene, const Sensor& s, int max_depth,
                           const Wavelengths& wl, Rng& rng) {
  PathCounters counters;
  const Frame frame = Frame::from_z(s.n);
  // Rays leave from just above the sensor, so that a sensor on a surface does not see that
  // surface; the light sample's distance and angle are the sensor's own (sp.error below).
  const float lift = 1e-6f * scene.bounds_info.radius;
  const Vec3 origin = s.p + s.n * lift;
  // Next-event estimation at a white Lambertian surface standing for the sensor (f = 1 / pi,
  // weighted by the power heuristic against the cosine sample below): pi times its radiance is
  // the illuminance. The point lies on no object and in the scene's outer medium.
  SurfacePoint sp;
  sp.p = s.p;
  sp.ng = sp.ns = s.n;
  sp.error = lift;
  const Material white = DiffuseMaterial{Spectrum(1.0f)};
  const WavelengthMaterials wm = WavelengthMaterials::resolved_per_point(scene, wl);
  Spectrum E =
      sample_direct_light(scene, sp, -1, -1, white, frame, Vec3(0, 0, 1), true, wm, rng, counters) *
      kPi;
  // A cosine-distributed direction: E = pi L, the emission it finds weighted against the light
  // sample, and the light beyond found as a camera path finds it.
  const Vec3 local = sample_cosine_hemisphere({rng.uniform(), rng.uniform()});
  const Vec3 wi = frame.to_world(local);
  const EmitterWeight first = EmitterWeight::mis(local.z * kInvPi, origin);
  E += path_radiance(scene, Ray{origin, wi, kInf}, PathSettings{max_depth}, wl, rng, counters,
                     first) *
       kPi;
  return E;
}

void sensor_pass(const RenderScene& scene, const std::vector<Sensor>& sensors, int max_depth,
                 uint64_t seed, int pass_index, Film* film) {
  // A stream of its own for each (pass, sensor, sample), apart from the pixels' streams.
  constexpr uint64_t kSensorStreams = 0x53454e534f525321ull;
  tbb::parallel_for(size_t(0), sensors.size(), [&](size_t i) {
    double sum = 0;
    for (int k = 0; k < kSensorSamplesPerPass; ++k) {
      Rng rng(stream_key(seed ^ kSensorStreams, uint64_t(pass_index), i, uint64_t(k)));
      const Wavelengths wl = sample_wavelengths(rng.uniform());
      const Spectrum E = sensor_irradiance(scene, sensors[i], max_depth, wl, rng);
      if (E.is_finite() && !E.has_negative()) sum += spectrum_to_luminance(E, wl);
    }
    film->add_sensor_pass(i, sum / kSensorSamplesPerPass);
  });
}

}  // namespace bpm
