// Unidirectional path tracer (integrator/path_radiance.h: next-event estimation with multiple
// importance sampling against BSDF sampling, Russian roulette, lights chosen in proportion to
// power). It is bpm's reference: its expectation equals pbrt-v4's PathIntegrator on the same scene.
#pragma once
#include "base/rng.h"
#include "film/film.h"
#include "integrator/counters.h"
#include "integrator/options.h"
#include "integrator/path_radiance.h"
#include "scene/flatten.h"

namespace bpm {

// Passes of one sample per pixel, each with its own eight wavelengths, until a budget ends the
// render.
RenderStats render_path(const LoadedScene& scene, const IntegratorOptions& options, Film* film);

}  // namespace bpm
