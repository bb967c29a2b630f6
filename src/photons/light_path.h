// Light paths for both photon methods: a photon leaves a light chosen in proportion to power
// (pbrt-v4's SampleLe), travels with the adjoint BSDF (importance transport: no 1/eta^2 on
// refraction, Veach's shading-normal correction) and Russian roulette on its change of power,
// and reports every diffuse surface it reaches, with the class of the path so far. bpm looks up
// backward photons there; fpm stores a forward photon.
#pragma once
#include <cmath>
#include <cstdint>

#include "base/rng.h"
#include "path/path_integrator.h"
#include "scene/render_scene.h"

namespace bpm {

// Photons per chunk: the unit of work of a light pass, and the unit whose results are combined in
// a fixed order, so that sums do not depend on the thread count.
constexpr int kPhotonsPerChunk = 1024;

// The wavelengths of iteration `it` of a photon method: drawn afresh each iteration, independently
// of everything else, so that iterations stay independent estimates (the error estimate needs it).
inline Wavelengths iteration_wavelengths(uint64_t seed, int it) {
  Rng rng(stream_key(seed ^ 0x7761766573ull, uint64_t(it), 0, 3));
  return sample_wavelengths(rng.uniform());
}

// How a photon arrived: straight from the light, through specular vertices only, or after at
// least one diffuse vertex.
enum class PhotonClass : uint8_t { kDirect, kCaustic, kIndirect };

struct LightCounters {
  uint64_t photons = 0;       // emitted
  uint64_t light_rays = 0;    // emitted and bounce rays
  uint64_t diffuse_hits = 0;  // photon hits on diffuse surfaces
  uint64_t queries = 0;       // map lookups (bpm)
  uint64_t entries = 0;       // accepted (backward photon, photon) pairs (bpm); photons stored (fpm)
  RayLog* log = nullptr;      // null except in benchmarks
  void add(const LightCounters& o) {
    photons += o.photons;
    light_rays += o.light_rays;
    diffuse_hits += o.diffuse_hits;
    queries += o.queries;
    entries += o.entries;
  }
};

// A photon at a diffuse surface: it arrived at sp along -wi with `flux` (per photon emitted,
// before dividing by their number) after `bounces` scattering events.
struct PhotonHit {
  int object;
  const SurfacePoint& sp;
  Vec3 wi;  // toward where the photon came from
  Spectrum flux;
  PhotonClass cls;
  int bounces;
};

// Traces one photon at the wavelengths of wm; calls on_hit(const PhotonHit&) at each diffuse surface. The path stops
// once a further bounce could not make a path of at most max_depth scattering events with the
// `min_eye_vertices` the estimator adds on the camera side.
template <class OnHit>
void trace_light_path(const RenderScene& scene, const WavelengthMaterials& wm, int max_depth, int min_eye_vertices,
                      Rng& rng, LightCounters& counters, OnHit&& on_hit) {
  ++counters.photons;
  if (scene.lights.empty() || max_depth < min_eye_vertices) return;
  float pmf;
  int li = scene.light_distribution.sample(rng.uniform(), &pmf);
  const Light& light = scene.lights[li];
  Vec2 u_pos{rng.uniform(), rng.uniform()}, u_dir{rng.uniform(), rng.uniform()};
  auto le = light_sample_le(light, scene.light_shape(light), u_pos, u_dir, scene.bounds_info, wm.wl);
  if (!le || le->flux.is_black() || pmf == 0) return;
  Spectrum beta = le->flux / pmf;
  bool has_surface = length_squared(le->n_light) > 0;
  Ray ray{has_surface ? offset_origin(le->origin, le->n_light, le->direction) : le->origin, le->direction, kInf};
  int bounces = 0;
  bool all_specular = true;
  // Only area lights may touch a medium (flatten.cpp): the one on the side the photon leaves to.
  int medium = -1;
  if (const auto* area = std::get_if<AreaLight>(&light))
    medium = medium_toward(scene, area->object, le->n_light, le->direction, scene.objects[size_t(area->object)].medium_outside);
  ++counters.light_rays;
  for (int guard = 0; guard < 10000; ++guard) {
    Hit hit;
    if (counters.log) counters.log->closest_hit.push_back(ray);
    if (!scene.intersect(ray, &hit)) break;
    if (!cross_medium(scene, medium, hit.t * length(ray.d), wm.wl, beta)) break;
    SurfacePoint sp = scene.surface(ray, hit);
    Material storage;
    const Material& m = wm.at(scene.objects[hit.object].material, texture_context(sp), storage);
    if (std::holds_alternative<InterfaceMaterial>(m)) {
      medium = medium_toward(scene, hit.object, sp.ng, ray.d, medium);
      ray = spawn_ray(sp, ray.d);
      ++counters.light_rays;
      continue;
    }
    Vec3 wo = -ray.d;
    if (!bsdf_is_specular(m)) {
      ++counters.diffuse_hits;
      PhotonClass cls = bounces == 0 ? PhotonClass::kDirect
                                     : (all_specular ? PhotonClass::kCaustic : PhotonClass::kIndirect);
      on_hit(PhotonHit{hit.object, sp, wo, beta, cls, bounces});
    }
    if (bounces + 1 + min_eye_vertices > max_depth) break;
    Frame frame = Frame::from_z(sp.ns);
    Vec3 wo_local = frame.to_local(wo);
    if (wo_local.z == 0) break;
    auto bs = bsdf_sample(m, wo_local, rng.uniform(), {rng.uniform(), rng.uniform()}, TransportMode::kImportance);
    if (!bs) break;
    Vec3 wi = frame.to_world(bs->wi);
    // Adjoint BSDF with shading normals (Veach 1997, 5.3): |wo.ns| |wi.ng| / (|wo.ng| |wi.ns|)
    // times the usual f |wi.ns| / pdf.
    float cos_o_g = std::fabs(dot(wo, sp.ng));
    if (cos_o_g == 0) break;
    Spectrum bnew =
        beta * bs->f * (std::fabs(wo_local.z) * std::fabs(dot(wi, sp.ng)) / (cos_o_g * bs->pdf_solid_angle));
    // Russian roulette on the change of power (pbrt-v4's SPPM photon pass).
    float q = std::fmax(0.0f, 1 - bnew.max_component() / beta.max_component());
    if (rng.uniform() < q) break;
    beta = bnew / (1 - q);
    if (beta.is_black() || !beta.is_finite()) break;
    ++bounces;
    all_specular = all_specular && bs->is_specular();
    medium = medium_toward(scene, hit.object, sp.ng, wi, medium);
    ray = spawn_ray(sp, wi);
    ++counters.light_rays;
  }
}

}  // namespace bpm
