#include "fpm/fpm_integrator.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "base/error.h"
#include "base/memory.h"
#include "fpm/eye_paths.h"
#include "fpm/photon_maps.h"
#include "integrator/progressive.h"
#include "photons/disc_probes.h"

namespace bpm {
namespace {

struct FpmTotals {
  LightCounters light;
  FpmEyeCounters eye;
  double light_s = 0, build_s = 0, eye_s = 0;
  uint64_t stored = 0, stored_caustic = 0;
  size_t peak_map_bytes = 0, peak_tree_bytes = 0;
  uint64_t emitted = 0;    // photons kept in the estimates (N summed over iterations)
  int iterations_cut = 0;  // iterations whose light pass the time budget cut short
};

double ratio(double a, double b) { return b > 0 ? a / b : 0.0; }

nlohmann::json to_json(const FpmTotals& t, const FpmSettings& s) {
  const LightCounters& lt = t.light;
  return {
      {"settings", settings_json(s)},
      {"light",
       {{"photons", lt.photons},
        {"light_rays", lt.light_rays},
        {"diffuse_hits", lt.diffuse_hits},
        {"photons_stored", t.stored},
        {"caustic_photons_stored", t.stored_caustic},
        {"photons_kept", t.emitted},
        {"iterations_cut", t.iterations_cut},
        // The paper's Table 1 counts per ray traced from a light with all its continuations (a
        // photon path); per segment counts every emitted and bounce ray.
        {"photons_per_forward_ray", ratio(double(t.stored), double(lt.photons))},
        {"photons_per_forward_segment", ratio(double(t.stored), double(lt.light_rays))},
        {"rays_per_second", ratio(double(lt.light_rays), t.light_s)}}},
      {"maps",
       {{"peak_photon_bytes", t.peak_map_bytes},
        {"peak_tree_bytes", t.peak_tree_bytes},
        {"forward_photon_bytes_each", sizeof(ForwardPhoton)},
        {"tree_build_s", t.build_s}}},
      {"eye",
       {{"camera_rays", t.eye.rays.camera_rays},
        {"bounce_rays", t.eye.rays.bounce_rays},
        {"shadow_rays", t.eye.rays.shadow_rays},
        {"probe_rays", t.eye.rays.probe_rays},
        {"lookups", t.eye.lookups},
        {"photons_used", t.eye.photons_used},
        {"rays_per_second", ratio(double(t.eye.rays.total()), t.eye_s)}}},
      {"stages_s", {{"light", t.light_s}, {"tree_build", t.build_s}, {"eye", t.eye_s}}},
  };
}

}  // namespace

RenderStats render_fpm(const LoadedScene& ls, const IntegratorOptions& opt,
                       const FpmSettings& settings, Film* film) {
  FpmSettings s = settings;
  s.photons_per_iteration = photons_for(settings, size_t(film->width()) * size_t(film->height()));
  if (!(s.k0 > 0) || !(s.k1 > 0)) throw Error("fpm: --k0 and --k1 (file: k0, k1) must be positive");
  if (s.photons_per_iteration <= 0)
    throw Error("fpm: --photons (file: photonsperiteration) must be positive");
  if (s.knn < 0) throw Error("fpm: --knn (file: knn) must not be negative");
  const RenderScene& scene = ls.scene;
  const CameraSampler camera(ls.camera, ls.filter, film->width(), film->height(), opt.seed);
  const float pixel_angle = std::sqrt(camera.camera().pixel_solid_angle());
  const int min_eye_vertices = s.final_gather ? 2 : 1;
  // Memory (base/memory.h): a photon is stored at most once per diffuse hit that still leaves room
  // for the eye vertices, plus one caustic copy; each stored photon is in its chunk's list, in the
  // joined map and in the tree. The worst iteration must fit the budget before the first one. Per
  // pixel, beside the film: the disc probes' edges and near-edge marks.
  const double fixed_bytes = double(film->bytes()) + 2.0 * film->width() * film->height();
  const double stored_per_photon = std::max(0, opt.max_depth - min_eye_vertices + 1) + 1;
  const double photon_bytes =
      2 * sizeof(ForwardPhoton) + 2 * (sizeof(SphereRef) + sizeof(uint32_t));
  // The map holds a whole iteration's photons: the automatic count takes no more than the budget
  // holds at worst (but never fewer than 100000, which fail as a count set would).
  if (settings.photons_per_iteration == 0 && opt.memory_budget > 0) {
    const double fit =
        (double(opt.memory_budget) - fixed_bytes) / (stored_per_photon * photon_bytes);
    s.photons_per_iteration = int(std::clamp(fit, 100000.0, double(s.photons_per_iteration)));
  }
  const uint64_t n_photons = uint64_t(s.photons_per_iteration);
  check_memory("fpm with " + std::to_string(n_photons) + " photons per iteration and maxdepth " +
                   std::to_string(opt.max_depth) + " (up to " +
                   std::to_string(int(stored_per_photon)) + " stored per photon)",
               fixed_bytes + double(n_photons) * stored_per_photon * photon_bytes,
               opt.memory_budget, "lower --photons or --maxdepth, or raise --memory");
  // Disc probes at vertices seen directly near edges only (photons/disc_probes.h).
  NearEdges near_edges(s.disc_probes, scene, camera.camera(), film->width(), film->height(),
                       ls.filter.radius);
  ForwardMaps maps;
  tbb::enumerable_thread_specific<LightCounters> light_counters;
  tbb::enumerable_thread_specific<FpmEyeCounters> eye_counters;
  FpmTotals tot;

  auto iteration = [&](int pass, const RenderControl& control) {
    const int it = opt.first_iteration + pass;  // the index random streams and radii follow
    // One set of wavelengths for every eye and light path of the iteration.
    const WavelengthMaterials wm(scene, iteration_wavelengths(opt.seed, it));
    // 1. Light pass: a forward photon at every diffuse hit.
    auto t = Clock::now();
    // The time budget holds inside an iteration: the light pass may end early, with fewer photons.
    const uint64_t emitted = trace_forward_photons(
        scene, wm, opt.max_depth, min_eye_vertices, n_photons, opt.seed, it, light_counters,
        [&] { return control.stop_requested(); }, &maps);
    tot.light_s += since(t);
    // After the first iteration, an eye pass would be cut at once: the iteration is dropped.
    if (control.cut(pass)) return PassResult{false, 0, "", ""};
    if (emitted < n_photons) ++tot.iterations_cut;
    tot.emitted += emitted;

    // 2. The maps, in chunk order (the same for any thread count), and their trees.
    t = Clock::now();
    build_forward_maps(&maps);
    tot.stored +=
        maps.global.photons.size();  // every photon once; the caustic map holds copies of some
    tot.stored_caustic += maps.caustic.photons.size();
    tot.build_s += since(t);
    tot.peak_map_bytes =
        std::max(tot.peak_map_bytes, maps.global.photon_bytes() + maps.caustic.photon_bytes());
    tot.peak_tree_bytes =
        std::max(tot.peak_tree_bytes, maps.global.tree.bytes() + maps.caustic.tree.bytes());

    // 3. Eye pass.
    t = Clock::now();
    float scale = radius_scale(s, it);
    near_edges.mark(s.k0 * scale, s.k1 * scale);
    FpmEyeParams ep{&wm,
                    &s,
                    opt.max_depth,
                    s.k0 * pixel_angle * scale,
                    s.k1 * pixel_angle * scale,
                    double(emitted)};
    for_each_sampled_pixel(film->width(), film->height(), control, pass, [&](uint32_t pixel) {
      CameraSample cs = camera.sample(it, pixel);
      const FpmEyeRadiance r = fpm_eye_radiance(scene, maps, ep, cs.ray, cs.rng,
                                                eye_counters.local(), near_edges.at(pixel));
      if (s.debias) {
        record_pass(film, pixel, r.L - r.bias, wm.wl, cs.filter_weight, ls.film.max_component_value,
                    true);
        return;
      }
      if (r.bias.is_finite() && cs.filter_weight != 0 && recordable(r.L))
        film->add_bias(int(pixel % uint32_t(film->width())), int(pixel / uint32_t(film->width())),
                       spectrum_to_rgb(r.bias, wm.wl));
      record_pass(film, pixel, r.L, wm.wl, cs.filter_weight, ls.film.max_component_value);
    });
    tot.eye_s += since(t);

    PassResult r;
    for (const FpmEyeCounters& c : eye_counters) r.rays += c.rays.total();
    for (const LightCounters& c : light_counters) r.rays += c.light_rays;
    char progress[64];
    std::snprintf(progress, sizeof progress, "  %zu photons stored", maps.global.photons.size());
    r.progress = progress;
    return r;
  };
  RenderStats stats;
  run_passes(opt, film, "iteration", iteration, &stats);
  for (const LightCounters& c : light_counters) tot.light.add(c);
  for (const FpmEyeCounters& c : eye_counters) tot.eye.add(c);
  stats.rays = tot.eye.rays;
  stats.light_rays = tot.light.light_rays;
  stats.details = to_json(tot, s);
  return stats;
}

}  // namespace bpm
