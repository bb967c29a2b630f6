#include "path/path_integrator.h"

#include <cmath>

#include "base/sampling.h"

namespace bpm {

Spectrum sample_direct_light(const RenderScene& scene, const SurfacePoint& sp, int object, int medium, const Material& m,
                             const Frame& frame, Vec3 wo_local, bool use_mis, const Wavelengths& wl, Rng& rng,
                             PathCounters& counters) {
  if (scene.lights.empty()) return {};
  float pmf;
  float ul = rng.uniform();
  int li = scene.light_distribution.sample(ul, &pmf);
  const Light& light = scene.lights[li];
  Vec2 u{rng.uniform(), rng.uniform()};
  auto ls = light_sample_li(light, scene.light_shape(light), sp.p, u, scene.bounds_info, wl);
  if (!ls || ls->radiance.is_black() || ls->pdf_solid_angle == 0) return {};
  Vec3 wi_local = frame.to_local(ls->wi);
  Spectrum f = bsdf_f(m, wo_local, wi_local, TransportMode::kRadiance) * std::fabs(wi_local.z);
  if (f.is_black()) return {};
  ++counters.shadow_rays;
  Vec3 origin = offset_origin(sp.p, sp.ng, ls->wi);
  // Lights with a surface get the shadow ray's end lifted off that surface.
  bool has_surface = length_squared(ls->n_light) > 0;
  Vec3 target = has_surface ? offset_origin(ls->p_light, ls->n_light, -ls->wi) : ls->p_light;
  if (counters.log) {
    Vec3 d = target - origin;
    float len = length(d);
    counters.log->shadow.push_back(Ray{origin, d / len, len * (1 - 1e-4f)});
  }
  if (scene.occluded(origin, target)) return {};
  if (int toward = medium_toward(scene, object, sp.ng, ls->wi, medium); toward >= 0) {
    f *= medium_transmittance(scene, toward, ls->is_infinite ? kInf : length(ls->p_light - sp.p), wl);
    if (f.is_black()) return {};
  }
  float p_light = pmf * ls->pdf_solid_angle;
  if (ls->is_delta || !use_mis) return ls->radiance * f / p_light;
  float p_bsdf = bsdf_pdf(m, wo_local, wi_local, TransportMode::kRadiance);
  return ls->radiance * f * (power_heuristic(p_light, p_bsdf) / p_light);
}

Spectrum path_radiance(const RenderScene& scene, Ray ray, const PathSettings& settings, const Wavelengths& wl,
                       Rng& rng, PathCounters& counters) {
  Spectrum L, beta(1.0f);
  bool specular_bounce = false;
  float eta_scale = 1;
  float prev_pdf_bsdf = 0;
  Vec3 prev_p;
  int depth = 0;
  int medium = -1;  // the camera is in vacuum (flatten.cpp)
  ++counters.camera_rays;
  for (int guard = 0; guard < 10000; ++guard) {
    Hit hit;
    if (counters.log) counters.log->closest_hit.push_back(ray);
    if (!scene.intersect(ray, &hit)) {
      cross_medium(scene, medium, kInf, wl, beta);  // escaping through a medium
      for (int li : scene.infinite_lights) {
        const Light& light = scene.lights[size_t(li)];
        Spectrum Le = environment_radiance(light, ray.d, wl);
        if (Le.is_black()) continue;
        if (depth == 0 || specular_bounce) {
          L += beta * Le;
        } else {
          float p_l = scene.light_distribution.pmf(li) * light_pdf_li(light, nullptr, prev_p, ray.d, {}, {});
          L += beta * Le * power_heuristic(prev_pdf_bsdf, p_l);
        }
      }
      break;
    }
    if (!cross_medium(scene, medium, hit.t * length(ray.d), wl, beta)) break;
    SurfacePoint sp = scene.surface(ray, hit);
    Vec3 wo = -ray.d;
    int light_index = scene.light_of_hit(hit);
    if (light_index >= 0) {
      const AreaLight& al = std::get<AreaLight>(scene.lights[light_index]);
      Spectrum Le = area_light_radiance(al, sp.ng, sp.uv, wo, wl);
      if (!Le.is_black()) {
        if (depth == 0 || specular_bounce) {
          L += beta * Le;
        } else {
          const Light& light = scene.lights[light_index];
          float p_l = scene.light_distribution.pmf(light_index) *
                      light_pdf_li(light, scene.light_shape(light), prev_p, ray.d, sp.p, sp.ng);
          L += beta * Le * power_heuristic(prev_pdf_bsdf, p_l);
        }
      }
    }
    const Material m = material_at(scene, scene.objects[hit.object].material, wl, texture_context(sp));
    if (std::holds_alternative<InterfaceMaterial>(m)) {
      // A boundary that does not scatter: continue the same ray past it.
      medium = medium_toward(scene, hit.object, sp.ng, ray.d, medium);
      ray = spawn_ray(sp, ray.d);
      ++counters.bounce_rays;
      continue;
    }
    if (depth++ == settings.max_depth) break;
    Frame frame = Frame::from_z(sp.ns);
    Vec3 wo_local = frame.to_local(wo);
    if (wo_local.z == 0) break;
    if (!bsdf_is_specular(m))
      L += beta * sample_direct_light(scene, sp, hit.object, medium, m, frame, wo_local, true, wl, rng, counters);

    float uc = rng.uniform();
    Vec2 u{rng.uniform(), rng.uniform()};
    auto bs = bsdf_sample(m, wo_local, uc, u, TransportMode::kRadiance);
    if (!bs) break;
    beta *= bs->f * (std::fabs(bs->wi.z) / bs->pdf_solid_angle);
    specular_bounce = bs->is_specular();
    prev_pdf_bsdf = bs->mis_pdf;
    if (bs->is_transmission()) eta_scale *= bs->eta * bs->eta;
    prev_p = sp.p;
    Vec3 wi = frame.to_world(bs->wi);
    medium = medium_toward(scene, hit.object, sp.ng, wi, medium);
    ray = spawn_ray(sp, wi);
    ++counters.bounce_rays;
    if (beta.is_black()) break;
    // Russian roulette on the throughput without the radiance scaling of refraction
    // (pbrt-v4's etaScale), after the first two bounces.
    Spectrum rr_beta = beta * eta_scale;
    if (rr_beta.max_component() < 1 && depth > 1) {
      float q = std::fmax(0.0f, 1 - rr_beta.max_component());
      if (rng.uniform() < q) break;
      beta /= 1 - q;
    }
  }
  return L;
}

}  // namespace bpm
