// The path tracer's estimate of the radiance along a ray: next-event estimation with multiple
// importance sampling (power heuristic) against BSDF sampling, Russian roulette, lights chosen in
// proportion to power; scattering in media. The path integrator renders with it
// (path/path_integrator.h); illuminance sensors trace their paths with it (integrator/sensors.h).
#pragma once
#include "base/rng.h"
#include "integrator/counters.h"
#include "integrator/direct_light.h"
#include "scene/render_scene.h"

namespace bpm {

struct PathSettings {
  int max_depth = 5;  // scattering events, as pbrt-v4's maxdepth
  // Leave out the light that reaches the ray's origin through traced lobes only (materials/
  // material.h): light from an emitter that meets traced lobes at every vertex between. The photon
  // methods count it with their caustic photons at an illuminance sensor. At a vertex every one
  // before which was traced, the gathered lobes take their direct light (next-event estimation
  // and a BSDF sample of that part, as a photon method's eye path at a diffuse vertex); the path
  // goes on through whichever lobe it samples.
  bool caustics_elsewhere = false;
  // Direct light in media also by equiangular sampling along each piece of the path's rays
  // (sample_direct_light_along), shared with next-event estimation at free-flight points.
  bool equiangular = true;
};

// Radiance arriving along -ray.d at the ray's origin, at the wavelengths wl. `first` weighs the
// emission of the first surface the ray meets (full for a camera ray; an illuminance sensor
// weighs it against its own light sample); the ray starts in `medium` (-1: none). In scattering
// media the path scatters too (a volumetric path tracer, as pbrt-v4's volpath): free-flight
// distances (sample_medium_distance), next-event estimation through the phase function and
// phase sampling, by the power heuristic; a scattering event counts toward max_depth.
Spectrum path_radiance(const RenderScene& scene, Ray ray, const PathSettings& settings,
                       const Wavelengths& wl, Rng& rng, PathCounters& counters,
                       const EmitterWeight& first = EmitterWeight::full(), int medium = -1);

}  // namespace bpm
