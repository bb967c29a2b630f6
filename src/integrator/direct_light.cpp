#include "integrator/direct_light.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "base/error.h"
#include "base/sampling.h"

namespace bpm {

Spectrum shadow_transmittance(const RenderScene& scene, Vec3 origin, Vec3 target, int medium,
                              bool infinite, const Wavelengths& wl, float* pass, int certain_last) {
  // The last certain_last probabilities of getting across, held back until a later stretch in a
  // scattering medium shows that they were not among the last (a ring, oldest at `held`).
  constexpr int kHeld = 8;
  BPM_CHECK(certain_last >= 0 && certain_last <= kHeld);
  std::array<float, kHeld> ring{};
  int held = 0, count = 0;
  // A stretch of `length` along r in `in`: its transmittance; in a scattering medium its mean is
  // the probability that a free flight gets across (next_vertex's PathState::pass).
  const auto stretch = [&](int in, const Ray& r, float length) {
    const Spectrum T = medium_transmittance(scene, in, r, length, wl);
    if (!pass || !scene.media[size_t(in)].scatters()) return T;
    if (certain_last == 0) {
      *pass *= T.average();
    } else if (count < certain_last) {
      ring[size_t((held + count++) % kHeld)] = T.average();
    } else {
      *pass *= ring[size_t(held)];
      ring[size_t((held + count) % kHeld)] = T.average();
      held = (held + 1) % kHeld;
    }
    return T;
  };
  if (pass) *pass = 1;
  if (!scene.occluded(origin, target)) {
    if (medium < 0) return Spectrum(1.0f);
    const Vec3 d = target - origin;
    const float len = length(d);
    return stretch(medium, Ray{origin, d / len, kInf}, infinite ? kInf : len);
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
      if (medium >= 0) T *= stretch(medium, r, infinite ? kInf : len);
      return T;
    }
    const Object& obj = scene.objects[size_t(h.object)];
    if (!std::holds_alternative<InterfaceMaterial>(scene.materials[size_t(obj.material)]))
      return {};
    const SurfacePoint sp = scene.surface(r, h);
    if (medium >= 0) T *= stretch(medium, r, h.t);
    if (T.is_black()) return T;
    medium = medium_toward(scene, h.object, sp.ng, r.d, medium);
    o = offset_origin(sp.p, sp.ng, r.d, sp.error);
  }
  return {};
}

std::optional<LightSampleAt> sample_light_at(const RenderScene& scene, const SurfacePoint& sp,
                                             int object, int medium, const Material& m,
                                             const Frame& frame, Vec3 wo_local,
                                             const WavelengthMaterials& wm, Rng& rng,
                                             PathCounters& counters, BsdfPart part) {
  const Wavelengths& wl = wm.wl;
  if (scene.lights.empty()) return std::nullopt;
  float pmf;
  float ul = rng.uniform();
  int li = scene.light_distribution.sample(ul, &pmf);
  const Light& light = scene.lights[li];
  Vec2 u{rng.uniform(), rng.uniform()};
  auto ls = light_sample_li(light, scene.light_shape(light), sp.p, u, scene.bounds_info, wl,
                            wm.light_spectrum(li));
  if (!ls || ls->radiance.is_black() || ls->pdf_solid_angle == 0) return std::nullopt;
  Vec3 wi_local = frame.to_local(ls->wi);
  Spectrum f =
      bsdf_f(m, wo_local, wi_local, TransportMode::kRadiance, part) * std::fabs(wi_local.z);
  if (f.is_black()) return std::nullopt;
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
  float pass = 1;
  f *= shadow_transmittance(scene, origin, target,
                            medium_toward(scene, object, sp.ng, ls->wi, medium), ls->is_infinite,
                            wl, &pass);
  if (f.is_black()) return std::nullopt;
  return LightSampleAt{li, pmf, *ls, wi_local, f, pass};
}

Spectrum sample_direct_light(const RenderScene& scene, const SurfacePoint& sp, int object,
                             int medium, const Material& m, const Frame& frame, Vec3 wo_local,
                             bool use_mis, const WavelengthMaterials& wm, Rng& rng,
                             PathCounters& counters, BsdfPart part) {
  const auto s =
      sample_light_at(scene, sp, object, medium, m, frame, wo_local, wm, rng, counters, part);
  if (!s) return {};
  const LightLiSample* ls = &s->ls;
  const Spectrum& f = s->f;
  const Vec3 wi_local = s->wi_local;
  float p_light = s->pmf * ls->pdf_solid_angle;
  if (ls->is_delta || !use_mis) return ls->radiance * f / p_light;
  float p_bsdf = bsdf_pdf(m, wo_local, wi_local, TransportMode::kRadiance, part);
  return ls->radiance * f * (power_heuristic(p_light, p_bsdf) / p_light);
}

MediumAtDistance medium_at_distance(const RenderScene& scene, int medium, const Ray& unit, float t,
                                    const Wavelengths& wl, float forced_length) {
  constexpr int n = Spectrum::kChannels;
  const Medium& m = scene.media[size_t(medium)];
  const Vec3 x = unit.o + unit.d * t;
  const bool forced = forced_length >= 0;
  MediumAtDistance r;
  Spectrum sigma_t_x, whole;  // sigma_t at x; the optical depth of the whole piece (forced)
  if (m.rgb_grid) {
    const Spectrum depth = m.rgb_grid->depth(unit, 0, t, wl);
    Spectrum a;
    m.rgb_grid->coefficients(x, wl, &a, &r.sigma_s);
    sigma_t_x = a + r.sigma_s;
    for (int k = 0; k < n; ++k) r.T[k] = std::exp(-depth[k]);
    if (forced) whole = m.rgb_grid->depth(unit, 0, forced_length, wl);
  } else {
    const float density = m.density(x), tau = m.depth(unit, 0, t);
    const Spectrum sigma_s = m.sigma_s.sample(wl), sigma_t = m.sigma_a.sample(wl) + sigma_s;
    for (int k = 0; k < n; ++k) r.T[k] = std::exp(-sigma_t[k] * tau);
    r.sigma_s = sigma_s * density;
    sigma_t_x = sigma_t * density;
    if (forced) {
      const float depth = m.depth(unit, 0, forced_length);
      for (int k = 0; k < n; ++k) whole[k] = sigma_t[k] > 0 ? sigma_t[k] * depth : 0.0f;
    }
  }
  double pdf = 0;
  for (int k = 0; k < n; ++k) {
    if (!forced)
      pdf += double(sigma_t_x[k]) * r.T[k];
    else if (whole[k] > 0)
      pdf += double(sigma_t_x[k]) * r.T[k] / -std::expm1(-double(whole[k]));
    else if (std::isfinite(forced_length) && forced_length > 0)
      pdf += 1.0 / forced_length;  // no extinction on the piece: uniform over it
  }
  r.flight_pdf = float(pdf / n);
  return r;
}

float sample_forced_medium_distance(const RenderScene& scene, int medium, const Ray& unit,
                                    float length, const Wavelengths& wl, Rng& rng, float& preset_u,
                                    Spectrum& beta) {
  constexpr int n = Spectrum::kChannels;
  const Medium& m = scene.media[size_t(medium)];
  const int j = std::min(int(rng.uniform() * n), n - 1);
  const float u = flight_uniform(rng, preset_u);
  // Wavelength j's optical depth over the piece, and the depth drawn in [0, it).
  float whole, sigma_t = 0, t = -1;
  if (m.rgb_grid) {
    whole = m.rgb_grid->depth(unit, 0, length, wl)[j];
  } else {
    sigma_t = m.sigma_a.sample(wl)[j] + m.sigma_s.sample(wl)[j];
    whole = sigma_t > 0 ? sigma_t * m.depth(unit, 0, length) : 0.0f;  // kInf long: kInf
  }
  if (whole > 0) {
    const float depth = sample_truncated_exponential(u, whole);
    t = m.rgb_grid ? m.rgb_grid->distance_at_depth(unit, j, depth, length, wl)
                   : m.distance_at_depth(unit, depth / sigma_t, length);
  } else if (std::isfinite(length) && length > 0) {
    t = u * length;
  }
  if (t < 0) return -1;
  t = std::min(t, length);
  const MediumAtDistance at = medium_at_distance(scene, medium, unit, t, wl, length);
  if (!(at.flight_pdf > 0)) return -1;
  beta *= at.T * at.sigma_s / at.flight_pdf;
  return t;
}

namespace {

// Equiangular sampling of the distance t in [0, length] along a unit ray about a point: uniform in
// the angle under which the point sees the ray, so the density of t is
// h / ((theta_b - theta_a) (h^2 + (t - delta)^2)), h the point's distance from the line and delta
// the distance along the ray to its foot.
struct Equiangular {
  float delta = 0, h = 0, theta_a = 0, theta_b = 0;
  float sample(float u) const { return delta + h * std::tan(theta_a + u * (theta_b - theta_a)); }
  float pdf(float t) const {
    return h / ((theta_b - theta_a) * (h * h + (t - delta) * (t - delta)));
  }
};
// None where the point lies on the line (no density to speak of: neither strategy counts that).
std::optional<Equiangular> equiangular_about(const Ray& unit, float length, Vec3 p) {
  const Vec3 w = p - unit.o;
  Equiangular e;
  e.delta = dot(w, unit.d);
  e.h = ::bpm::length(w - unit.d * e.delta);
  if (!(e.h > 1e-6f * ::bpm::length(w))) return std::nullopt;
  e.theta_a = std::atan2(-e.delta, e.h);
  e.theta_b = std::atan2(length - e.delta, e.h);  // pi / 2 without end
  if (!(e.theta_b > e.theta_a)) return std::nullopt;
  return e;
}

// The area density with which sample_direct_light_along draws a light's point (1 for a point).
float light_point_pdf(const Light& light) {
  const auto* area = std::get_if<AreaLight>(&light);
  return area ? 1 / area->area : 1.0f;
}

}  // namespace

std::optional<LightSampleAt> sample_light_in_medium(const RenderScene& scene, const PathVertex& v,
                                                    float g, const WavelengthMaterials& wm,
                                                    Rng& rng, PathCounters& counters) {
  const Wavelengths& wl = wm.wl;
  if (scene.lights.empty()) return std::nullopt;
  float pmf;
  int li = scene.light_distribution.sample(rng.uniform(), &pmf);
  const Light& light = scene.lights[size_t(li)];
  Vec2 u{rng.uniform(), rng.uniform()};
  const Vec3 p = v.sp.p;
  auto ls = light_sample_li(light, scene.light_shape(light), p, u, scene.bounds_info, wl,
                            wm.light_spectrum(li));
  if (!ls || ls->radiance.is_black() || ls->pdf_solid_angle == 0) return std::nullopt;
  const float phase = henyey_greenstein(dot(-v.wo, ls->wi), g);
  if (!(phase > 0)) return std::nullopt;
  ++counters.shadow_rays;
  const bool has_surface = length_squared(ls->n_light) > 0;
  const Vec3 target = has_surface
                          ? offset_origin(ls->p_light, ls->n_light, -ls->wi, ls->p_light_error)
                          : ls->p_light;
  float pass = 1;
  const Spectrum f =
      shadow_transmittance(scene, p, target, v.medium, ls->is_infinite, wl, &pass) * phase;
  if (f.is_black()) return std::nullopt;
  return LightSampleAt{li, pmf, *ls, ls->wi, f, pass};
}

Spectrum sample_direct_light_in_medium(const RenderScene& scene, const PathVertex& v, float g,
                                       const WavelengthMaterials& wm, Rng& rng,
                                       PathCounters& counters) {
  const auto s = sample_light_in_medium(scene, v, g, wm, rng, counters);
  if (!s) return {};
  const Light& light = scene.lights[size_t(s->light)];
  const LightLiSample* ls = &s->ls;
  const Spectrum& f = s->f;
  const Vec3 p = v.sp.p;
  const float phase = henyey_greenstein(dot(-v.wo, ls->wi), g);
  const float pmf = s->pmf;
  const Wavelengths& wl = wm.wl;
  const float p_light = pmf * ls->pdf_solid_angle;
  float share = ls->is_delta ? 1 : power_heuristic(p_light, phase);
  // The balance heuristic against sample_direct_light_along's density of the same light path.
  const std::optional<Equiangular> eq =
      v.piece.equiangular && !ls->is_infinite
          ? equiangular_about(v.piece.ray, v.piece.length, ls->p_light)
          : std::nullopt;
  if (eq) {
    float p_area = 1;  // next-event estimation's density of the light's point
    if (!ls->is_delta)
      p_area = ls->pdf_solid_angle * absdot(ls->n_light, ls->wi) / length_squared(ls->p_light - p);
    const float p_flight = medium_at_distance(scene, v.medium, v.piece.ray, v.piece.t, wl,
                                              v.piece.forced ? v.piece.length : -1.0f)
                               .flight_pdf *
                           p_area;
    const float p_along = eq->pdf(v.piece.t) * light_point_pdf(light);
    share *= p_flight > 0 ? p_flight / (p_flight + p_along) : 0.0f;
  }
  return ls->radiance * f * (share / p_light);
}

Spectrum sample_direct_light_along(const RenderScene& scene, int medium, const Ray& ray,
                                   float length, bool forced, const WavelengthMaterials& wm,
                                   Rng& rng, PathCounters& counters) {
  const Wavelengths& wl = wm.wl;
  if (scene.lights.empty()) return {};
  float pmf;
  const int li = scene.light_distribution.sample(rng.uniform(), &pmf);
  const Light& light = scene.lights[size_t(li)];
  const Shape* shape = scene.light_shape(light);
  const Vec2 u{rng.uniform(), rng.uniform()};
  const float ut = rng.uniform();
  const std::optional<LightPoint> lp = light_sample_point(light, shape, u);
  if (!lp) return {};
  const std::optional<Equiangular> eq = equiangular_about(ray, length, lp->p);
  if (!eq) return {};
  const float t = std::clamp(eq->sample(ut), 0.0f, length);
  const Vec3 x = ray.o + ray.d * t;
  // The light arriving at x from the point: radiance per unit solid angle at x times G, the
  // solid angle per unit area of the light; next-event estimation's density of that point.
  Spectrum radiance;
  Vec3 wi, target;
  float G = 1, p_area = 1, p_solid_angle = 0;
  if (lp->is_delta) {
    const auto ls = light_sample_li(light, shape, x, u, scene.bounds_info, wl);
    if (!ls || ls->radiance.is_black()) return {};
    radiance = ls->radiance;
    wi = ls->wi;
    target = ls->p_light;
  } else {
    const Vec3 d = lp->p - x;
    const float d2 = length_squared(d);
    if (!(d2 > 0)) return {};
    wi = d / std::sqrt(d2);
    const float cos_light = absdot(lp->n, wi);
    if (cos_light == 0) return {};
    radiance = area_light_radiance(std::get<AreaLight>(light), lp->n, lp->uv, -wi, wl,
                                   wm.light_spectrum(li));
    if (radiance.is_black()) return {};
    G = cos_light / d2;
    p_solid_angle = light_pdf_li(light, shape, x, wi, lp->p, lp->n);
    p_area = p_solid_angle * G;
    target = offset_origin(lp->p, lp->n, -wi, lp->error);
  }
  const float g = scene.media[size_t(medium)].g;
  const float phase = henyey_greenstein(dot(ray.d, wi), g);
  if (!(phase > 0)) return {};
  const MediumAtDistance at = medium_at_distance(scene, medium, ray, t, wl, forced ? length : -1);
  if (at.sigma_s.is_black()) return {};
  ++counters.shadow_rays;
  const Spectrum f = shadow_transmittance(scene, x, target, medium, false, wl);
  if (f.is_black()) return {};
  // Next-event estimation's share against phase sampling, split between the free flight and this
  // sample by the balance heuristic (the 1 / p of this sample folded in).
  const float share = lp->is_delta ? 1 : power_heuristic(pmf * p_solid_angle, phase);
  const float denominator = pmf * (at.flight_pdf * p_area + eq->pdf(t) * lp->pdf_area);
  if (!(denominator > 0)) return {};
  return radiance * f * at.T * at.sigma_s * (phase * G * share / denominator);
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
