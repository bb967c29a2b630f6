// The scene as the integrators see it: flat arrays of objects, materials and lights, plus one
// Embree 3 scene in which geometry id == object id.
#pragma once
#include <embree3/rtcore.h>

#include <memory>
#include <string>
#include <vector>

#include "base/error.h"
#include "base/ray.h"
#include "base/rng.h"
#include "base/sampling.h"
#include "lights/light.h"
#include "materials/material.h"
#include "scene/bump.h"
#include "scene/medium.h"
#include "scene/shapes.h"

namespace bpm {

struct Object {
  Shape shape;
  int material = 0;
  // Media inside and outside (the side the geometric normal points to); -1 is vacuum. A surface
  // with the same medium on both sides leaves a ray in the medium it travels in.
  int medium_inside = -1, medium_outside = -1;
  int first_light = -1;  // index of the area light of primitive 0; primitive i is first_light + i
  // pbrt-v4 "alpha": where it is below 1 a ray passes through the surface with probability
  // 1 - alpha (a cut-out where it is 0).
  FloatParam alpha{1, -1};
  bool has_alpha() const { return alpha.textured() || alpha.value < 1; }
  std::string source;  // file:line of the Shape directive, for statistics and messages
};

class Accel;

class RenderScene {
 public:
  RenderScene();
  ~RenderScene();
  RenderScene(RenderScene&&) noexcept;
  RenderScene& operator=(RenderScene&&) noexcept;

  std::vector<Object> objects;
  std::vector<MaterialDesc> materials;
  TextureSet textures;      // the nodes textured materials read
  std::vector<Bump> bumps;  // per material (or fewer: none past the end)
  std::vector<Medium> media;
  // Per light (or fewer: -1 past the end): the medium a light other than an area light sits in,
  // where its photons start (an area light's leave to the medium on their side of its surface).
  std::vector<int> light_medium;
  int medium_of_light(size_t light) const {
    return light < light_medium.size() ? light_medium[light] : -1;
  }
  bool has_emissive_media() const {
    for (const Medium& m : media)
      if (m.emits()) return true;
    return false;
  }
  // Whether a surface has the interface material (commit sets it): shadow rays then cross them.
  bool has_interfaces = false;
  // Whether any medium scatters.
  bool has_scattering_media() const {
    for (const Medium& m : media)
      if (m.scatters()) return true;
    return false;
  }
  std::vector<Light> lights;
  std::vector<int> infinite_lights;  // lights a ray that escapes the scene sees
  // Some light has an area or lies at infinity: one that a BSDF sample can find (not only points
  // and directions, which next-event estimation alone reaches).
  bool bsdf_finds_lights = false;
  Distribution1D light_distribution;  // in proportion to power
  Bounds3 bounds;
  SceneBoundsInfo bounds_info;

  // Builds the Embree scene and the light distribution; call once after filling the arrays.
  void commit();

  bool intersect(const Ray& ray, Hit* hit) const;
  // Up to kBundle rays that start close together and go alike (Embree's coherent traversal);
  // found[i] says whether ray i hit, and hits[i] where.
  static constexpr int kBundle = 8;
  void intersect_bundle(const Ray* rays, int n, Hit* hits, bool* found) const;
  // Calls visit(object, primitive) for every primitive whose bounds come within `radius` of p (a
  // superset of those that do), until it returns false.
  template <class Visit>
  void for_each_near(Vec3 p, float radius, Visit visit) const {
    visit_near(
        p, radius,
        [](void* v, int object, int primitive) {
          return (*static_cast<Visit*>(v))(object, primitive);
        },
        &visit);
  }
  using NearVisit = bool (*)(void* ctx, int object, int primitive);
  void visit_near(Vec3 p, float radius, NearVisit visit, void* ctx) const;
  // True when something blocks the open segment between a and b.
  bool occluded(Vec3 a, Vec3 b) const;
  bool occluded_ray(const Ray& ray) const;
  // False when the ray can find no emission: no environment light, and no emitting surface along
  // it (a query against the emitters alone, much cheaper than `intersect`). True does not say
  // that the emitter met is the nearest surface.
  bool may_reach_emitter(const Ray& ray) const;
  // The surface point of a hit, its shading normal bent by its material's bump or normal map.
  SurfacePoint surface(const Ray& ray, const Hit& hit) const {
    const Object& o = objects[hit.object];
    SurfacePoint sp =
        surface_point(o.shape, hit.primitive, hit.barycentric, ray.o + ray.d * hit.t, ray.d);
    if (size_t(o.material) < bumps.size() && bumps[size_t(o.material)].active())
      apply_bump(bumps[size_t(o.material)], textures,
                 surface_derivatives(o.shape, hit.primitive, sp), &sp);
    return sp;
  }
  const Shape* light_shape(const Light& l) const {
    auto* a = std::get_if<AreaLight>(&l);
    return a ? &objects[a->object].shape : nullptr;
  }
  int light_of_hit(const Hit& h) const {
    int f = objects[h.object].first_light;
    return f < 0 ? -1 : f + h.primitive;
  }

  // Embree counts.
  size_t triangle_count() const;

 private:
  std::unique_ptr<Accel> accel_;
};

inline TextureContext texture_context(const SurfacePoint& sp) { return {sp.p, sp.uv}; }

// The medium a ray leaving a surface of `object` (geometric normal ng) toward w travels in, when
// the ray that arrived was in `current`.
inline int medium_toward(const RenderScene& scene, int object, Vec3 ng, Vec3 w, int current) {
  if (object < 0) return current;  // a point on no object (an illuminance sensor)
  const Object& o = scene.objects[size_t(object)];
  if (o.medium_inside == o.medium_outside) return current;
  return dot(w, ng) > 0 ? o.medium_outside : o.medium_inside;
}

// The medium a point p stands in, as found along a ray from p toward d: the side from which the
// ray reaches the first surface ahead that separates two media, or `outer` (the camera's medium)
// where none lies ahead.
int medium_at(const RenderScene& scene, Vec3 p, Vec3 d, int outer);

// The fraction of light that crosses `distance` along the unit ray in `medium` (-1: vacuum) at
// each wavelength without being absorbed or scattered away: exp(-sigma_t tau), tau the medium's
// optical depth in density units (scene/medium.h).
inline Spectrum medium_transmittance(const RenderScene& scene, int medium, const Ray& ray,
                                     float distance, const Wavelengths& wl) {
  Spectrum t(1.0f);
  if (medium < 0) return t;
  const Medium& m = scene.media[size_t(medium)];
  if (m.rgb_grid) {
    const Spectrum tau = m.rgb_grid->depth(ray, 0, distance, wl);
    for (int i = 0; i < Spectrum::kChannels; ++i) t[i] = std::exp(-tau[i]);
    return t;
  }
  const Spectrum sigma = m.sigma_a.sample(wl) + m.sigma_s.sample(wl);
  const float tau = m.depth(ray, 0, distance);
  for (int i = 0; i < Spectrum::kChannels; ++i)
    if (sigma[i] > 0) t[i] = std::exp(-sigma[i] * tau);
  return t;
}

// The mean over the wavelengths of sigma_t (per unit length) at the point p of `medium`.
inline float medium_mean_sigma_t(const RenderScene& scene, int medium, Vec3 p,
                                 const Wavelengths& wl) {
  const Medium& m = scene.media[size_t(medium)];
  if (m.rgb_grid) {
    Spectrum a, s;
    m.rgb_grid->coefficients(p, wl, &a, &s);
    return (a + s).average();
  }
  return (m.sigma_a.sample(wl) + m.sigma_s.sample(wl)).average() * m.density(p);
}

// An rgbgrid's glow along the first `distance` of a unit ray: per wavelength i the integral of
// exp(-tau_i(t)) sigma_a_i(x) Le_i(x) dt, each wavelength with its own optical depth tau_i. One
// distance, drawn from one wavelength's exponential in its optical depth cut at the piece's end
// (uniform where that wavelength's depth is 0), the wavelength drawn uniformly, estimates it,
// weighed by the mixture of all wavelengths' densities there.
inline Spectrum rgb_grid_emission(const RgbGrid& g, const Ray& ray, float distance,
                                  const Wavelengths& wl, Rng& rng) {
  constexpr int n = Spectrum::kChannels;
  Spectrum L;
  if (!(distance > 0) || !std::isfinite(distance)) return L;
  const Spectrum whole = g.depth(ray, 0, distance, wl);
  const int j = std::min(int(rng.uniform() * n), n - 1);
  const float u = rng.uniform();
  Spectrum tau;  // every wavelength's depth up to the point drawn
  float t = u * distance;
  if (whole[j] > 0) {
    t = g.flight(ray, j, sample_truncated_exponential(u, whole[j]), distance, wl, &tau);
    if (t < 0) t = distance;  // short of the depth by rounding: tau is then the whole depth
  } else {
    tau = g.depth(ray, 0, t, wl);
  }
  const Vec3 x = ray.o + ray.d * t;
  Spectrum sigma_a, sigma_s;
  g.coefficients(x, wl, &sigma_a, &sigma_s);
  double pdf = 0;
  for (int k = 0; k < n; ++k)
    pdf += whole[k] > 0 ? double(sigma_a[k] + sigma_s[k]) * std::exp(-double(tau[k])) /
                              -std::expm1(-double(whole[k]))
                        : 1.0 / distance;
  pdf /= n;
  if (!(pdf > 0)) return L;
  const Spectrum e = g.glow(x, wl);
  for (int i = 0; i < n; ++i) L[i] = float(sigma_a[i] * e[i] * std::exp(-double(tau[i])) / pdf);
  return L;
}

// The radiance that an emitting medium sends along the unit ray toward its origin from the first
// `distance` of it, attenuated on the way: the integral of T(t) sigma_a(x) Le dt, which with
// sigma = density (sigma per unit density) and d tau = density dt is
// sigma_a Le (1 - exp(-sigma_t tau)) / sigma_t, exactly (scene/medium.h). Where a uniformgrid's
// glow varies (an Lescale grid s(x), a temperature grid), sigma_a times the integral of
// exp(-sigma_t tau) s Le(x) over tau has no closed form: one depth drawn by `rng` (the path's
// stream) estimates it.
inline Spectrum medium_emission(const RenderScene& scene, int medium, const Ray& ray,
                                float distance, const Wavelengths& wl, Rng* rng) {
  Spectrum L;
  if (medium < 0) return L;
  const Medium& m = scene.media[size_t(medium)];
  if (!m.emits()) return L;
  if (m.rgb_grid) {
    BPM_CHECK(rng);  // set by every path that may cross a glowing grid
    return rgb_grid_emission(*m.rgb_grid, ray, distance, wl, *rng);
  }
  const Spectrum sigma_a = m.sigma_a.sample(wl), sigma_t = sigma_a + m.sigma_s.sample(wl);
  const float tau = m.depth(ray, 0, distance);
  if (m.le_scale) {
    if (!(tau > 0)) return L;
    BPM_CHECK(rng);  // set by every path that may cross a glowing grid
    // A depth drawn from one wavelength's exp(-sigma_t tau) on [0, tau] (uniform where sigma_t is
    // 0), the wavelength drawn uniformly; weighed by the mixture of all wavelengths' densities.
    constexpr int n = Spectrum::kChannels;
    const int j = std::min(int(rng->uniform() * n), n - 1);
    const float u = rng->uniform();
    const float whole = sigma_t[j] * tau;
    const float at = whole > 0 ? sample_truncated_exponential(u, whole) / sigma_t[j] : u * tau;
    double pdf = 0;
    for (int k = 0; k < n; ++k)
      pdf += sigma_t[k] * tau > 0 ? double(sigma_t[k]) * std::exp(-double(sigma_t[k]) * at) /
                                        -std::expm1(-double(sigma_t[k]) * tau)
                                  : 1.0 / tau;
    pdf /= n;
    const float t = m.distance_at_depth(ray, std::min(at, tau), distance);
    const Spectrum glow = m.varying_glow(ray.o + ray.d * (t >= 0 ? t : distance), wl);
    for (int i = 0; i < n; ++i)
      L[i] = float(sigma_a[i] * glow[i] * std::exp(-double(sigma_t[i]) * at) / pdf);
    return L;
  }
  const Spectrum Le = m.Le.sample(wl);
  for (int i = 0; i < Spectrum::kChannels; ++i)
    if (sigma_t[i] > 0) L[i] = sigma_a[i] * Le[i] * -std::expm1(-sigma_t[i] * tau) / sigma_t[i];
  return L;
}

// Attenuates a path's throughput over `distance` along the unit ray in `medium`; false when
// nothing is left of it.
inline bool cross_medium(const RenderScene& scene, int medium, const Ray& ray, float distance,
                         const Wavelengths& wl, Spectrum& beta) {
  if (medium < 0) return true;
  beta *= medium_transmittance(scene, medium, ray, distance, wl);
  return !beta.is_black();
}

// Whether a ray from o along d passes through an alpha-masked surface at sp: true with
// probability 1 - alpha there, decided by a hash of the ray and the point, so that the same query
// always gets the same answer and the layers a ray crosses decide independently.
bool alpha_passes(const TextureSet& textures, const FloatParam& alpha, const SurfacePoint& sp,
                  Vec3 o, Vec3 d);

// The scene material a mix material stands for at a point (a material that is not a mix stands
// for itself): the second with probability `amount`, by a hash of the point.
int choose_mix(const RenderScene& scene, int material, const TextureContext& ctx);

// The material of a surface point at the wavelengths (resolved there, textures and mixes included).
inline Material material_at(const RenderScene& scene, int material, const Wavelengths& wl,
                            const TextureContext& ctx) {
  material = choose_mix(scene, material, ctx);
  return resolve_material(scene.materials[size_t(material)], wl, scene.textures, ctx);
}

// The scene's materials evaluated at one set of wavelengths. The photon methods use one set for
// every path of an iteration, so that eye and light paths meet at the same wavelengths. Textured
// materials are resolved per surface point instead.
struct WavelengthMaterials {
  Wavelengths wl;
  std::vector<Material> materials;
  std::vector<char> textured;
  std::vector<int> light_spectrum_index;  // per light, into light_spectra; -1: none
  std::vector<Spectrum> light_spectra;
  const RenderScene* scene;
  bool per_point = false;  // every material resolved at each point (no copies made)
  WavelengthMaterials(const RenderScene& s, const Wavelengths& wavelengths)
      : wl(wavelengths), scene(&s) {
    materials.reserve(s.materials.size());
    for (const MaterialDesc& d : s.materials) {
      textured.push_back(material_is_textured(d));
      materials.push_back(textured.back() ? Material{} : resolve_material(d, wl));
    }
    // An area light without an image emits one spectrum all over: evaluated here once, not for
    // every photon and shadow ray. The lights of one emissive mesh, one after the other, share
    // their curve and so one entry.
    light_spectrum_index.assign(s.lights.size(), -1);
    const SpectrumCurve* last = nullptr;
    for (size_t i = 0; i < s.lights.size(); ++i) {
      const auto* a = std::get_if<AreaLight>(&s.lights[i]);
      if (!a || a->image) continue;
      if (!last || !a->radiance.same_curve(*last)) {
        light_spectra.push_back(a->radiance.sample(wl));
        last = &a->radiance;
      }
      light_spectrum_index[i] = int(light_spectra.size()) - 1;
    }
  }
  // Light `light`'s emission spectrum at wl when it is the same all over the light (see
  // light_sample_le); null otherwise, and for single paths.
  const Spectrum* light_spectrum(int light) const {
    const size_t i = size_t(light);
    if (i >= light_spectrum_index.size() || light_spectrum_index[i] < 0) return nullptr;
    return &light_spectra[size_t(light_spectrum_index[i])];
  }
  // For a single path (the path tracer draws wavelengths per pixel sample): copies of every
  // material would cost more than resolving the few the path meets.
  static WavelengthMaterials resolved_per_point(const RenderScene& s,
                                                const Wavelengths& wavelengths) {
    return WavelengthMaterials(s, wavelengths, true);
  }
  // The material at a point: the iteration's copy, or for a textured one its resolution at ctx,
  // made in storage.
  const Material& at(int material, const TextureContext& ctx, Material& storage) const {
    if (!per_point && !textured[size_t(material)]) return materials[size_t(material)];
    return resolve_into(material, ctx, storage);
  }

 private:
  // at()'s slow path, out of line so that the common case inlines.
  const Material& resolve_into(int material, const TextureContext& ctx, Material& storage) const;
  WavelengthMaterials(const RenderScene& s, const Wavelengths& wavelengths, bool)
      : wl(wavelengths), scene(&s), per_point(true) {}
};

// Offsets a ray origin off the surface at p (normal n, p's error bound `error`, SurfacePoint)
// toward direction w, to avoid re-intersecting the surface it leaves. No absolute floor: a scene
// modelled in micrometres is as safe as one in metres.
inline Vec3 offset_origin(Vec3 p, Vec3 n, Vec3 w, float error) {
  const float eps = std::fmax(error, 1e-30f);
  return p + n * (dot(n, w) > 0 ? eps : -eps);
}
inline Ray spawn_ray(const SurfacePoint& sp, Vec3 w) {
  return Ray{offset_origin(sp.p, sp.ng, w, sp.error), w, kInf};
}

}  // namespace bpm
