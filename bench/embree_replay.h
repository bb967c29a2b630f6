// Bare Embree casting recorded rays: the yardstick the integrators' ray rates are compared with.
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <vector>

#include "integrator/counters.h"
#include "scene/render_scene.h"

namespace bpm {

// Every ray a path traces, kept for replaying through bare Embree.
struct RayLog : RayObserver {
  std::vector<Ray> closest_rays;  // camera, bounce and light rays
  std::vector<Ray> shadow_rays;   // shadow rays (t_max is the segment length)
  void closest_hit(const Ray& r) override { closest_rays.push_back(r); }
  void shadow(const Ray& r) override { shadow_rays.push_back(r); }
};

// Casts every recorded ray (closest hit, then shadow rays) with `threads` threads; returns rays
// per second.
inline double embree_replay(const RenderScene& scene, const RayLog& log, int threads) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  auto t0 = std::chrono::steady_clock::now();
  std::atomic<uint64_t> sink{0};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, log.closest_rays.size(), 4096),
                    [&](const auto& r) {
                      uint64_t hits = 0;
                      Hit h;
                      for (size_t i = r.begin(); i < r.end(); ++i)
                        hits += scene.intersect(log.closest_rays[i], &h);
                      sink += hits;
                    });
  tbb::parallel_for(tbb::blocked_range<size_t>(0, log.shadow_rays.size(), 4096),
                    [&](const auto& r) {
                      uint64_t hits = 0;
                      for (size_t i = r.begin(); i < r.end(); ++i)
                        hits += scene.occluded_ray(log.shadow_rays[i]);
                      sink += hits;
                    });
  double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return double(log.closest_rays.size() + log.shadow_rays.size()) / t;
}

}  // namespace bpm
