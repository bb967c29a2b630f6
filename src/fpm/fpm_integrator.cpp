#include "fpm/fpm_integrator.h"

#include <tbb/blocked_range.h>
#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>

#include "base/error.h"
#include "bpm/sphere_kdtree.h"
#include "camera/camera.h"
#include "render/control.h"
#include "photons/density.h"
#include "photons/light_path.h"

namespace bpm {
namespace {


constexpr uint64_t kPhotonStream = 0x66706d70686f74ull;

struct ForwardPhoton {
  Vec3 p;
  Vec3 wi;  // toward where the photon came from
  Vec3 ng;
  Spectrum flux;
  uint16_t bounces;
  PhotonClass cls;
};

struct PhotonMap {
  std::vector<ForwardPhoton> photons;
  CentreKdTree tree;
  void build() {
    std::vector<SphereRef> points(photons.size());
    for (size_t i = 0; i < photons.size(); ++i) points[i] = {photons[i].p, 0};
    tree.build(points);
  }
  size_t photon_bytes() const { return photons.size() * sizeof(ForwardPhoton); }
};

struct EyeParams {
  const WavelengthMaterials* materials;
  const FpmSettings* fpm;
  int max_depth;
  float normal_cos;
  float radius_per_length0, radius_per_length1;
  double emitted;
};

struct EyeCounters {
  PathCounters rays;
  uint64_t lookups = 0, photons_used = 0;
  void add(const EyeCounters& o) {
    rays.add(o.rays);
    lookups += o.lookups;
    photons_used += o.photons_used;
  }
};

// Radiance reflected at sp toward wo from the map's photons of the accepted classes, eq. (2):
// sum f dPhi / (pi r^2 N). With knn > 0 the radius is the distance to the knn-th nearest
// photon within `radius` (Jensen's estimate), else `radius`.
template <class Accept>
Spectrum estimate(const PhotonMap& map, const Material& m, const SurfacePoint& sp, Vec3 wo,
                  float radius, int eye_depth, const EyeParams& prm, Accept&& accept, EyeCounters& c) {
  ++c.lookups;
  auto usable = [&](const ForwardPhoton& ph) {
    return accept(ph.cls) && eye_depth + int(ph.bounces) <= prm.max_depth && dot(ph.ng, sp.ng) >= prm.normal_cos;
  };
  float r = radius;
  if (prm.fpm->knn > 0) {
    std::vector<float> d2;
    map.tree.query_within(sp.p, radius, [&](uint32_t i) {
      if (usable(map.photons[i])) d2.push_back(length_squared(map.photons[i].p - sp.p));
    });
    if (int(d2.size()) > prm.fpm->knn) {
      std::nth_element(d2.begin(), d2.begin() + prm.fpm->knn - 1, d2.end());
      r = std::sqrt(d2[prm.fpm->knn - 1]) * 1.0001f;
    }
  }
  Spectrum sum;
  map.tree.query_within(sp.p, r, [&](uint32_t i) {
    const ForwardPhoton& ph = map.photons[i];
    if (!usable(ph)) return;
    ++c.photons_used;
    sum += photon_contribution(m, sp.ng, sp.ns, wo, ph.wi, ph.flux);
  });
  return sum * float(1.0 / (kPi * double(r) * r * prm.emitted));
}

// One eye path to its first diffuse vertex (and, with final gathering, one more).
Spectrum eye_radiance(const RenderScene& scene, const PhotonMap& global, const PhotonMap& caustic,
                      const EyeParams& prm, Ray ray, Rng& rng, EyeCounters& c) {
  const Wavelengths& wl = prm.materials->wl;
  Spectrum L, beta(1.0f);
  int depth = 0;
  float length = 0;
  bool gathering = false;  // between x1 and x2 on a final-gather ray
  int medium = -1;         // the camera is in vacuum (flatten.cpp)
  ++c.rays.camera_rays;
  for (int guard = 0; guard < 10000; ++guard) {
    Hit hit;
    if (!scene.intersect(ray, &hit)) {
      cross_medium(scene, medium, kInf, wl, beta);  // escaping through a medium
      if (!gathering)
        for (int li : scene.infinite_lights)
          L += beta * environment_radiance(scene.lights[size_t(li)], ray.d, wl);
      break;
    }
    length += hit.t * bpm::length(ray.d);
    if (!cross_medium(scene, medium, hit.t * bpm::length(ray.d), wl, beta)) break;
    SurfacePoint sp = scene.surface(ray, hit);
    Vec3 wo = -ray.d;
    int light_index = scene.light_of_hit(hit);
    if (light_index >= 0 && !gathering)
      L += beta * area_light_radiance(std::get<AreaLight>(scene.lights[light_index]), sp.ng, sp.uv, wo, wl);
    Material storage;
    const Material& m = prm.materials->at(scene.objects[hit.object].material, texture_context(sp), storage);
    if (std::holds_alternative<InterfaceMaterial>(m)) {
      medium = medium_toward(scene, hit.object, sp.ng, ray.d, medium);
      ray = spawn_ray(sp, ray.d);
      ++c.rays.bounce_rays;
      continue;
    }
    if (depth++ == prm.max_depth) break;
    Frame frame = Frame::from_z(sp.ns);
    Vec3 wo_local = frame.to_local(wo);
    if (wo_local.z == 0) break;
    if (!bsdf_is_specular(m)) {
      float r1 = length * prm.radius_per_length1;
      if (gathering) {
        // x2: everything the global map holds, direct photons included.
        L += beta * estimate(global, m, sp, wo, r1, depth, prm, [](PhotonClass) { return true; }, c);
        break;
      }
      // x1: direct light by next-event estimation (BSDF samples that find an emitter are never
      // counted), caustics from the caustic map.
      L += beta * sample_direct_light(scene, sp, hit.object, medium, m, frame, wo_local, false, wl, rng, c.rays);
      L += beta * estimate(caustic, m, sp, wo, length * prm.radius_per_length0, depth, prm,
                           [](PhotonClass k) { return k == PhotonClass::kCaustic; }, c);
      if (!prm.fpm->final_gather) {
        L += beta * estimate(global, m, sp, wo, r1, depth, prm,
                             [](PhotonClass k) { return k == PhotonClass::kIndirect; }, c);
        break;
      }
      gathering = true;
    }
    auto bs = bsdf_sample(m, wo_local, rng.uniform(), {rng.uniform(), rng.uniform()}, TransportMode::kRadiance);
    if (!bs) break;
    beta *= bs->f * (std::fabs(bs->wi.z) / bs->pdf_solid_angle);
    if (beta.is_black()) break;
    Vec3 wi = frame.to_world(bs->wi);
    medium = medium_toward(scene, hit.object, sp.ng, wi, medium);
    ray = spawn_ray(sp, wi);
    ++c.rays.bounce_rays;
  }
  return L;
}

}  // namespace

RenderStats render_fpm(const LoadedScene& ls, const RenderOptions& opt, Film* film) {
  const BpmSettings& s = opt.bpm;  // radii, their policy and photons per iteration are shared
  const FpmSettings& fs_ = opt.fpm;
  if (!(s.k0 > 0) || !(s.k1 > 0)) throw Error("fpm: radius factors k0 and k1 must be positive");
  if (s.photons_per_batch <= 0) throw Error("fpm: photons per iteration must be positive");
  if (fs_.knn < 0) throw Error("fpm: knn must not be negative");
  std::unique_ptr<tbb::global_control> limit;
  if (opt.threads > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, opt.threads);
  const int w = film->width(), h = film->height();
  const RenderScene& scene = ls.scene;
  PerspectiveCamera camera(ls.camera, w, h);
  Filter filter(ls.filter);
  const float pixel_angle = std::sqrt(camera.pixel_solid_angle());
  const float max_value = ls.film.max_component_value;
  const uint64_t n_photons = uint64_t(s.photons_per_batch);
  const int n_chunks = int((n_photons + kPhotonsPerChunk - 1) / kPhotonsPerChunk);
  const int min_eye_vertices = fs_.final_gather ? 2 : 1;

  struct Chunk {
    std::vector<ForwardPhoton> global, caustic;
  };
  std::vector<Chunk> chunks(n_chunks);
  PhotonMap global, caustic;
  tbb::enumerable_thread_specific<LightCounters> light_counters;
  tbb::enumerable_thread_specific<EyeCounters> eye_counters;
  RenderStats stats;
  double light_s = 0, build_s = 0, eye_s = 0;
  uint64_t stored = 0, stored_caustic = 0;
  size_t peak_map_bytes = 0, peak_tree_bytes = 0;

  RenderControl control(opt, *film, "iteration");
  for (int iter = 0; control.keep_going(iter); ++iter) {
    const int it = opt.first_iteration + iter;  // the index random streams and radii follow
    // ---- 1. light pass: a forward photon at every diffuse hit ----
    auto t_stage = Clock::now();
    // One set of wavelengths for every eye and light path of the iteration.
    const WavelengthMaterials wm(scene, iteration_wavelengths(opt.seed, it));
    tbb::parallel_for(tbb::blocked_range<int>(0, n_chunks, 1), [&](const tbb::blocked_range<int>& r) {
      LightCounters& lc = light_counters.local();
      for (int c = r.begin(); c < r.end(); ++c) {
        Chunk& ch = chunks[c];
        ch.global.clear();
        ch.caustic.clear();
        uint64_t first = uint64_t(c) * kPhotonsPerChunk, last = std::min(first + kPhotonsPerChunk, n_photons);
        for (uint64_t k = first; k < last; ++k) {
          Rng rng(stream_key(opt.seed ^ kPhotonStream, uint64_t(it), k, 2));
          trace_light_path(scene, wm, opt.max_depth, min_eye_vertices, rng, lc, [&](const PhotonHit& hit) {
            if (hit.bounces + min_eye_vertices > opt.max_depth) return;
            ForwardPhoton ph{hit.sp.p, hit.wi, hit.sp.ng, hit.flux, uint16_t(hit.bounces), hit.cls};
            ch.global.push_back(ph);
            if (hit.cls == PhotonClass::kCaustic) ch.caustic.push_back(ph);
            ++lc.entries;
          });
        }
      }
    });
    light_s += since(t_stage);

    // ---- 2. the maps, in chunk order (the same for any thread count), and their trees ----
    t_stage = Clock::now();
    global.photons.clear();
    caustic.photons.clear();
    for (const Chunk& ch : chunks) {
      global.photons.insert(global.photons.end(), ch.global.begin(), ch.global.end());
      caustic.photons.insert(caustic.photons.end(), ch.caustic.begin(), ch.caustic.end());
    }
    stored += global.photons.size();  // every photon once; the caustic map holds copies of some
    stored_caustic += caustic.photons.size();
    tbb::parallel_invoke([&] { global.build(); }, [&] { caustic.build(); });
    build_s += since(t_stage);
    peak_map_bytes = std::max(peak_map_bytes, global.photon_bytes() + caustic.photon_bytes());
    peak_tree_bytes = std::max(peak_tree_bytes, global.tree.bytes() + caustic.tree.bytes());

    // ---- 3. eye pass ----
    t_stage = Clock::now();
    float scale = radius_scale(s, it);
    EyeParams ep{&wm, &fs_, opt.max_depth, s.normal_cos, s.k0 * pixel_angle * scale, s.k1 * pixel_angle * scale,
                 double(n_photons)};
    tbb::parallel_for(tbb::blocked_range2d<int>(0, h, 16, 0, w, 16), [&](const tbb::blocked_range2d<int>& r) {
      EyeCounters& ec = eye_counters.local();
      for (int y = r.rows().begin(); y < r.rows().end(); ++y)
        for (int x = r.cols().begin(); x < r.cols().end(); ++x) {
          if (!control.sample_pixel(iter, uint32_t(y) * w + x)) continue;
          Rng rng(stream_key(opt.seed, uint64_t(it), uint64_t(y) * w + x));
          FilterSample fsm = filter.sample({rng.uniform(), rng.uniform()});
          Ray ray = camera.generate_ray({x + 0.5f + fsm.offset.x, y + 0.5f + fsm.offset.y}, {rng.uniform(), rng.uniform()});
          Spectrum L = eye_radiance(scene, global, caustic, ep, ray, rng, ec);
          film->add_sample(x, y, film_rgb(L, wm.wl, max_value), fsm.weight);
          film->end_pass(x, y);
        }
    });
    eye_s += since(t_stage);
    stats.passes = iter + 1;
    uint64_t rays = 0;
    for (const EyeCounters& c : eye_counters) rays += c.rays.total();
    for (const LightCounters& c : light_counters) rays += c.light_rays;
    char extra[64];
    std::snprintf(extra, sizeof extra, "  %zu photons stored", global.photons.size());
    control.after_pass(iter, rays, extra);
  }
  control.finish();
  stats.stop_reason = control.stop_reason();
  stats.mean_sampling_probability = control.mean_sampling_probability();
  stats.render_seconds = control.elapsed();
  LightCounters lt;
  for (const LightCounters& c : light_counters) lt.add(c);
  EyeCounters et;
  for (const EyeCounters& c : eye_counters) et.add(c);
  stats.rays = et.rays;
  stats.light_rays = lt.light_rays;
  stats.relative_error = film->relative_error();
  stats.details = {
      {"settings",
       {{"k0", s.k0},
        {"k1", s.k1},
        {"radius_policy", to_string(s.radius_policy)},
        {"alpha", s.alpha},
        {"photons_per_iteration", s.photons_per_batch},
        {"final_gather", fs_.final_gather},
        {"knn", fs_.knn},
        {"normal_cos", s.normal_cos}}},
      {"light",
       {{"photons", lt.photons},
        {"light_rays", lt.light_rays},
        {"diffuse_hits", lt.diffuse_hits},
        {"photons_stored", stored},
        {"caustic_photons_stored", stored_caustic},
        // The paper's Table 1 counts per ray traced from a light with all its continuations (a
        // photon path); per segment counts every emitted and bounce ray.
        {"photons_per_forward_ray", lt.photons ? double(stored) / double(lt.photons) : 0.0},
        {"photons_per_forward_segment", lt.light_rays ? double(stored) / double(lt.light_rays) : 0.0},
        {"rays_per_second", light_s > 0 ? double(lt.light_rays) / light_s : 0.0}}},
      {"maps",
       {{"peak_photon_bytes", peak_map_bytes},
        {"peak_tree_bytes", peak_tree_bytes},
        {"forward_photon_bytes_each", sizeof(ForwardPhoton)},
        {"tree_build_s", build_s}}},
      {"eye",
       {{"camera_rays", et.rays.camera_rays},
        {"bounce_rays", et.rays.bounce_rays},
        {"shadow_rays", et.rays.shadow_rays},
        {"lookups", et.lookups},
        {"photons_used", et.photons_used},
        {"rays_per_second", eye_s > 0 ? double(et.rays.total()) / eye_s : 0.0}}},
      {"stages_s", {{"light", light_s}, {"tree_build", build_s}, {"eye", eye_s}}},
  };
  return stats;
}

}  // namespace bpm
