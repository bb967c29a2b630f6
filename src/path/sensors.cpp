#include "path/sensors.h"

#include <tbb/parallel_for.h>

#include "base/sampling.h"

namespace bpm {

void sensor_pass(const RenderScene& scene, const std::vector<Sensor>& sensors, int max_depth,
                 uint64_t seed, int pass_index, Film* film,
                 tbb::enumerable_thread_specific<PathCounters>& counters) {
  // A stream of its own for each (pass, sensor, sample).
  tbb::parallel_for(size_t(0), sensors.size(), [&](size_t i) {
    double sum = 0;
    for (int k = 0; k < kSensorSamplesPerPass; ++k) {
      Rng rng(stream_key(seed ^ kSensorStreams, uint64_t(pass_index), i, uint64_t(k)));
      const Wavelengths wl = sample_wavelengths(rng.uniform());
      const Spectrum E = sensor_irradiance(scene, sensors[i], max_depth, wl, rng, counters.local());
      if (E.is_finite() && !E.has_negative()) sum += spectrum_to_luminance(E, wl);
    }
    film->add_sensor_pass(i, sum / kSensorSamplesPerPass);
  });
}

}  // namespace bpm
