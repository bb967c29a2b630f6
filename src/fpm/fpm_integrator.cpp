#include "fpm/fpm_integrator.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "base/error.h"
#include "base/memory.h"
#include "fpm/eye_paths.h"
#include "fpm/photon_maps.h"
#include "integrator/progressive.h"
#include "photons/disc_probes.h"
#include "photons/medium_radius.h"

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

// One render of fpm: what its iterations share. iteration() reads as the algorithm, one method a
// stage: light pass, maps, eye pass.
class FpmRender {
 public:
  FpmRender(const LoadedScene& ls, const IntegratorOptions& opt, const FpmSettings& settings,
            Film* film);
  PassResult iteration(int pass, const RenderControl& control);
  // The sensors' estimates of the last iteration, into the film (IntegratorOptions::sensor_pass).
  void record_sensors(Film* film) const { sensor_sums_.record(film); }
  // The render's statistics once run_passes has filled `stats`.
  RenderStats finish(RenderStats stats);

 private:
  // The three stages of an iteration. light_pass returns false when the iteration is dropped.
  bool light_pass(const WavelengthMaterials& wm, int pass, int it, const RenderControl& control);
  void build_maps();
  void eye_pass(const WavelengthMaterials& wm, int pass, int it, const RenderControl& control);
  // Adds a pixel's estimate (and its bias) to the film.
  void record(uint32_t pixel, const FpmEyeRadiance& r, const CameraSample& cs,
              const WavelengthMaterials& wm);
  PassResult progress() const;
  // Fits the photon count to the memory budget and checks that the worst iteration fits; returns
  // the photons per iteration.
  uint64_t reserve_memory(const FpmSettings& settings);

  const LoadedScene& ls_;
  const RenderScene& scene_;
  const IntegratorOptions& opt_;
  FpmSettings s_;  // photons_per_iteration as reserve_memory fitted it
  Film* film_;
  const CameraSampler camera_;
  const int min_eye_vertices_;
  const uint64_t n_photons_;
  // Disc probes at vertices seen directly near edges only (photons/disc_probes.h).
  NearEdges near_edges_;
  ForwardMaps maps_;
  tbb::enumerable_thread_specific<LightCounters> light_counters_;
  tbb::enumerable_thread_specific<FpmEyeCounters> eye_counters_;
  FpmTotals tot_;
  uint64_t emitted_ = 0;  // photons the last light pass emitted
  // Illuminance sensors, when the render has them (photons/sensor_discs.h).
  std::unique_ptr<SensorDiscs> sensors_;
  SensorIteration sensor_sums_;
  float medium_min_length_;  // photons/medium_radius.h
};

FpmSettings checked_settings(const FpmSettings& settings, size_t n_pixels) {
  FpmSettings s = settings;
  s.photons_per_iteration = photons_for(settings, n_pixels);
  if (!(s.k0 > 0) || !(s.k1 > 0)) throw Error("fpm: --k0 and --k1 (file: k0, k1) must be positive");
  if (s.photons_per_iteration <= 0)
    throw Error("fpm: --photons (file: photonsperiteration) must be positive");
  if (s.knn < 0) throw Error("fpm: --knn (file: knn) must not be negative");
  s.radius_policy = fpm_radius_policy(s.radius_policy);
  return s;
}

FpmRender::FpmRender(const LoadedScene& ls, const IntegratorOptions& opt,
                     const FpmSettings& settings, Film* film)
    : ls_(ls),
      scene_(ls.scene),
      opt_(opt),
      s_(checked_settings(settings, size_t(film->width()) * size_t(film->height()))),
      film_(film),
      camera_(ls.camera, ls.filter, ls.film.raster_for(film->width(), film->height()), opt.seed),
      min_eye_vertices_(s_.final_gather ? 2 : 1),
      n_photons_(reserve_memory(settings)),
      near_edges_(s_.disc_probes, scene_, camera_.camera(), film->width(), film->height(),
                  ls.filter.radius),
      sensors_(make_sensor_discs(scene_, opt.sensors, camera_.camera(), s_)),
      sensor_sums_(opt.sensors.size()),
      medium_min_length_(
          scene_.has_scattering_media()
              ? median_surface_distance(scene_, camera_.camera(), film->width(), film->height())
              : 0) {}

// Memory (base/memory.h): a photon is stored at most once per diffuse hit that still leaves room
// for the eye vertices, plus one caustic copy; each stored photon is in its chunk's list, in the
// joined map and in the tree. The worst iteration must fit the budget before the first one. Per
// pixel, beside the film: the disc probes' edges and near-edge marks.
uint64_t FpmRender::reserve_memory(const FpmSettings& settings) {
  const double fixed_bytes = double(film_->bytes()) + 2.0 * film_->width() * film_->height();
  const double stored_per_photon = std::max(0, opt_.max_depth - min_eye_vertices_ + 1) + 1;
  const double photon_bytes =
      2 * sizeof(ForwardPhoton) + 2 * (sizeof(SphereRef) + sizeof(uint32_t));
  // The map holds a whole iteration's photons: the automatic count takes no more than the budget
  // holds at worst (but never fewer than 100000, which fail as a count set would).
  if (settings.photons_per_iteration == 0 && opt_.memory_budget > 0) {
    const double fit =
        (double(opt_.memory_budget) - fixed_bytes) / (stored_per_photon * photon_bytes);
    s_.photons_per_iteration = int(std::clamp(fit, 100000.0, double(s_.photons_per_iteration)));
  }
  const uint64_t n_photons = uint64_t(s_.photons_per_iteration);
  check_memory("fpm with " + std::to_string(n_photons) + " photons per iteration and maxdepth " +
                   std::to_string(opt_.max_depth) + " (up to " +
                   std::to_string(int(stored_per_photon)) + " stored per photon)",
               fixed_bytes + double(n_photons) * stored_per_photon * photon_bytes,
               opt_.memory_budget, "lower --photons or --maxdepth, or raise --memory");
  return n_photons;
}

PassResult FpmRender::iteration(int pass, const RenderControl& control) {
  const int it = opt_.first_iteration + pass;  // the index random streams and radii follow
  // One set of wavelengths for every eye and light path of the iteration.
  const WavelengthMaterials wm(scene_, iteration_wavelengths(opt_.seed, it, ls_.film.spectral));
  if (!opt_.image && !may_have_caustics(scene_)) {
    // Sensors alone in a scene without caustics: the photons would add nothing, the paths from
    // the sensors find everything.
    sensor_sums_.clear();
    sensor_sums_.finish(scene_, *sensors_, opt_.max_depth, s_.bias_model, opt_.seed, it, 0);
    return progress();
  }
  // 1. Light pass: a forward photon at every diffuse hit (and the sensors' crossings).
  if (!light_pass(wm, pass, it, control)) return PassResult{false, 0, "", ""};
  if (sensors_) {
    sensor_sums_.clear();
    for (const ForwardMaps::Chunk& ch : maps_.chunks) sensor_sums_.add(ch.crossings);
    sensor_sums_.finish(scene_, *sensors_, opt_.max_depth, s_.bias_model, opt_.seed, it, emitted_);
  }
  if (!opt_.image) return progress();
  // 2. The maps, in chunk order (the same for any thread count), and their trees.
  build_maps();
  // 3. Eye pass.
  eye_pass(wm, pass, it, control);
  return progress();
}

bool FpmRender::light_pass(const WavelengthMaterials& wm, int pass, int it,
                           const RenderControl& control) {
  const auto t = Clock::now();
  // The time budget holds inside an iteration: the light pass may end early, with fewer photons.
  if (sensors_) sensors_->set_scale(radius_scale(s_, it));
  emitted_ = trace_forward_photons(
      scene_, wm, opt_.max_depth, min_eye_vertices_, n_photons_, opt_.seed, it, light_counters_,
      [&] { return control.stop_requested(); }, &maps_, sensors_.get());
  tot_.light_s += since(t);
  // After the first iteration, an eye pass would be cut at once: the iteration is dropped.
  if (control.cut(pass)) return false;
  if (emitted_ < n_photons_) ++tot_.iterations_cut;
  tot_.emitted += emitted_;
  return true;
}

void FpmRender::build_maps() {
  const auto t = Clock::now();
  build_forward_maps(&maps_);
  tot_.stored +=
      maps_.global.photons.size();  // every photon once; the caustic map holds copies of some
  tot_.stored_caustic += maps_.caustic.photons.size();
  tot_.build_s += since(t);
  tot_.peak_map_bytes =
      std::max(tot_.peak_map_bytes, maps_.global.photon_bytes() + maps_.caustic.photon_bytes());
  tot_.peak_tree_bytes =
      std::max(tot_.peak_tree_bytes, maps_.global.tree.bytes() + maps_.caustic.tree.bytes());
}

void FpmRender::eye_pass(const WavelengthMaterials& wm, int pass, int it,
                         const RenderControl& control) {
  const auto t = Clock::now();
  float scale = radius_scale(s_, it);
  near_edges_.mark(s_.k0 * scale, s_.k1 * scale);
  FpmEyeParams ep{&wm,
                  &s_,
                  opt_.max_depth,
                  s_.k0 * scale,
                  s_.k1 * scale,
                  double(emitted_),
                  medium_min_length_,
                  opt_.equiangular};
  for_each_sampled_pixel(film_->width(), film_->height(), control, pass, [&](uint32_t pixel) {
    CameraSample cs = camera_.sample(it, pixel);
    const FpmEyeRadiance r = fpm_eye_radiance(scene_, maps_, ep, cs.camera_ray(), cs.footprint,
                                              cs.rng, eye_counters_.local(), near_edges_.at(pixel));
    record(pixel, r, cs, wm);
  });
  tot_.eye_s += since(t);
}

void FpmRender::record(uint32_t pixel, const FpmEyeRadiance& r, const CameraSample& cs,
                       const WavelengthMaterials& wm) {
  if (s_.debias) {
    record_pass(film_, pixel, r.L - r.bias, wm.wl, cs.filter_weight, ls_.film.max_component_value,
                true);
    return;
  }
  if (r.bias.is_finite() && cs.filter_weight != 0 && recordable(r.L))
    film_->add_bias(int(pixel % uint32_t(film_->width())), int(pixel / uint32_t(film_->width())),
                    film_->rgb_of(r.bias, wm.wl), spectrum_to_luminance(r.bias, wm.wl));
  record_pass(film_, pixel, r.L, wm.wl, cs.filter_weight, ls_.film.max_component_value);
}

PassResult FpmRender::progress() const {
  PassResult r;
  for (const FpmEyeCounters& c : eye_counters_) r.rays += c.rays.total();
  for (const LightCounters& c : light_counters_) r.rays += c.light_rays;
  char progress[64];
  std::snprintf(progress, sizeof progress, "  %zu photons stored", maps_.global.photons.size());
  r.progress = progress;
  return r;
}

RenderStats FpmRender::finish(RenderStats stats) {
  for (const LightCounters& c : light_counters_) tot_.light.add(c);
  for (const FpmEyeCounters& c : eye_counters_) tot_.eye.add(c);
  stats.rays = tot_.eye.rays;
  stats.light_rays = tot_.light.light_rays;
  stats.details = to_json(tot_, s_);
  return stats;
}

}  // namespace

RenderStats render_fpm(const LoadedScene& ls, const IntegratorOptions& opt,
                       const FpmSettings& settings, Film* film) {
  IntegratorOptions o = opt;
  FpmRender fpm(ls, o, settings, film);
  if (!opt.sensors.empty()) o.sensor_pass = [&fpm](int, Film* f) { fpm.record_sensors(f); };
  RenderStats stats;
  run_passes(
      o, film, "iteration",
      [&fpm](int pass, const RenderControl& control) { return fpm.iteration(pass, control); },
      &stats);
  return fpm.finish(stats);
}

}  // namespace bpm
