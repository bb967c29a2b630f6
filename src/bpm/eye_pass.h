// The eye pass (DESIGN.md, "one path, counted exactly once"): a camera path through specular
// vertices and up to D + 1 diffuse vertices. It counts emission seen through specular vertices
// only, direct light at each diffuse vertex by next-event estimation, and leaves a backward
// photon at each diffuse vertex for the light pass to fill: caustic photons only at x_1..x_D
// (radius r0), every photon but direct ones at x_(D+1) (radius r1), where the path ends.
#pragma once
#include <vector>

#include "base/rng.h"
#include "bpm/backward_photon.h"
#include "bpm/settings.h"
#include "path/path_integrator.h"
#include "scene/render_scene.h"

namespace bpm {

struct EyePassParams {
  const WavelengthMaterials* materials = nullptr;  // this iteration's wavelengths
  int diffuse_depth = 1;
  int max_depth = 5;
  // Radius per unit of eye path length: k * sqrt(pixel solid angle) * radius_scale(iteration).
  float radius_per_length0 = 0, radius_per_length1 = 0;
};

struct EyeCounters {
  PathCounters rays;  // camera, bounce and shadow rays
  uint64_t backward_photons = 0;
  void add(const EyeCounters& o) {
    rays.add(o.rays);
    backward_photons += o.backward_photons;
  }
};

// Backward photons of one thread, one list per scene object (no locks: each thread has its own).
using ObjectPhotonLists = std::vector<std::vector<BackwardPhoton>>;

// Traces one eye path for `pixel`; returns the radiance the eye pass itself accounts for and
// appends the path's backward photons to out[object].
Spectrum trace_eye_path(const RenderScene& scene, const EyePassParams& params, Ray ray, uint32_t pixel, Rng& rng,
                        ObjectPhotonLists& out, EyeCounters& counters);

}  // namespace bpm
