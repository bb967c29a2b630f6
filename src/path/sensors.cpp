#include "path/sensors.h"

#include <tbb/parallel_for.h>

#include "base/sampling.h"
#include "integrator/direct_light.h"
#include "path/path_integrator.h"

namespace bpm {

Spectrum sensor_irradiance(const RenderScene& scene, const Sensor& s, int max_depth,
                           const Wavelengths& wl, Rng& rng) {
  PathCounters counters;
  const WavelengthMaterials wm = WavelengthMaterials::resolved_per_point(scene, wl);
  Spectrum E = sensor_light_sample(scene, s, wm, rng, counters);
  // A cosine-distributed direction: E = pi L, the emission it finds weighted against the light
  // sample, and the light beyond found as a camera path finds it.
  const Vec3 origin = s.p + s.n * sensor_lift(scene);
  const Vec3 local = sample_cosine_hemisphere({rng.uniform(), rng.uniform()});
  const Vec3 wi = Frame::from_z(s.n).to_world(local);
  const EmitterWeight first = EmitterWeight::mis(local.z * kInvPi, origin);
  E += path_radiance(scene, Ray{origin, wi, kInf}, PathSettings{max_depth}, wl, rng, counters,
                     first) *
       kPi;
  return E;
}

void sensor_pass(const RenderScene& scene, const std::vector<Sensor>& sensors, int max_depth,
                 uint64_t seed, int pass_index, Film* film) {
  // A stream of its own for each (pass, sensor, sample).
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
