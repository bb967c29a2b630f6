#include "path/path_integrator.h"

#include <tbb/enumerable_thread_specific.h>

#include <cmath>

#include "integrator/direct_light.h"
#include "integrator/path_vertex.h"
#include "integrator/progressive.h"

namespace bpm {

Spectrum path_radiance(const RenderScene& scene, Ray ray, const PathSettings& settings,
                       const Wavelengths& wl, Rng& rng, PathCounters& counters,
                       const EmitterWeight& first) {
  const WavelengthMaterials materials = WavelengthMaterials::resolved_per_point(scene, wl);
  PathState s{ray};
  Spectrum L;
  EmitterWeight emitter = first;
  float eta_scale = 1;
  int depth = 0;
  ++counters.camera_rays;
  for (int guard = 0; guard < 10000; ++guard) {
    PathVertex v;
    if (next_eye_vertex(scene, materials, s, v, counters, emitter, L) != StepEnd::kVertex) break;
    if (depth++ == settings.max_depth) break;
    if (v.wo_local.z == 0) break;
    keep_hero_wavelength_at(v, s);
    if (!bsdf_is_specular(v.m()))
      L += s.beta * sample_direct_light(scene, v.sp, v.object(), s.medium, v.m(), v.frame,
                                        v.wo_local, true, materials, rng, counters);

    float uc = rng.uniform();
    Vec2 u{rng.uniform(), rng.uniform()};
    auto bs = sample_bsdf(v, uc, u, TransportMode::kRadiance);
    if (!bs) break;
    s.beta *= bs->f * (std::fabs(bs->wi.z) / bs->pdf_solid_angle);
    emitter = bs->is_specular() ? EmitterWeight::full() : EmitterWeight::mis(bs->mis_pdf, v.sp.p);
    if (bs->is_transmission()) eta_scale *= bs->eta * bs->eta;
    leave_vertex(scene, v, v.frame.to_world(bs->wi), s);
    ++counters.bounce_rays;
    if (s.beta.is_black()) break;
    // Russian roulette on the throughput without the radiance scaling of refraction
    // (pbrt-v4's etaScale), after the first two bounces.
    Spectrum rr_beta = s.beta * eta_scale;
    if (rr_beta.max_component() < 1 && depth > 1) {
      float q = std::fmax(0.0f, 1 - rr_beta.max_component());
      if (rng.uniform() < q) break;
      s.beta /= 1 - q;
    }
  }
  return L;
}

RenderStats render_path(const LoadedScene& ls, const IntegratorOptions& opt, Film* film) {
  const CameraSampler camera(ls.camera, ls.filter, film->width(), film->height(), opt.seed);
  const PathSettings settings{opt.max_depth};
  tbb::enumerable_thread_specific<PathCounters> counters;
  RenderStats stats;
  auto pass = [&](int pass, const RenderControl& control) {
    const int index = opt.first_iteration + pass;
    for_each_sampled_pixel(film->width(), film->height(), control, pass, [&](uint32_t pixel) {
      CameraSample cs = camera.sample(index, pixel);
      Wavelengths wl = sample_wavelengths(cs.rng.uniform());
      Spectrum L = path_radiance(ls.scene, cs.ray, settings, wl, cs.rng, counters.local());
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
