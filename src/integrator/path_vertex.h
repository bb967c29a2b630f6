// The vertex step every path loop shares (path tracing, bpm's eye pass, fpm's eye paths and the
// light paths of both photon methods): follow the ray to the next surface that scatters,
// attenuating the throughput in absorbing media and crossing interface surfaces on the way; then,
// after the integrator has done its work at the vertex, sample the BSDF and leave.
#pragma once
#include <algorithm>
#include <cmath>
#include <optional>
#include <variant>

#include "base/error.h"
#include "base/rng.h"
#include "integrator/counters.h"
#include "scene/render_scene.h"

namespace bpm {

// A path between two vertices.
struct PathState {
  Ray ray;
  Spectrum beta{1.0f};     // throughput
  int medium = -1;         // the medium the ray travels in (-1: vacuum)
  float length = 0;        // world distance travelled, interfaces included
  bool hero_only = false;  // only the first wavelength goes on (hero_wavelength_only)
  Rng* rng = nullptr;      // draws where the ray scatters in a medium (next_vertex)
  // When in [0, 1): the uniform number of the path's first free flight in a scattering medium (or
  // of its first forced medium vertex), drawn by the caller instead of the stream (bpm stratifies
  // it over a pixel's iterations, CameraSampler::stream_uniform); taken once.
  float flight_u = -1;
  // The ray crosses scattering media as absorbing ones (exp(-sigma_t tau), no free flight): the
  // caller draws the points where it scatters itself, along the pieces that in_medium reports
  // (bpm's forced medium vertices, bpm/eye_pass.cpp).
  bool cross_media = false;
  // Set by next_vertex: the probability that its free flights got across the scattering media
  // between the ray's origin and the vertex it reached (the mean over the wavelengths of each
  // piece's transmittance, up to a medium vertex on the last; 1 where none was crossed). The
  // combined estimators' weights divide next-event estimation's density by it
  // (photons/merge_weights.h).
  float pass = 1;
};

// The piece of a ray through a scattering medium on which a medium vertex was drawn: from ray.o
// along the unit ray.d, `length` long (kInf: without end), the vertex at distance t;
// `equiangular`: the path also sampled direct light along the piece (direct_light.h); `forced`:
// t was drawn on the piece whatever the path did past it (sample_forced_medium_distance), not by
// a free flight.
struct MediumPiece {
  Ray ray;
  float length = 0;
  float t = 0;
  bool equiangular = false;
  bool forced = false;
};

// A surface where the path scatters.
struct PathVertex {
  Hit hit;
  SurfacePoint sp;
  Vec3 wo;                             // toward where the path came from
  int material_index = -1;             // the object's material in RenderScene::materials
  const Material* material = nullptr;  // resolved at sp (textures, mixes) at the path's wavelengths
  Material storage;                    // holds the material when it had to be resolved at sp
  Frame frame;                         // shading frame
  Vec3 wo_local;
  bool on_curve = false;  // the surface is a curve (scene/curves.h)
  // A point inside a scattering medium (StepEnd::kMedium): sp.p is the point, wo the way back,
  // `medium` the medium, `piece` where on its ray it was drawn; no surface, material or frame.
  int medium = -1;
  MediumPiece piece;
  PathVertex() = default;
  PathVertex(const PathVertex&) = delete;  // material may point into storage
  PathVertex& operator=(const PathVertex&) = delete;
  int object() const { return hit.object; }
  const Material& m() const { return *material; }
};

enum class StepEnd { kVertex, kMedium, kEscaped, kAbsorbed };

// The uniform number of a free flight: `preset` when the caller set one (PathState::flight_u),
// which is then spent, else the next of the stream.
inline float flight_uniform(Rng& rng, float& preset) {
  if (!(preset >= 0)) return rng.uniform();
  const float u = preset;
  preset = -1;
  return u;
}

// Where a ray in a scattering medium next scatters, before `distance` (kInf: none ahead), all
// measured in optical depth in density units (scene/medium.h: a homogeneous medium's is the
// distance). The distance follows one wavelength's free flight, the wavelength drawn uniformly, and
// the throughput is weighted by the mixture of all wavelengths' densities (one-sample MIS, the
// balance heuristic: chromatic media stay unbiased at every wavelength): at a scattering point
// beta *= sigma_s T(t) / p(t), past it beta *= T(distance) / P(t > distance); *pass is multiplied
// by the mean transmittance up to the point or past the piece. Returns the scattering distance,
// or a negative value when the ray gets past.
inline float sample_medium_distance(const Spectrum& sigma_t, const Spectrum& sigma_s,
                                    float distance, Rng& rng, float& preset_u, Spectrum& beta,
                                    float& pass) {
  constexpr int n = Spectrum::kChannels;
  const int j = std::min(int(rng.uniform() * n), n - 1);
  const float u = flight_uniform(rng, preset_u);
  const float t = sigma_t[j] > 0 ? -std::log1p(-u) / sigma_t[j] : kInf;
  if (t < distance) {
    double p = 0, T = 0;
    for (int k = 0; k < n; ++k) {
      const double e = std::exp(-double(sigma_t[k]) * t);
      p += sigma_t[k] * e;
      T += e;
    }
    p /= n;
    pass *= float(T / n);
    for (int k = 0; k < n; ++k)
      beta[k] *= float(sigma_s[k] * std::exp(-double(sigma_t[k]) * t) / p);
    return t;
  }
  double P = 0;
  Spectrum T;
  for (int k = 0; k < n; ++k) {
    T[k] = sigma_t[k] > 0 ? float(std::exp(-double(sigma_t[k]) * distance)) : 1.0f;
    P += T[k];
  }
  P /= n;
  pass *= float(P);
  for (int k = 0; k < n; ++k) beta[k] *= float(T[k] / P);
  return -1;
}

// sample_medium_distance in an rgbgrid, whose sigma_t varies with the wavelength from point to
// point: wavelength j's free flight drawn in its own optical depth, every wavelength weighted by
// the mixture of their densities sigma_t(x) T(t); *pass as sample_medium_distance's. Returns the
// distance, or negative past it.
inline float sample_rgb_grid_flight(const RgbGrid& g, const Ray& unit, float distance,
                                    const Wavelengths& wl, Rng& rng, float& preset_u,
                                    Spectrum& beta, float& pass) {
  constexpr int n = Spectrum::kChannels;
  const int j = std::min(int(rng.uniform() * n), n - 1);
  const float tau = -std::log1p(-flight_uniform(rng, preset_u));
  Spectrum depth;  // up to the point drawn, or the whole way
  const float t = g.flight(unit, j, tau, distance, wl, &depth);
  if (t >= 0) {
    Spectrum a, s;
    g.coefficients(unit.o + unit.d * t, wl, &a, &s);
    double p = 0, T = 0;
    for (int k = 0; k < n; ++k) {
      const double e = std::exp(-double(depth[k]));
      p += (a[k] + s[k]) * e;
      T += e;
    }
    p /= n;
    pass *= float(T / n);
    for (int k = 0; k < n; ++k)
      beta[k] = p > 0 ? float(beta[k] * s[k] * std::exp(-double(depth[k])) / p) : 0.0f;
    return t;
  }
  double P = 0;
  Spectrum T;
  for (int k = 0; k < n; ++k) {
    T[k] = float(std::exp(-double(depth[k])));
    P += T[k];
  }
  P /= n;
  pass *= float(P);
  for (int k = 0; k < n; ++k) beta[k] = P > 0 ? float(beta[k] * T[k] / P) : 0.0f;
  return -1;
}

// What a path reports of the pieces of its rays that cross a scattering medium: none.
struct NoMediumPieces {
  void operator()(const Ray&, float, const Spectrum&) const {}
};

// Follows s.ray to the next scattering surface or medium point and fills v. on_surface(hit, sp) is
// called at every surface reached, interfaces included, with s.beta already attenuated up to it
// (emission is counted there); in_medium(ray, distance, beta) for every piece of the ray inside a
// scattering or glowing medium before the point where it scatters is drawn: the whole piece up to
// the next surface (distance along the unit direction, kInf where the ray leaves the scene) with
// the throughput at its start (photon beams, bpm/light_pass.h). kEscaped: the ray left the scene
// (s.ray is the escaping ray, s.beta attenuated by the medium it leaves in); kAbsorbed: nothing is
// left of the throughput. Each crossing of an interface counts one ray in continuation_rays.
template <class OnSurface, class InMedium = NoMediumPieces>
StepEnd next_vertex(const RenderScene& scene, const WavelengthMaterials& materials, PathState& s,
                    PathVertex& v, uint64_t& continuation_rays, RayObserver* observer,
                    OnSurface&& on_surface, InMedium&& in_medium = {}) {
  const Wavelengths& wl = materials.wl;
  s.pass = 1;
  for (int guard = 0; guard < 10000; ++guard) {
    if (observer) observer->closest_hit(s.ray);
    v.hit = Hit();
    const bool hit = scene.intersect(s.ray, &v.hit);
    const float distance = hit ? v.hit.t * length(s.ray.d) : kInf;
    const bool scatters = s.medium >= 0 && scene.media[size_t(s.medium)].scatters();
    if (scatters && !s.cross_media) {
      BPM_CHECK(s.rng);  // set by every path that may meet a scattering medium
      const Medium& m = scene.media[size_t(s.medium)];
      const Ray unit{s.ray.o, normalize(s.ray.d), kInf};
      in_medium(unit, distance, s.beta);
      float t = -1;
      if (m.rgb_grid) {
        t = sample_rgb_grid_flight(*m.rgb_grid, unit, distance, wl, *s.rng, s.flight_u, s.beta,
                                   s.pass);
      } else {
        // The free flight in optical depth (density units), then as a distance (scene/medium.h).
        const Spectrum sigma_s = m.sigma_s.sample(wl), sigma_t = m.sigma_a.sample(wl) + sigma_s;
        const float tau = sample_medium_distance(sigma_t, sigma_s, m.depth(unit, 0, distance),
                                                 *s.rng, s.flight_u, s.beta, s.pass);
        if (tau >= 0) t = m.distance_at_depth(unit, tau, distance);
      }
      if (t >= 0) {
        s.length += t;
        v.medium = s.medium;
        v.material = nullptr;
        v.sp = SurfacePoint{};
        v.sp.p = s.ray.o + normalize(s.ray.d) * t;
        v.wo = -normalize(s.ray.d);
        v.piece = MediumPiece{unit, distance, t, false};
        return s.beta.is_black() ? StepEnd::kAbsorbed : StepEnd::kMedium;
      }
      if (s.beta.is_black()) return StepEnd::kAbsorbed;
      if (!hit) return StepEnd::kEscaped;
    } else {
      const Ray unit{s.ray.o, normalize(s.ray.d), kInf};
      if (scatters || (s.medium >= 0 && scene.media[size_t(s.medium)].emits()))
        in_medium(unit, distance, s.beta);
      if (!hit) {
        cross_medium(scene, s.medium, unit, kInf, wl, s.beta);
        return StepEnd::kEscaped;
      }
      if (!cross_medium(scene, s.medium, unit, distance, wl, s.beta)) return StepEnd::kAbsorbed;
    }
    s.length += distance;
    v.sp = scene.surface(s.ray, v.hit);
    on_surface(v.hit, v.sp);
    v.material_index = scene.objects[size_t(v.hit.object)].material;
    v.on_curve = std::holds_alternative<Curves>(scene.objects[size_t(v.hit.object)].shape);
    v.material = &materials.at(v.material_index, texture_context(v.sp), v.storage);
    if (std::holds_alternative<InterfaceMaterial>(*v.material)) {
      // A boundary that does not scatter: the same ray goes on past it.
      s.medium = medium_toward(scene, v.hit.object, v.sp.ng, s.ray.d, s.medium);
      s.ray = spawn_ray(v.sp, s.ray.d);
      ++continuation_rays;
      continue;
    }
    v.medium = -1;
    v.wo = -s.ray.d;
    v.frame = Frame::from_z(v.sp.ns);
    v.wo_local = v.frame.to_local(v.wo);
    return StepEnd::kVertex;
  }
  return StepEnd::kAbsorbed;
}

inline StepEnd next_vertex(const RenderScene& scene, const WavelengthMaterials& materials,
                           PathState& s, PathVertex& v, uint64_t& continuation_rays,
                           RayObserver* observer) {
  return next_vertex(scene, materials, s, v, continuation_rays, observer,
                     [](const Hit&, const SurfacePoint&) {});
}

// Samples the BSDF at v. The caller draws uc and u, in an order of its own that is fixed in the
// code (argument evaluation order is not), so that the image does not depend on the compiler.
inline std::optional<BsdfSample> sample_bsdf(const PathVertex& v, float uc, Vec2 u,
                                             TransportMode mode, BsdfPart part = BsdfPart::kAll) {
  return bsdf_sample(v.m(), v.wo_local, uc, u, mode, part);
}

// What a photon method's eye path does at a vertex (BsdfPart): gather there (a diffuse vertex:
// next-event estimation and photon estimates with the gathered lobes), or go on through it as
// through a specular vertex, with the traced lobes; `part` is what it then samples and evaluates.
// Whether the photon methods go through v whatever lobe they sample there: every lobe of its
// material is traced, or v lies on a curve, whose ribbons face each ray that meets them and so
// offer no surface on which a photon and a gathering point could meet. Light paths then neither
// leave photons there nor end a caustic there.
inline bool vertex_all_traced(const PathVertex& v) { return v.on_curve || bsdf_all_traced(v.m()); }

// A material with both parts is traced with probability p (bsdf_traced_part_probability) and
// gathered otherwise, beta divided by p or 1 - p: each light path through it is counted by one of
// the two choices, with the lobe that carries it.
struct EyeVertexChoice {
  bool gather;
  BsdfPart part;
};
inline EyeVertexChoice choose_eye_vertex(const PathVertex& v, Rng& rng, PathState& s) {
  if (vertex_all_traced(v)) return {false, BsdfPart::kAll};
  const float p = bsdf_traced_part_probability(v.m(), v.wo_local);
  if (p == 0) return {true, BsdfPart::kAll};
  if (rng.uniform() < p) {
    s.beta /= p;
    return {false, BsdfPart::kTraced};
  }
  s.beta /= 1 - p;
  return {true, BsdfPart::kGathered};
}

// At a dispersive surface the path goes on at its hero wavelength alone (once: the scaling of
// hero_wavelength_only applies to the whole path).
inline void keep_hero_wavelength_at(const PathVertex& v, PathState& s) {
  if (s.hero_only || !material_is_dispersive(v.m())) return;
  s.beta = hero_wavelength_only(s.beta);
  s.hero_only = true;
}

// Two half paths that meet (a photon and a gathering point) each scaled the hero by the number of
// wavelengths when they kept it alone; the full path must be scaled once.
inline float hero_join_factor(bool eye_hero_only, bool light_hero_only) {
  return eye_hero_only && light_hero_only ? 1.0f / Spectrum::kChannels : 1.0f;
}

// Leaves v toward wi (world): the medium on that side, and a ray lifted off the surface.
inline void leave_vertex(const RenderScene& scene, const PathVertex& v, Vec3 wi, PathState& s) {
  s.medium = medium_toward(scene, v.hit.object, v.sp.ng, wi, s.medium);
  s.ray = spawn_ray(v.sp, wi);
}

}  // namespace bpm
