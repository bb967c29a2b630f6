#include "path/path_integrator.h"

#include <tbb/enumerable_thread_specific.h>

#include <cmath>

#include "integrator/progressive.h"

namespace bpm {

RenderStats render_path(const LoadedScene& ls, const IntegratorOptions& opt, Film* film) {
  const CameraSampler camera(ls.camera, ls.filter,
                             ls.film.raster_for(film->width(), film->height()), opt.seed);
  const PathSettings settings{opt.max_depth, false, opt.equiangular};
  tbb::enumerable_thread_specific<PathCounters> counters;
  RenderStats stats;
  auto pass = [&](int pass, const RenderControl& control) {
    const int index = opt.first_iteration + pass;
    for_each_sampled_pixel(film->width(), film->height(), control, pass, [&](uint32_t pixel) {
      CameraSample cs = camera.sample(index, pixel);
      Wavelengths wl = ls.film.spectral.wavelengths(cs.rng.uniform());
      const Spectrum L = cs.weight > 0
                             ? path_radiance(ls.scene, cs.ray, settings, wl, cs.rng,
                                             counters.local(), EmitterWeight::full(), cs.medium) *
                                   cs.weight
                             : Spectrum();
      record_pass(film, pixel, L, wl, cs.filter_weight, ls.film.max_component_value);
    });
    PassResult r;
    for (const PathCounters& c : counters) r.rays += c.total();
    return r;
  };
  run_passes(opt, film, "pass", pass, &stats);
  for (const PathCounters& c : counters) stats.rays.add(c);
  return stats;
}

}  // namespace bpm
