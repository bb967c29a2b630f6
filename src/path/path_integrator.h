// Unidirectional path tracer: next-event estimation with multiple importance sampling (power
// heuristic) against BSDF sampling, Russian roulette, lights chosen in proportion to power. It is
// bpm's reference: its expectation equals pbrt-v4's PathIntegrator on the same scene.
#pragma once
#include "base/rng.h"
#include "film/film.h"
#include "integrator/counters.h"
#include "integrator/direct_light.h"
#include "integrator/options.h"
#include "scene/flatten.h"

namespace bpm {

struct PathSettings {
  int max_depth = 5;  // scattering events, as pbrt-v4's maxdepth
};

// Radiance arriving along -ray.d at the ray's origin, at the wavelengths wl. `first` weighs the
// emission of the first surface the ray meets (full for a camera ray; an illuminance sensor
// weighs it against its own light sample, path/sensors.h).
Spectrum path_radiance(const RenderScene& scene, Ray ray, const PathSettings& settings,
                       const Wavelengths& wl, Rng& rng, PathCounters& counters,
                       const EmitterWeight& first = EmitterWeight::full());

// Passes of one sample per pixel, each with its own eight wavelengths, until a budget ends the
// render.
RenderStats render_path(const LoadedScene& scene, const IntegratorOptions& options, Film* film);

}  // namespace bpm
