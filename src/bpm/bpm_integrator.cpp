#include "bpm/bpm_integrator.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdio>

#include "base/error.h"
#include "base/memory.h"
#include "bpm/accumulate.h"
#include "bpm/backward_maps.h"
#include "bpm/eye_pass.h"
#include "bpm/light_pass.h"
#include "bpm/masks.h"
#include "bpm/statistics.h"
#include "integrator/progressive.h"
#include "photons/emission_guide.h"

namespace bpm {
namespace {

void check(const BpmSettings& s) {
  if (s.diffuse_depth < 0 || s.diffuse_depth > 3) throw Error("bpm: diffuse depth must be in 0..3");
  if (!(s.k0 > 0) || !(s.k1 > 0)) throw Error("bpm: radius factors k0 and k1 must be positive");
  if (!(s.alpha > 0 && s.alpha < 1)) throw Error("bpm: alpha must be in (0, 1)");
  if (s.photons_per_iteration <= 0) throw Error("bpm: photons per iteration must be positive");
  if (s.emission_samples < 1 || s.emission_samples > 1024)
    throw Error("bpm: emission samples must be in 1..1024");
  if (!(s.radius >= 0) || !std::isfinite(s.radius)) throw Error("bpm: radius must not be negative");
}

// 1 / (value + floor) per pixel from the running means; the floor, a tenth of the image's mean
// value, keeps dark pixels from drawing every photon (relMSE adds 0.01 to r^2 for the same reason).
void update_pixel_weights(const std::vector<double>& sum, const std::vector<uint32_t>& count,
                          std::vector<float>* weight) {
  double total = 0;
  size_t seen = 0;
  for (size_t p = 0; p < sum.size(); ++p)
    if (count[p]) {
      total += sum[p] / count[p];
      ++seen;
    }
  // Nothing to weigh by (no estimate yet, or means that are not positive under --debias): no
  // weights, the same whatever was there before (a resumed render recomputes them).
  if (seen == 0 || !(total > 0)) {
    weight->clear();
    return;
  }
  const double floor = 0.1 * total / double(seen);
  weight->assign(sum.size(), float(1 / floor));
  for (size_t p = 0; p < sum.size(); ++p)
    if (count[p]) (*weight)[p] = float(1 / (std::max(0.0, sum[p] / count[p]) + floor));
}

// Memory (base/memory.h). Per pixel, what the eye pass (with the edges and near-edge marks of the
// disc probes, and the emission statistics with their copy at the end of a round), the masks and
// the emission guide keep.
constexpr double kPixelBytes = sizeof(Spectrum) + 2 * sizeof(float) + 4 * sizeof(uint8_t) +
                               sizeof(uint16_t) + sizeof(float) +
                               3 * sizeof(EmissionStats<double>) + sizeof(double) +
                               sizeof(uint32_t) + sizeof(float) + sizeof(uint16_t);

// What the extra emission samples cost against whole iterations (emission_sample_count), in rays:
// all the rays the iterations cast and the pixels they sampled, the extra emission samples and
// their rays.
struct EmissionCost {
  std::array<double, 4> v{};  // rays (the extra samples' included), pixels, samples, sample rays
  // What an iteration costs per pixel without extra samples over what one extra sample costs,
  // less one (at least 0); -1 while no extra sample has been taken (unknown).
  double ratio() const {
    const auto [rays, pixels, samples, sample_rays] = v;
    if (!(pixels > 0) || !(samples > 0) || !(sample_rays > 0)) return -1;
    return std::max(0.0, ((rays - sample_rays) / pixels) / (sample_rays / samples) - 1);
  }
};
// Per backward photon: the thread's list and the map's copy, its three fluxes (all, inner half,
// inner quarter) and hit flag, its references in the two trees (about two per tree where spheres
// overlap cells), and its place among its pixel's for the accumulation.
constexpr double kBackwardPhotonBytes = 2 * sizeof(BackwardPhoton) + 3 * sizeof(Spectrum) + 1 +
                                        4 * (sizeof(SphereRef) + sizeof(uint32_t)) +
                                        sizeof(uint32_t);

// What an iteration's maps take once built, with the light pass's per-photon arrays.
double maps_bytes(const BackwardMaps& maps, const LightPassParams& lp) {
  return double(maps.photons.capacity() * sizeof(BackwardPhoton) + maps.tree_bytes() +
                maps.first_bucket.capacity() * sizeof(uint32_t) +
                size_t(maps.bucket_count() + 1) * sizeof(uint32_t) +
                maps.photons.size() * (3 * sizeof(Spectrum) + 1) +
                lp.photon_materials.capacity() * sizeof(Material));
}

}  // namespace

RenderStats render_bpm(const LoadedScene& ls, const IntegratorOptions& opt,
                       const BpmSettings& settings, Film* film) {
  const size_t n_pixels = size_t(film->width()) * size_t(film->height());
  BpmSettings s = settings;
  s.photons_per_iteration = photons_for(settings, n_pixels);
  check(s);
  const RenderScene& scene = ls.scene;
  const CameraSampler camera(ls.camera, ls.filter, film->width(), film->height(), opt.seed);
  const float pixel_angle = std::sqrt(camera.camera().pixel_solid_angle());

  PixelMasks masks(film->width(), film->height(), tbb::this_task_arena::max_concurrency());
  EyePixels eye(n_pixels);
  tbb::enumerable_thread_specific<ObjectPhotonLists> thread_lists(
      [&] { return ObjectPhotonLists(scene.objects.size()); });
  EyeCounters eye_exemplar;
  eye_exemplar.rays.observer = opt.eye_ray_observer;
  tbb::enumerable_thread_specific<EyeCounters> eye_counters(eye_exemplar);
  BackwardMaps maps;
  LightPassBuffers light;
  LightPassResult light_result;  // of the last light pass; its arrays are reused
  PixelSums pixel_sums;
  pixel_sums.places = s.diffuse_depth + 2;
  LightCounters light_exemplar;
  light_exemplar.observer = opt.light_ray_observer;
  light.counters = tbb::enumerable_thread_specific<LightCounters>(light_exemplar);
  BpmTotals tot;
  // Guided emission learns from each iteration's photons, scored relative to the pixels they
  // reach; the pixels' values are the running means of their estimates. Both change at the end
  // of a round (integrator/control.h): estimate_new holds the round's sums and counts until then.
  EmissionGuide guide = s.guide_emission ? EmissionGuide(scene) : EmissionGuide();
  std::vector<double> estimate_sum(n_pixels, 0.0), estimate_new(2 * n_pixels, 0.0);
  std::vector<uint32_t> estimate_count(n_pixels, 0);
  std::vector<float> pixel_weight;

  // An eye path leaves at most D + 2 backward photons (two at x_1 when D = 0, one at each other
  // diffuse vertex): the worst iteration must fit the memory budget before the first one starts.
  // The light pass holds the hits of a group of photons, and its entries get what the film, the
  // actual maps and those hits leave (applied in more rounds).
  const std::string size = std::to_string(film->width()) + "x" + std::to_string(film->height());
  const std::string advice =
      "lower --resolution or --diffuse-depth (or the radii: --k0, --k1, --radius), or raise "
      "--memory";
  const double fixed_bytes =
      double(film->bytes()) + double(n_pixels) * kPixelBytes +
      light_pass_hit_bytes(opt.max_depth, tbb::this_task_arena::max_concurrency(),
                           n_pixels * size_t(s.diffuse_depth + 2));
  check_memory("bpm at " + size + " with diffuse depth " + std::to_string(s.diffuse_depth) +
                   " (up to " + std::to_string(s.diffuse_depth + 2) +
                   " backward photons per pixel and iteration)",
               fixed_bytes + double(n_pixels) * (s.diffuse_depth + 2) * kBackwardPhotonBytes,
               opt.memory_budget, advice);

  // In a scene where no light path can be a caustic, the backward photons that accept only
  // caustics (half of them at D = 0) would gather nothing: they are not made.
  const bool caustics = may_have_caustics(scene);

  // Disc probes at first vertices near edges only (photons/disc_probes.h); with a radius in world
  // units the radii on screen are unknown, and every disc is probed.
  NearEdges near_edges(s.disc_probes && s.radius <= 0, scene, camera.camera(), ls.film.width,
                       ls.film.height, ls.filter.radius);

  auto iteration = [&](int pass, const RenderControl& control) {
    const int it = opt.first_iteration + pass;  // the index random streams and radii follow
    const float scale = radius_scale(s, it);
    // One set of wavelengths for every eye and light path of the iteration.
    const WavelengthMaterials wm(scene, iteration_wavelengths(opt.seed, it));

    // 1. Eye pass: backward photons, and the light the eye paths count themselves.
    auto t = Clock::now();
    EyePassParams ep{&wm,
                     s.diffuse_depth,
                     opt.max_depth,
                     s.k0 * pixel_angle * scale,
                     s.k1 * pixel_angle * scale,
                     s.emission_samples,
                     s.radius * scale,
                     caustics,
                     s.normal_cos,
                     s.disc_probes,
                     &near_edges};
    // Where the first vertices' discs are probed: near edges, within this iteration's radii.
    near_edges.mark(s.k0 * scale, s.k1 * scale);
    bool complete = run_eye_pass(scene, ep, camera, masks, control, pass, it, &eye,
                                 {thread_lists, eye_counters});
    tot.eye_s += since(t);
    // An eye pass cut short (an interrupt, or the time budget after the first iteration) leaves
    // pixels without their estimate: the iteration is dropped.
    if (!complete) return PassResult{false, 0, "", ""};

    // 2. Per-object sphere trees over the backward photons.
    t = Clock::now();
    std::vector<ObjectPhotonLists*> lists;
    for (ObjectPhotonLists& l : thread_lists) lists.push_back(&l);
    build_backward_maps(lists, scene.objects.size(), s.centre_tree, &maps);
    LightPassParams lp{&wm, opt.max_depth, s.normal_cos, {}};
    // The time budget holds inside an iteration: its light pass ends early with the photons
    // traced so far (the iteration is still a complete estimate, only noisier).
    lp.stop = [&] { return control.stop_requested(); };
    resolve_photon_materials(maps, &lp);
    if (!guide.empty() && !pixel_weight.empty()) lp.pixel_weight = &pixel_weight;
    if (opt.memory_budget > 0) {
      // The eye pass's lists keep their memory for the next iteration: a second copy of the
      // backward photons (counted by their number, not the lists' capacities, which depend on
      // how the threads shared the pixels: a budget decision must not).
      const double list_bytes = double(maps.photons.size() * sizeof(BackwardPhoton));
      const double used = fixed_bytes + maps_bytes(maps, lp) + list_bytes;
      // Over the budget (the estimate before the first iteration assumed typical trees and no
      // textured materials): an error in the first iteration, which has nothing to keep; later,
      // the render ends with the iterations so far and says why.
      if (used > double(opt.memory_budget)) {
        if (pass == 0)
          check_memory("bpm's backward photons and trees at " + size, used, opt.memory_budget,
                       advice);
        tot.build_s += since(t);
        return PassResult{false, 0, "", "memory"};
      }
      lp.entry_bytes_limit = std::max<size_t>(1, size_t(double(opt.memory_budget) - used));
    }
    tot.build_s += since(t);
    tot.add_maps(maps);

    // 3. Light pass: a fixed number of photons, in groups.
    run_light_pass(scene, maps, lp, s, masks, opt.seed, it, &light,
                   guide.empty() ? nullptr : &guide, &light_result);
    // Its time counts even if the iteration is dropped below: its rays reach the counters.
    tot.add_light_pass_time(light_result);
    // The film averages iterations with equal weights, so an iteration the budget cut to a share
    // f of its photons adds variance ~ 1/f to a mean of n: with n - 1 whole ones, keeping it
    // helps only when ((n - 1) + 1/f) / n^2 < 1 / (n - 1), about f > 1/2. A later iteration with
    // less than half its photons is dropped; the first is always kept (an image needs one).
    if (light_result.cut && pass > 0 &&
        2 * light_result.emitted < uint64_t(s.photons_per_iteration))
      return PassResult{false, 0, "", ""};
    tot.add_light_pass(light_result);

    // 4. Accumulation of the iteration into the film; masks balanced for the next one.
    t = Clock::now();
    accumulate_iteration(maps, &light_result, &eye, wm.wl, ls.film.max_component_value, s, film,
                         &pixel_sums, guide.empty() ? nullptr : &estimate_new);
    tot.accumulate_s += since(t);
    masks.rebuild(eye.cost_ns);

    PassResult r;
    for (const EyeCounters& c : eye_counters) r.rays += c.rays.total();
    for (const LightCounters& c : light.counters) r.rays += c.light_rays;
    char progress[128];
    std::snprintf(progress, sizeof progress, "  %zu backward photons  coverage %.2f%s",
                  maps.photons.size(), light_result.coverage,
                  light_result.cut ? "  (light pass cut short by the budget)" : "");
    r.progress = progress;
    return r;
  };
  // Carried from one iteration to the next, and merged at the end of each round: the pixels'
  // emission statistics and what their extra samples cost (their sample counts follow from them),
  // what the guide learnt and the pixels' running means (the pixel weights follow from them).
  EmissionCost cost_sum, cost_new, counted;  // counted: the counters' totals at the last round
  // The round's costs so far: cost_new (kept from a checkpoint or another process's share) and
  // what the counters added since the last round.
  auto round_cost = [&] {
    EmissionCost now, round = cost_new;
    for (const EyeCounters& c : eye_counters) {
      now.v[0] += double(c.rays.total());
      now.v[1] += double(c.pixels);
      now.v[2] += double(c.emission_samples);
      now.v[3] += double(c.emission_rays);
    }
    for (const LightCounters& c : light.counters) now.v[0] += double(c.light_rays);
    for (size_t k = 0; k < now.v.size(); ++k) round.v[k] += now.v[k] - counted.v[k];
    return std::pair{round, now};
  };
  auto set_emission_samples = [&] {
    const double ratio = cost_sum.ratio();
    for (size_t p = 0; p < n_pixels; ++p)
      eye.emission_samples[p] =
          eye.sees_emission[p]
              ? uint16_t(emission_sample_count(eye.emission_stats[p], ratio, s.emission_samples))
              : 1;
  };
  IntegratorState state;
  state.learnt = [&](std::vector<double>* out) {
    for (uint8_t& saw : eye.saw_emission) {
      out->push_back(saw);
      saw = 0;
    }
    for (EmissionStats<double>& st : eye.round_stats) {
      out->insert(out->end(), st.v.begin(), st.v.end());
      st = {};
    }
    const auto [round, now] = round_cost();
    out->insert(out->end(), round.v.begin(), round.v.end());
    counted = now;
    cost_new = {};
    if (guide.empty()) return;
    guide.take_learnt(out);
    out->insert(out->end(), estimate_new.begin(), estimate_new.end());
    std::fill(estimate_new.begin(), estimate_new.end(), 0.0);
  };
  constexpr size_t kStats = EmissionStats<double>::kValues;
  const size_t pixel_values = (1 + kStats) * n_pixels + EmissionCost().v.size();
  state.merge = [&](const std::vector<double>& sums) {
    // Rounded to float before they join, as the guide's sums below.
    const double* stats = sums.data() + n_pixels;
    for (size_t p = 0; p < n_pixels; ++p) {
      std::array<double, kStats>& st = eye.emission_stats[p].v;
      for (size_t k = 0; k < kStats; ++k) st[k] += double(float(stats[kStats * p + k]));
      if (sums[p] > 0) eye.sees_emission[p] = 1;
    }
    const double* c = stats + kStats * n_pixels;
    for (size_t k = 0; k < cost_sum.v.size(); ++k) cost_sum.v[k] += double(float(c[k]));
    set_emission_samples();
    if (guide.empty()) return;
    // A round's sums are rounded to float precision before they join: processes add their
    // shares in another order than one process adds passes, and a difference in the last bits
    // of a sum would move a boundary of the guided density, so that the same seed would draw
    // other photons.
    std::vector<double> learnt(sums.size() - pixel_values);
    for (size_t i = 0; i < learnt.size(); ++i) learnt[i] = double(float(sums[pixel_values + i]));
    guide.merge(learnt.data());
    tot.guide_moved = guide.moved();
    const double* e = learnt.data() + 2 * guide.cells();
    for (size_t p = 0; p < n_pixels; ++p) {
      estimate_sum[p] += e[2 * p];
      estimate_count[p] += uint32_t(e[2 * p + 1]);
    }
    update_pixel_weights(estimate_sum, estimate_count, &pixel_weight);
  };
  state.keep_learnt = [&](const std::vector<double>& sums) {
    const double* stats = sums.data() + n_pixels;
    for (size_t p = 0; p < n_pixels; ++p) {
      eye.saw_emission[p] = sums[p] > 0;
      std::copy_n(stats + kStats * p, kStats, eye.round_stats[p].v.begin());
    }
    const double* c = stats + kStats * n_pixels;
    std::copy_n(c, cost_new.v.size(), cost_new.v.begin());
    if (guide.empty()) return;
    guide.keep_learnt(sums.data() + pixel_values);
    const double* e = sums.data() + pixel_values + 2 * guide.cells();
    estimate_new.assign(e, e + 2 * n_pixels);
  };
  state.save = [&](ByteWriter& w) {
    w.put_vector(eye.sees_emission);
    w.put_vector(eye.saw_emission);
    w.put_vector(eye.emission_stats);
    w.put_vector(eye.round_stats);
    w.put(cost_sum.v);
    w.put(round_cost().first.v);  // the counters start from zero when the render goes on
    w.put(uint8_t(!guide.empty()));
    if (guide.empty()) return;
    guide.save(w);
    w.put_vector(estimate_sum);
    w.put_vector(estimate_count);
    w.put_vector(estimate_new);
  };
  state.load = [&](ByteReader& r) {
    eye.sees_emission = r.get_vector<uint8_t>();
    eye.saw_emission = r.get_vector<uint8_t>();
    eye.emission_stats = r.get_vector<EmissionStats<double>>();
    eye.round_stats = r.get_vector<EmissionStats<double>>();
    if (eye.sees_emission.size() != n_pixels || eye.saw_emission.size() != n_pixels ||
        eye.emission_stats.size() != n_pixels || eye.round_stats.size() != n_pixels)
      throw Error(r.what() + " is truncated or corrupt (pixels that see emission)");
    cost_sum.v = r.get<std::array<double, 4>>();
    cost_new.v = r.get<std::array<double, 4>>();
    // The counters start again from zero.
    counted = {};
    set_emission_samples();
    if (r.get<uint8_t>() != uint8_t(!guide.empty()))
      throw Error(r.what() + " differs in guided emission (--no-guide)");
    if (guide.empty()) return;
    guide.load(r);
    estimate_sum = r.get_vector<double>();
    estimate_count = r.get_vector<uint32_t>();
    estimate_new = r.get_vector<double>();
    if (estimate_sum.size() != n_pixels || estimate_count.size() != n_pixels ||
        estimate_new.size() != 2 * n_pixels)
      throw Error(r.what() + " is truncated or corrupt (pixel estimates)");
    update_pixel_weights(estimate_sum, estimate_count, &pixel_weight);
  };
  RenderStats stats;
  run_passes(opt, film, "iteration", iteration, &stats, state);
  for (const EyeCounters& c : eye_counters) tot.eye.add(c);
  for (const LightCounters& c : light.counters) tot.light.add(c);
  stats.rays = tot.eye.rays;
  stats.light_rays = tot.light.light_rays;
  stats.details = to_json(tot, s, stats.passes, n_pixels);
  return stats;
}

}  // namespace bpm
