// The backward photon mapping integrator (the paper's Fig. 3): each iteration is an eye pass
// that leaves backward photons, per-object sphere trees, a light pass in batches until the
// backward photons are covered, and the accumulation of the iteration's image into the film.
#pragma once
#include <nlohmann/json.hpp>

#include "bpm/settings.h"
#include "film/film.h"
#include "render/renderer.h"
#include "scene/flatten.h"

namespace bpm {

RenderStats render_bpm(const LoadedScene& scene, const RenderOptions& options, Film* film);

}  // namespace bpm
