// The eye side of forward photon mapping: one eye path per pixel through specular vertices to its
// first diffuse vertex x1, where direct light comes from next-event estimation, caustics from the
// caustic map and indirect light from the global map, either at x1 or, with final gathering, at
// the diffuse vertex x2 one BSDF sample further.
#pragma once
#include "base/rng.h"
#include "fpm/photon_maps.h"
#include "fpm/settings.h"
#include "integrator/counters.h"
#include "scene/render_scene.h"

namespace bpm {

struct FpmEyeParams {
  const WavelengthMaterials* materials;  // this iteration's wavelengths
  const FpmSettings* fpm;
  int max_depth;
  float k0, k1;    // radii in pixel footprints (PixelFootprint at the vertex's path length)
  double emitted;  // photons emitted, N of eq. (2)
  // In a scattering medium the radii are never those of a shorter path than this
  // (photons/medium_radius.h).
  float medium_min_length = 0;
  // Direct light in media also sampled along the rays that lead to x1
  // (IntegratorOptions::equiangular).
  bool equiangular = true;
};

struct FpmEyeCounters {
  PathCounters rays;
  uint64_t lookups = 0, photons_used = 0;
  void add(const FpmEyeCounters& o) {
    rays.add(o.rays);
    lookups += o.lookups;
    photons_used += o.photons_used;
  }
};

// Radiance arriving along -ray.d at the camera, and the estimate of its bias: the photon
// estimates' 2 (L(r) - L(r / sqrt 2)), as bpm's (film.h, add_bias). near_edge: the pixel's
// mark_near_edges bits (photons/disc_probes.h), which decide whether the discs about a vertex
// seen directly are probed.
struct FpmEyeRadiance {
  Spectrum L, bias;
};
FpmEyeRadiance fpm_eye_radiance(const RenderScene& scene, const ForwardMaps& maps,
                                const FpmEyeParams& params, CameraRay ray, PixelFootprint footprint,
                                Rng& rng, FpmEyeCounters& counters, uint8_t near_edge = 3);

}  // namespace bpm
