// Forward photon mapping (Jensen 1996), made progressive: the prototype the paper compares
// backward photon maps with (section 5). Each iteration traces photons from the lights and stores
// one at every diffuse surface they reach (a global map, and a caustic map for photons whose path
// so far was specular only), builds kd-trees over the photon centres, and then traces one eye path
// per pixel to its first diffuse vertex x1, where direct light comes from next-event estimation,
// caustics from the caustic map, and indirect light from the global map, either at x1 or, with
// final gathering, at the diffuse vertex x2 one BSDF sample further.
#pragma once
#include "film/film.h"
#include "render/renderer.h"
#include "scene/flatten.h"

namespace bpm {

RenderStats render_fpm(const LoadedScene& scene, const RenderOptions& options, Film* film);

}  // namespace bpm
