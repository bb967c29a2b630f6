// Unidirectional path tracer: next-event estimation with multiple importance sampling (power
// heuristic) against BSDF sampling, Russian roulette, lights chosen in proportion to power. It is
// bpm's reference: its expectation equals pbrt-v4's PathIntegrator on the same scene.
#pragma once
#include <cstdint>
#include <vector>

#include "base/rng.h"
#include "scene/render_scene.h"

namespace bpm {

// Every ray a path traces, for benchmarks that replay them through bare Embree.
struct RayLog {
  std::vector<Ray> closest_hit;  // camera and bounce rays
  std::vector<Ray> shadow;       // shadow rays (t_max is the segment length)
};

struct PathCounters {
  uint64_t camera_rays = 0, bounce_rays = 0, shadow_rays = 0;
  RayLog* log = nullptr;  // null except in benchmarks
  void add(const PathCounters& o) {
    camera_rays += o.camera_rays;
    bounce_rays += o.bounce_rays;
    shadow_rays += o.shadow_rays;
  }
  uint64_t total() const { return camera_rays + bounce_rays + shadow_rays; }
};

struct PathSettings {
  int max_depth = 5;  // scattering events, as pbrt-v4's maxdepth
};

// Direct light at a non-specular vertex by sampling one light chosen by power (Veach 1997,
// 9.2.4), with the power heuristic against BSDF sampling when use_mis (the caller then weights
// the emitters its BSDF samples hit), else with full weight. sp lies on `object`, reached by a ray
// in `medium`: the shadow ray's absorption is that of the medium on the light's side.
Spectrum sample_direct_light(const RenderScene& scene, const SurfacePoint& sp, int object, int medium, const Material& m,
                             const Frame& frame, Vec3 wo_local, bool use_mis, const Wavelengths& wl, Rng& rng,
                             PathCounters& counters);

// Radiance arriving along -ray.d at the ray's origin, at the wavelengths wl.
Spectrum path_radiance(const RenderScene& scene, Ray ray, const PathSettings& settings, const Wavelengths& wl,
                       Rng& rng, PathCounters& counters);

}  // namespace bpm
