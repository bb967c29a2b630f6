// Rays counted by kind, per thread, for the statistics every render reports; and an observer that
// benchmarks attach to see every ray a path traces.
#pragma once
#include <cstdint>

#include "base/ray.h"

namespace bpm {

// Sees every ray traced (closest-hit rays, and shadow rays with t_max the segment length);
// benchmarks replay them through bare Embree. Null in renders.
class RayObserver {
 public:
  virtual ~RayObserver() = default;
  virtual void closest_hit(const Ray& ray) = 0;
  virtual void shadow(const Ray& ray) = 0;
};

// Camera-side rays: camera rays, their continuations (bounces and crossings of interfaces; also
// the photon methods' rays from the last vertex that look for a light, direct_light_by_bsdf, when
// the query against the emitters alone did not rule them out), shadow rays, and the photon
// methods' disc probes (closest-hit rays; photons/disc_probes.h). The emitter queries themselves
// are not counted.
struct PathCounters {
  uint64_t camera_rays = 0, bounce_rays = 0, shadow_rays = 0, probe_rays = 0;
  RayObserver* observer = nullptr;
  void add(const PathCounters& o) {
    camera_rays += o.camera_rays;
    bounce_rays += o.bounce_rays;
    shadow_rays += o.shadow_rays;
    probe_rays += o.probe_rays;
  }
  uint64_t total() const { return camera_rays + bounce_rays + shadow_rays + probe_rays; }
};

}  // namespace bpm
