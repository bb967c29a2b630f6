// The backward photon mapping integrator (the paper's Fig. 3). Each iteration is an independent
// estimate of the image in four stages, one file each: the eye pass leaves backward photons
// (eye_pass), per-object sphere trees are built over them (backward_maps), photons from the lights
// reach them, a fixed number in groups (light_pass), and the iteration's image joins the
// film (accumulate). integrator/progressive.h runs the iterations until a budget ends the render.
#pragma once
#include "bpm/settings.h"
#include "film/film.h"
#include "integrator/options.h"
#include "scene/flatten.h"

namespace bpm {

RenderStats render_bpm(const LoadedScene& scene, const IntegratorOptions& options,
                       const BpmSettings& settings, Film* film);

}  // namespace bpm
