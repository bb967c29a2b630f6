// Forward photon mapping (Jensen 1996), made progressive: the prototype the paper compares
// backward photon maps with (section 5). Each iteration traces photons from the lights into a
// global and a caustic map (photon_maps), builds kd-trees over the photon centres, and then traces
// one eye path per pixel that reads the maps (eye_paths).
#pragma once
#include "film/film.h"
#include "fpm/settings.h"
#include "integrator/options.h"
#include "scene/flatten.h"

namespace bpm {

RenderStats render_fpm(const LoadedScene& scene, const IntegratorOptions& options,
                       const FpmSettings& settings, Film* film);

}  // namespace bpm
