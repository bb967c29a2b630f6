// The floor under a light pass's ray rate: a photon loop that does only what any photon tracer
// must on this scene (draw a light by power, sample its emission, and at each hit find the point
// and normal, then bounce diffusely or stop by a Russian roulette of one half), with nothing
// stored, no materials, no guide. Its rays per second against bare Embree casting the same rays
// say how near to ray casting a light pass can come here at all: the part of bare Embree's rate a
// loop keeps when every ray waits for the hit before it, and pays for its emission and its hit
// points.
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <optional>
#include <vector>

#include "base/rng.h"
#include "base/sampling.h"
#include "integrator/counters.h"
#include "lights/light.h"
#include "scene/render_scene.h"

namespace bpm {

struct FloorRun {
  uint64_t rays = 0;
  double seconds = 0;
};

// A photon's first ray: a light drawn by power, its emission sampled (pbrt-v4's SampleLe).
inline std::optional<Ray> emitted_ray(const RenderScene& scene, const WavelengthMaterials& wm,
                                      Rng& rng) {
  float pmf = 0;
  const int li = scene.light_distribution.sample(rng.uniform(), &pmf);
  const Light& light = scene.lights[size_t(li)];
  const Vec2 u_pos{rng.uniform(), rng.uniform()}, u_dir{rng.uniform(), rng.uniform()};
  const auto le = light_sample_le(light, scene.light_shape(light), u_pos, u_dir, scene.bounds_info,
                                  wm.wl, wm.light_spectrum(li));
  if (!le) return std::nullopt;
  return Ray{length_squared(le->n_light) > 0
                 ? offset_origin(le->origin, le->n_light, le->direction, le->origin_error)
                 : le->origin,
             le->direction, kInf};
}

// Traces `photons` photons with `threads` threads; each ray is shown to `log` when given (then
// use one thread: a RayLog is not shared). The same photons and rays for any thread count.
// kChainOnly: the emissions are made before the clock starts, and a hit makes no point: the next
// ray leaves from o + t d (a little short of it) in a uniform direction back to the side it came
// from. What remains is each ray's wait for the hit before it.
template <bool kChainOnly = false>
FloorRun photon_floor(const RenderScene& scene, uint64_t photons, int threads,
                      RayObserver* log = nullptr) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  const WavelengthMaterials wm(scene, sample_wavelengths(0.5f));
  auto photon_rng = [](uint64_t k) { return Rng(stream_key(0x666c6f6f72ull, k)); };
  std::vector<std::optional<Ray>> first;
  if (kChainOnly) {
    first.resize(photons);
    tbb::parallel_for(uint64_t(0), photons, [&](uint64_t k) {
      Rng rng = photon_rng(k);
      first[k] = emitted_ray(scene, wm, rng);
    });
  }
  std::atomic<uint64_t> rays{0};
  const auto t0 = std::chrono::steady_clock::now();
  tbb::parallel_for(tbb::blocked_range<uint64_t>(0, photons, 4096), [&](const auto& range) {
    uint64_t n = 0;
    for (uint64_t k = range.begin(); k < range.end(); ++k) {
      Rng rng = photon_rng(k);
      const std::optional<Ray> start = kChainOnly ? first[k] : emitted_ray(scene, wm, rng);
      if (!start) continue;
      Ray ray = *start;
      for (int depth = 0; depth < 16; ++depth) {
        ++n;
        if (log) log->closest_hit(ray);
        Hit h;
        if (!scene.intersect(ray, &h)) break;
        if (kChainOnly) {
          if (rng.uniform() < 0.5f) break;
          Vec3 d = sample_uniform_sphere({rng.uniform(), rng.uniform()});
          if (dot(d, ray.d) > 0) d = -d;
          ray = Ray{ray.o + ray.d * (h.t * 0.999f), d, kInf};
          continue;
        }
        const SurfacePoint sp = scene.surface(ray, h);
        if (rng.uniform() < 0.5f) break;
        const Vec3 n_up = dot(sp.ng, ray.d) < 0 ? sp.ng : -sp.ng;
        const Vec3 d =
            Frame::from_z(n_up).to_world(sample_cosine_hemisphere({rng.uniform(), rng.uniform()}));
        ray = Ray{offset_origin(sp.p, n_up, d, sp.error), d, kInf};
      }
    }
    rays += n;
  });
  return {rays.load(),
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()};
}

}  // namespace bpm
