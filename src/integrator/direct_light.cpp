#include "integrator/direct_light.h"

#include <cmath>

#include "base/sampling.h"

namespace bpm {

Spectrum shadow_transmittance(const RenderScene& scene, Vec3 origin, Vec3 target, int medium,
                              bool infinite, const Wavelengths& wl) {
  if (!scene.occluded(origin, target)) {
    if (medium < 0) return Spectrum(1.0f);
    const Vec3 d = target - origin;
    const float len = length(d);
    return medium_transmittance(scene, medium, Ray{origin, d / len, kInf}, infinite ? kInf : len,
                                wl);
  }
  if (!scene.has_interfaces) return {};
  Spectrum T(1.0f);
  Vec3 o = origin;
  for (int guard = 0; guard < 64; ++guard) {
    const Vec3 d = target - o;
    const float len = length(d);
    if (!(len > 0)) return {};
    const Ray r{o, d / len, len * (1 - 1e-4f)};
    Hit h;
    if (!scene.intersect(r, &h)) {
      if (medium >= 0) T *= medium_transmittance(scene, medium, r, infinite ? kInf : len, wl);
      return T;
    }
    const Object& obj = scene.objects[size_t(h.object)];
    if (!std::holds_alternative<InterfaceMaterial>(scene.materials[size_t(obj.material)]))
      return {};
    const SurfacePoint sp = scene.surface(r, h);
    if (medium >= 0) T *= medium_transmittance(scene, medium, r, h.t, wl);
    if (T.is_black()) return T;
    medium = medium_toward(scene, h.object, sp.ng, r.d, medium);
    o = offset_origin(sp.p, sp.ng, r.d, sp.error);
  }
  return {};
}

Spectrum sample_direct_light(const RenderScene& scene, const SurfacePoint& sp, int object,
                             int medium, const Material& m, const Frame& frame, Vec3 wo_local,
                             bool use_mis, const WavelengthMaterials& wm, Rng& rng,
                             PathCounters& counters, BsdfPart part) {
  const Wavelengths& wl = wm.wl;
  if (scene.lights.empty()) return {};
  float pmf;
  float ul = rng.uniform();
  int li = scene.light_distribution.sample(ul, &pmf);
  const Light& light = scene.lights[li];
  Vec2 u{rng.uniform(), rng.uniform()};
  auto ls = light_sample_li(light, scene.light_shape(light), sp.p, u, scene.bounds_info, wl,
                            wm.light_spectrum(li));
  if (!ls || ls->radiance.is_black() || ls->pdf_solid_angle == 0) return {};
  Vec3 wi_local = frame.to_local(ls->wi);
  Spectrum f =
      bsdf_f(m, wo_local, wi_local, TransportMode::kRadiance, part) * std::fabs(wi_local.z);
  if (f.is_black()) return {};
  ++counters.shadow_rays;
  Vec3 origin = offset_origin(sp.p, sp.ng, ls->wi, sp.error);
  // Lights with a surface get the shadow ray's end lifted off that surface.
  bool has_surface = length_squared(ls->n_light) > 0;
  Vec3 target = has_surface ? offset_origin(ls->p_light, ls->n_light, -ls->wi, ls->p_light_error)
                            : ls->p_light;
  if (counters.observer) {
    Vec3 d = target - origin;
    float len = length(d);
    counters.observer->shadow(Ray{origin, d / len, len * (1 - 1e-4f)});
  }
  f *= shadow_transmittance(scene, origin, target,
                            medium_toward(scene, object, sp.ng, ls->wi, medium), ls->is_infinite,
                            wl);
  if (f.is_black()) return {};
  float p_light = pmf * ls->pdf_solid_angle;
  if (ls->is_delta || !use_mis) return ls->radiance * f / p_light;
  float p_bsdf = bsdf_pdf(m, wo_local, wi_local, TransportMode::kRadiance, part);
  return ls->radiance * f * (power_heuristic(p_light, p_bsdf) / p_light);
}

Spectrum sample_direct_light_in_medium(const RenderScene& scene, Vec3 p, int medium, Vec3 travel,
                                       float g, const WavelengthMaterials& wm, Rng& rng,
                                       PathCounters& counters) {
  const Wavelengths& wl = wm.wl;
  if (scene.lights.empty()) return {};
  float pmf;
  int li = scene.light_distribution.sample(rng.uniform(), &pmf);
  const Light& light = scene.lights[size_t(li)];
  Vec2 u{rng.uniform(), rng.uniform()};
  auto ls = light_sample_li(light, scene.light_shape(light), p, u, scene.bounds_info, wl,
                            wm.light_spectrum(li));
  if (!ls || ls->radiance.is_black() || ls->pdf_solid_angle == 0) return {};
  const float phase = henyey_greenstein(dot(travel, ls->wi), g);
  if (!(phase > 0)) return {};
  ++counters.shadow_rays;
  const bool has_surface = length_squared(ls->n_light) > 0;
  const Vec3 target = has_surface
                          ? offset_origin(ls->p_light, ls->n_light, -ls->wi, ls->p_light_error)
                          : ls->p_light;
  const Spectrum f = shadow_transmittance(scene, p, target, medium, ls->is_infinite, wl) * phase;
  if (f.is_black()) return {};
  const float p_light = pmf * ls->pdf_solid_angle;
  if (ls->is_delta) return ls->radiance * f / p_light;
  return ls->radiance * f * (power_heuristic(p_light, phase) / p_light);
}

Spectrum weighted_surface_emission(const RenderScene& scene, const Ray& ray, const Hit& hit,
                                   const SurfacePoint& sp, const Wavelengths& wl,
                                   const Spectrum& beta, const EmitterWeight& w) {
  int light_index = scene.light_of_hit(hit);
  if (light_index < 0 || w.kind == EmitterWeight::kNone) return {};
  const Light& light = scene.lights[size_t(light_index)];
  Spectrum Le = area_light_radiance(std::get<AreaLight>(light), sp.ng, sp.uv, -ray.d, wl);
  if (Le.is_black()) return {};
  if (w.kind == EmitterWeight::kFull) return beta * Le;
  float p_light = scene.light_distribution.pmf(light_index) *
                  light_pdf_li(light, scene.light_shape(light), w.p_prev, ray.d, sp.p, sp.ng);
  return beta * Le * power_heuristic(w.pdf_bsdf, p_light);
}

void add_environment_emission(const RenderScene& scene, const Ray& ray, const Wavelengths& wl,
                              const Spectrum& beta, const EmitterWeight& w, Spectrum& L) {
  if (w.kind == EmitterWeight::kNone) return;
  for (int li : scene.infinite_lights) {
    const Light& light = scene.lights[size_t(li)];
    Spectrum Le = environment_radiance(light, ray.d, wl);
    if (Le.is_black()) continue;
    if (w.kind == EmitterWeight::kFull) {
      L += beta * Le;
    } else {
      float p_light =
          scene.light_distribution.pmf(li) * light_pdf_li(light, nullptr, w.p_prev, ray.d, {}, {});
      L += beta * Le * power_heuristic(w.pdf_bsdf, p_light);
    }
  }
}

Spectrum direct_light_by_bsdf(const RenderScene& scene, const WavelengthMaterials& materials,
                              const PathVertex& v, PathState s, BsdfPart part, Rng& rng,
                              PathCounters& counters) {
  if (!scene.bsdf_finds_lights) return {};  // points and directions: next-event estimation's
  const float uc = rng.uniform();
  const Vec2 u{rng.uniform(), rng.uniform()};
  const auto bs = sample_bsdf(v, uc, u, TransportMode::kRadiance, part);
  if (!bs || bs->is_specular()) return {};
  s.beta *= bs->f * (std::fabs(bs->wi.z) / bs->pdf_solid_angle);
  if (s.beta.is_black()) return {};
  leave_vertex(scene, v, v.frame.to_world(bs->wi), s);
  // Most such rays meet no emitter at all; the query against the emitters alone says so cheaply.
  if (!scene.may_reach_emitter(s.ray)) return {};
  ++counters.bounce_rays;
  Spectrum L;
  PathVertex next;
  next_eye_vertex(scene, materials, s, next, counters, EmitterWeight::mis(bs->mis_pdf, v.sp.p), L);
  return L;
}

}  // namespace bpm
