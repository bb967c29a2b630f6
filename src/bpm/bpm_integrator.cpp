#include "bpm/bpm_integrator.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cstdio>
#include <limits>

#include "base/error.h"
#include "bpm/backward_maps.h"
#include "bpm/eye_pass.h"
#include "bpm/light_pass.h"
#include "bpm/masks.h"
#include "camera/camera.h"
#include "render/control.h"

namespace bpm {

float radius_scale(const BpmSettings& s, int iteration) {
  if (s.radius_policy == RadiusPolicy::kFixed) return 1;
  // r_(i+1)^2 = r_i^2 (i + alpha) / (i + 1), i counted from 1 (Knaus & Zwicker 2011, eq. 20).
  double r2 = 1;
  for (int i = 1; i <= iteration; ++i) r2 *= (i + double(s.alpha)) / (i + 1);
  return float(std::sqrt(r2));
}

namespace {


// Domain separation of photon streams from pixel streams.
constexpr uint64_t kPhotonStream = 0x70686f746f6e73ull;

struct BpmTotals {
  EyeCounters eye;
  LightCounters light;
  uint64_t backward_rays = 0;
  size_t peak_photon_bytes = 0, peak_tree_bytes = 0, peak_entry_bytes = 0;
  double eye_s = 0, build_s = 0, light_trace_s = 0, light_apply_s = 0, accumulate_s = 0;
  uint64_t batches = 0;
  double coverage_sum = 0, last_coverage = 0;
  double duplication_sum = 0;
  int duplication_n = 0;
};

nlohmann::json to_json(const BpmTotals& t, const BpmSettings& s, int iterations, size_t pixels) {
  uint64_t backward_rays = t.eye.rays.camera_rays + t.eye.rays.bounce_rays;
  double light_s = t.light_trace_s + t.light_apply_s;
  return {
      {"settings",
       {{"diffuse_depth", s.diffuse_depth},
        {"k0", s.k0},
        {"k1", s.k1},
        {"radius_policy", to_string(s.radius_policy)},
        {"alpha", s.alpha},
        {"photons_per_batch", s.photons_per_batch},
        {"coverage_target", s.coverage},
        {"max_batches", s.max_batches},
        {"normal_cos", s.normal_cos},
        {"tree", s.centre_tree ? "centres" : "spheres"}}},
      {"eye",
       {{"camera_rays", t.eye.rays.camera_rays},
        {"bounce_rays", t.eye.rays.bounce_rays},
        {"shadow_rays", t.eye.rays.shadow_rays},
        {"backward_photons", t.eye.backward_photons},
        // The paper's Table 1 counts per ray traced from the camera with all its continuations
        // (an eye path); per segment counts every camera and bounce ray.
        {"backward_photons_per_backward_ray",
         t.eye.rays.camera_rays ? double(t.eye.backward_photons) / double(t.eye.rays.camera_rays) : 0.0},
        {"backward_photons_per_backward_segment", backward_rays ? double(t.eye.backward_photons) / backward_rays : 0.0},
        {"backward_photons_per_pixel_iteration",
         iterations && pixels ? double(t.eye.backward_photons) / (double(iterations) * pixels) : 0.0},
        {"rays_per_second", t.eye_s > 0 ? double(t.eye.rays.total()) / t.eye_s : 0.0}}},
      {"maps",
       {{"peak_photon_bytes", t.peak_photon_bytes},
        {"peak_tree_bytes", t.peak_tree_bytes},
        {"peak_entry_bytes", t.peak_entry_bytes},
        {"backward_photon_bytes_each", sizeof(BackwardPhoton)},
        {"tree_build_s", t.build_s},
        {"mean_sphere_duplication", t.duplication_n ? t.duplication_sum / t.duplication_n : 0.0}}},
      {"light",
       {{"photons", t.light.photons},
        {"light_rays", t.light.light_rays},
        {"diffuse_hits", t.light.diffuse_hits},
        {"queries", t.light.queries},
        {"queries_per_second", t.light_trace_s > 0 ? double(t.light.queries) / t.light_trace_s : 0.0},
        {"entries", t.light.entries},
        {"batches", t.batches},
        {"batches_per_iteration", iterations ? double(t.batches) / iterations : 0.0},
        {"coverage_mean", iterations ? t.coverage_sum / iterations : 0.0},
        {"coverage_last", t.last_coverage},
        {"rays_per_second", light_s > 0 ? double(t.light.light_rays) / light_s : 0.0}}},
      {"stages_s",
       {{"eye", t.eye_s},
        {"tree_build", t.build_s},
        {"light_trace", t.light_trace_s},
        {"light_apply", t.light_apply_s},
        {"accumulate", t.accumulate_s}}},
  };
}

}  // namespace

RenderStats render_bpm(const LoadedScene& ls, const RenderOptions& opt, Film* film) {
  const BpmSettings& s = opt.bpm;
  if (s.diffuse_depth < 0 || s.diffuse_depth > 3) throw Error("bpm: diffuse depth must be in 0..3");
  if (!(s.k0 > 0) || !(s.k1 > 0)) throw Error("bpm: radius factors k0 and k1 must be positive");
  if (!(s.alpha > 0 && s.alpha < 1)) throw Error("bpm: alpha must be in (0, 1)");
  if (s.photons_per_batch <= 0 || s.max_batches <= 0) throw Error("bpm: photons per batch and batch cap must be positive");
  if (!(s.coverage >= 0 && s.coverage <= 1)) throw Error("bpm: coverage must be in [0, 1]");

  std::unique_ptr<tbb::global_control> limit;
  if (opt.threads > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, opt.threads);
  const int threads = tbb::this_task_arena::max_concurrency();
  const int w = film->width(), h = film->height();
  const size_t n_pixels = size_t(w) * h;
  const RenderScene& scene = ls.scene;
  PerspectiveCamera camera(ls.camera, w, h);
  Filter filter(ls.filter);
  const float max_value = ls.film.max_component_value;
  const float pixel_angle = std::sqrt(camera.pixel_solid_angle());

  PixelMasks masks(w, h, threads);
  std::vector<Spectrum> eye_L(n_pixels), photon_L(n_pixels);
  std::vector<float> weight(n_pixels), cost(n_pixels);
  tbb::enumerable_thread_specific<ObjectPhotonLists> thread_lists(
      [&] { return ObjectPhotonLists(scene.objects.size()); });
  tbb::enumerable_thread_specific<EyeCounters> eye_counters;
  tbb::enumerable_thread_specific<LightCounters> light_counters;
  struct Chunk {
    std::vector<std::vector<PhotonEntry>> by_slot;
  };
  BackwardMaps maps;
  BpmTotals tot;
  RenderStats stats;
  const uint64_t photons_per_batch = uint64_t(s.photons_per_batch);
  const int chunks_per_batch = int((photons_per_batch + kPhotonsPerChunk - 1) / kPhotonsPerChunk);
  std::vector<Chunk> chunks(chunks_per_batch);

  RenderControl control(opt, *film, "iteration");
  std::vector<uint8_t> sampled(n_pixels, 0);
  for (int iter = 0; control.keep_going(iter); ++iter) {
    const int it = opt.first_iteration + iter;  // the index random streams and radii follow
    // ---- 1. eye pass, block by block, each slot over its mask ----
    auto t_stage = Clock::now();
    float scale = radius_scale(s, it);
    // One set of wavelengths for every eye and light path of the iteration.
    const WavelengthMaterials wm(scene, iteration_wavelengths(opt.seed, it));
    EyePassParams ep{&wm, s.diffuse_depth, opt.max_depth, s.k0 * pixel_angle * scale, s.k1 * pixel_angle * scale};
    LightPassParams lp{&wm, opt.max_depth, s.normal_cos, {}};
    const int slots = masks.slots();
    tbb::parallel_for(tbb::blocked_range<int>(0, masks.block_count() * slots, 1), [&](const tbb::blocked_range<int>& r) {
      ObjectPhotonLists& lists = thread_lists.local();
      EyeCounters& ec = eye_counters.local();
      for (int task = r.begin(); task < r.end(); ++task) {
        if (interrupt_flag().load(std::memory_order_relaxed)) return;
        for (uint32_t pixel : masks.pixels(task / slots, task % slots)) {
          sampled[pixel] = control.sample_pixel(iter, pixel);
          if (!sampled[pixel]) {
            cost[pixel] = 0;
            continue;
          }
          auto tp = Clock::now();
          int x = int(pixel % w), y = int(pixel / w);
          Rng rng(stream_key(opt.seed, uint64_t(it), pixel));
          FilterSample fs = filter.sample({rng.uniform(), rng.uniform()});
          Vec2 p_film{x + 0.5f + fs.offset.x, y + 0.5f + fs.offset.y};
          Ray ray = camera.generate_ray(p_film, {rng.uniform(), rng.uniform()});
          eye_L[pixel] = trace_eye_path(scene, ep, ray, pixel, rng, lists, ec);
          weight[pixel] = fs.weight;
          photon_L[pixel] = Spectrum();
          cost[pixel] = float(std::chrono::duration<double, std::nano>(Clock::now() - tp).count());
        }
      }
    });
    tot.eye_s += since(t_stage);
    if (interrupt_flag().load()) {
      // An iteration without its light pass would be a wrong image: drop it.
      for (ObjectPhotonLists& l : thread_lists)
        for (auto& v : l) v.clear();
      break;
    }

    // ---- 2. per-object trees ----
    t_stage = Clock::now();
    std::vector<ObjectPhotonLists*> lists;
    for (ObjectPhotonLists& l : thread_lists) lists.push_back(&l);
    build_backward_maps(lists, scene.objects.size(), s.centre_tree, &maps);
    resolve_photon_materials(maps, &lp);
    tot.build_s += since(t_stage);
    tot.peak_photon_bytes = std::max(tot.peak_photon_bytes, maps.photon_bytes());
    tot.peak_tree_bytes = std::max(tot.peak_tree_bytes, maps.tree_bytes());
    if (!s.centre_tree) {
      size_t in = 0, stored = 0;
      for (size_t o = 0; o < scene.objects.size(); ++o) {
        size_t n = maps.object_begin[o + 1] - maps.object_begin[o];
        in += n;
        stored += maps.sphere_trees[o].reference_count();
      }
      if (in) {
        tot.duplication_sum += double(stored) / double(in);
        ++tot.duplication_n;
      }
    }

    // ---- 3. light pass in batches until the backward photons are covered ----
    const size_t n_bp = maps.photons.size();
    std::vector<Spectrum> acc(n_bp);
    std::vector<uint8_t> hit(n_bp, 0);
    size_t n_indirect = 0;
    for (const BackwardPhoton& bp : maps.photons) n_indirect += (bp.accepts & kAcceptsIndirect) != 0;
    uint64_t emitted = 0;
    double coverage = n_indirect ? 0.0 : 1.0;
    for (int batch = 0; batch < s.max_batches; ++batch) {
      t_stage = Clock::now();
      tbb::parallel_for(tbb::blocked_range<int>(0, chunks_per_batch, 1), [&](const tbb::blocked_range<int>& r) {
        LightCounters& lc = light_counters.local();
        for (int c = r.begin(); c < r.end(); ++c) {
          Chunk& ch = chunks[c];
          ch.by_slot.resize(slots);
          for (auto& v : ch.by_slot) v.clear();
          uint64_t first = uint64_t(c) * kPhotonsPerChunk;
          uint64_t last = std::min(first + kPhotonsPerChunk, photons_per_batch);
          for (uint64_t k = first; k < last; ++k) {
            uint64_t index = uint64_t(batch) * photons_per_batch + k;
            Rng rng(stream_key(opt.seed ^ kPhotonStream, uint64_t(it), index, 1));
            trace_photon(scene, maps, lp, masks.owner(), rng, ch.by_slot, lc);
          }
        }
      });
      emitted += photons_per_batch;
      ++tot.batches;
      tot.light_trace_s += since(t_stage);
      size_t entry_bytes = 0;
      for (const Chunk& ch : chunks)
        for (const auto& v : ch.by_slot) entry_bytes += v.capacity() * sizeof(PhotonEntry);
      tot.peak_entry_bytes = std::max(tot.peak_entry_bytes, entry_bytes);

      // Phase two: each slot applies the entries of its own pixels, chunk by chunk in order.
      t_stage = Clock::now();
      tbb::parallel_for(tbb::blocked_range<int>(0, slots, 1), [&](const tbb::blocked_range<int>& r) {
        for (int slot = r.begin(); slot < r.end(); ++slot)
          for (const Chunk& ch : chunks)
            for (const PhotonEntry& e : ch.by_slot[slot]) {
              acc[e.backward_photon] += e.value;
              hit[e.backward_photon] = 1;
            }
      });
      tot.light_apply_s += since(t_stage);
      if (n_indirect) {
        size_t covered = 0;
        for (size_t g = 0; g < n_bp; ++g) covered += hit[g] && (maps.photons[g].accepts & kAcceptsIndirect);
        coverage = double(covered) / double(n_indirect);
      }
      if (coverage >= s.coverage || interrupt_flag().load()) break;
    }
    tot.coverage_sum += coverage;
    tot.last_coverage = coverage;

    // ---- 4. accumulate the iteration: eye part plus photon part of every pixel ----
    t_stage = Clock::now();
    for (size_t g = 0; g < n_bp; ++g) {
      const BackwardPhoton& bp = maps.photons[g];
      if (acc[g].is_black()) continue;
      // eq. (2): L = tau * sum f dPhi / (pi r^2), with dPhi = flux / N emitted.
      photon_L[bp.pixel] += bp.tau * acc[g] * float(1.0 / (kPi * double(bp.radius) * bp.radius * double(emitted)));
    }
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& r) {
      for (int y = r.begin(); y < r.end(); ++y)
        for (int x = 0; x < w; ++x) {
          size_t p = size_t(y) * w + x;
          if (!sampled[p]) continue;
          film->add_sample(x, y, film_rgb(eye_L[p] + photon_L[p], wm.wl, max_value), weight[p]);
          film->end_pass(x, y);
        }
    });
    tot.accumulate_s += since(t_stage);
    masks.rebuild(cost);
    stats.passes = iter + 1;

    uint64_t rays = 0;
    for (const EyeCounters& c : eye_counters) rays += c.rays.total();
    for (const LightCounters& c : light_counters) rays += c.light_rays;
    char extra[128];
    std::snprintf(extra, sizeof extra, "  %zu backward photons  %d batches  coverage %.2f", n_bp,
                  int(emitted / photons_per_batch), coverage);
    control.after_pass(iter, rays, extra);
  }
  control.finish();
  stats.stop_reason = control.stop_reason();
  stats.mean_sampling_probability = control.mean_sampling_probability();
  stats.render_seconds = control.elapsed();
  for (const EyeCounters& c : eye_counters) tot.eye.add(c);
  for (const LightCounters& c : light_counters) tot.light.add(c);
  stats.rays = tot.eye.rays;
  stats.light_rays = tot.light.light_rays;
  stats.relative_error = film->relative_error();
  stats.details = to_json(tot, s, stats.passes, n_pixels);
  return stats;
}

}  // namespace bpm
