// The path tracer's estimator of illuminance sensors (integrator/sensors.h), the unbiased
// reference: next-event estimation at the sensor, combined by multiple importance sampling with a
// cosine-distributed direction whose path then goes on as a camera path does.
#pragma once
#include <tbb/enumerable_thread_specific.h>

#include <vector>

#include "base/rng.h"
#include "film/film.h"
#include "integrator/counters.h"
#include "integrator/sensors.h"
#include "scene/render_scene.h"

namespace bpm {

// One pass of every sensor: the mean of kSensorSamplesPerPass estimates each, at wavelengths and
// random numbers keyed by (seed, pass index, sensor), recorded in the film's sensor sums; the
// rays traced are added to `counters` (the thread's own).
void sensor_pass(const RenderScene& scene, const std::vector<Sensor>& sensors, int max_depth,
                 uint64_t seed, int pass_index, Film* film,
                 tbb::enumerable_thread_specific<PathCounters>& counters);

}  // namespace bpm
