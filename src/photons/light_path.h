// Light paths for both photon methods: a photon leaves a light chosen in proportion to power
// (pbrt-v4's SampleLe), or where an EmissionGuide sends it, travels with the adjoint BSDF
// (importance transport: no 1/eta^2 on refraction, Veach's shading-normal correction) and Russian
// roulette on its change of power, and reports every diffuse surface it reaches, with the class of
// the path so far. bpm looks up backward photons there; fpm stores a forward photon.
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "base/rng.h"
#include "film/film.h"
#include "integrator/counters.h"
#include "integrator/path_vertex.h"
#include "photons/emission_guide.h"
#include "photons/merge_weights.h"
#include "scene/render_scene.h"

namespace bpm {

// Photons per chunk: the unit of work of a light pass, and the unit whose results are combined in
// a fixed order, so that sums do not depend on the thread count.
constexpr int kPhotonsPerChunk = 1024;

// Runs body(c) for the chunks c in [0, n) in parallel, where a stop request can cut the loop
// short: a chunk does not start once stop() is true (chunk 0 always runs: a pass or round keeps
// at least one), and the result is the number of leading chunks that ran. The caller keeps only
// those: the photons kept are then a prefix of the photon sequence, the same whichever thread ran
// which chunk, and the work of any later chunk that ran is the caller's to discard.
template <class Body, class Stop>
int run_chunks_until(int n, const Stop& stop, const Body& body) {
  std::vector<uint8_t> ran(size_t(n), 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, n, 1), [&](const tbb::blocked_range<int>& r) {
    for (int c = r.begin(); c < r.end(); ++c) {
      if (c > 0 && stop()) continue;
      body(c);
      ran[size_t(c)] = 1;
    }
  });
  int kept = 0;
  while (kept < n && ran[size_t(kept)]) ++kept;
  return kept;
}

// The wavelengths of iteration `it` of a photon method, shared by all its eye and light paths.
// Within an iteration they are stratified (sample_wavelengths): one in each of the kChannels
// strata, at the same offset v within its stratum, the first (hero) one in stratum k. Within its
// stream (it mod Film::kStreams) the t-th iteration (t = it / Film::kStreams) takes
// (v, k / kChannels) from point t of a (0,2)-sequence (van der Corput and the second Sobol
// dimension) under a random digital shift of the stream's own, so that a stream's first 2^m
// iterations place the offsets one in each 2^-m of the stratum (the spectrum is covered evenly: the
// colour converges about as 1 / iterations instead of 1 / sqrt(iterations)), and place the hero
// one in each 2^-m of the whole range (light that only the hero carries, past dispersive glass,
// converges as well). The streams' shifts are independent, so their means are independent
// estimates, whose spread is the render's error estimate (Film::set_independent_passes). For each
// iteration alone v and the hero are uniform, so every iteration is an unbiased estimate and the
// hero alone has the full density (hero_wavelength_only relies on it).
inline Wavelengths iteration_wavelengths(uint64_t seed, int it, const SpectralBuckets& film = {}) {
  const int stream = it % Film::kStreams;
  const uint32_t t = uint32_t(it / Film::kStreams);
  Rng rng(stream_key(seed ^ 0x7761766573ull, uint64_t(stream), 0, 3));
  uint32_t shift_v = rng.next_u32(), shift_k = rng.next_u32();
  double v = double(van_der_corput_bits(t) ^ shift_v) * 0x1p-32;
  double k = std::floor(double(sobol2_bits(t) ^ shift_k) * 0x1p-32 * Spectrum::kChannels);
  return film.wavelengths(float((v + k) / Spectrum::kChannels));
}

// How a photon arrived: straight from the light, through specular vertices only, or after at
// least one diffuse vertex.
enum class PhotonClass : uint8_t { kDirect, kCaustic, kIndirect };

struct LightCounters {
  uint64_t photons = 0;       // emitted
  uint64_t light_rays = 0;    // emitted and bounce rays
  uint64_t diffuse_hits = 0;  // photon hits on diffuse surfaces
  uint64_t queries = 0;       // map lookups (bpm)
  uint64_t entries = 0;  // accepted (backward photon, photon) pairs (bpm); photons stored (fpm)
  uint64_t beams = 0;    // photon beams gathered at the spheres in media (bpm)
  // Rays that tested whether a photon is cut off from a backward photon (photon_cut_off; bpm).
  uint64_t cut_off_rays = 0;
  // Shadow rays that tried to join caustic photons to the camera, and those that reached it
  // (bpm/camera_connections.h).
  uint64_t camera_rays = 0, camera_hits = 0;
  // Shadow rays that tried to join photons' vertices to eye vertices, and those that got through
  // (bpm/vertex_connections.h).
  uint64_t vertex_rays = 0, vertex_hits = 0;
  RayObserver* observer = nullptr;
  void add(const LightCounters& o) {
    photons += o.photons;
    light_rays += o.light_rays;
    diffuse_hits += o.diffuse_hits;
    queries += o.queries;
    entries += o.entries;
    beams += o.beams;
    cut_off_rays += o.cut_off_rays;
    camera_rays += o.camera_rays;
    camera_hits += o.camera_hits;
    vertex_rays += o.vertex_rays;
    vertex_hits += o.vertex_hits;
  }
};

// Whether some material of the scene's objects may have a traced lobe (materials/material.h),
// through which light could reach a diffuse surface as a caustic: all but diffuse reflection,
// diffuse transmission and interfaces (a mix counts as one that may).
inline bool may_have_caustics(const RenderScene& scene) {
  for (const Object& o : scene.objects) {
    if (o.material < 0 || size_t(o.material) >= scene.materials.size()) return true;
    const MaterialDesc& m = scene.materials[size_t(o.material)];
    if (!std::holds_alternative<DiffuseDesc>(m) &&
        !std::holds_alternative<DiffuseTransmissionDesc>(m) &&
        !std::holds_alternative<InterfaceMaterial>(m))
      return true;
  }
  return false;
}

// A photon at a diffuse surface: it arrived at sp along -wi with `flux` (per photon emitted,
// before dividing by their number) after `bounces` scattering events.
struct PhotonHit {
  int object;
  const SurfacePoint& sp;
  Vec3 wi;  // toward where the photon came from
  Spectrum flux;
  PhotonClass cls;
  int bounces;
  bool hero_only;   // the photon keeps its hero wavelength alone (PathState)
  int medium = -1;  // a point where the photon scatters in this medium (object -1, sp.p only)
  // PhotonMis::merge_factor where the light path is traced for combined estimators; else 0.
  float merge_factor = 0;
  // The photon's products (photons/merge_weights.h) where its path so far may be combined; else
  // null.
  const PhotonMis* mis = nullptr;
  int ray_medium = -1;  // the medium the photon arrived through (-1: vacuum)
};

// A straight piece of a photon's path, from ray.o along ray.d up to t_max (in units of ray.d; kInf
// where the photon leaves the scene) at a surface of geometric normal end_ng (zero when it leaves),
// with the flux it starts with in `medium` (-1: vacuum), after `bounces` scattering events. The
// illuminance sensors of the photon methods count the photons reaching them
// (photons/sensor_discs.h).
struct PhotonSegment {
  const Ray& ray;
  float t_max;
  Vec3 end_ng;
  const Spectrum& flux;
  int medium;
  PhotonClass cls;
  int bounces;
  bool hero_only;
};

// A photon's way through a scattering medium (a photon beam): from ray.o along the unit ray.d up
// to t_max (kInf where it leaves the scene), the whole way to the next surface whether or not the
// photon scatters before it, with the flux it starts with; at t the flux is flux exp(-sigma_t t)
// (long beams: Jarosz et al. 2011). bpm gathers beams at the backward photons in media.
struct PhotonBeam {
  const Ray& ray;
  float t_max;
  const Spectrum& flux;
  int medium;
  PhotonClass cls;
  int bounces;
  bool hero_only;
};

// What a photon reports of its beams: nothing.
struct NoBeams {
  void operator()(const PhotonBeam&) const {}
};

// Unguided emission: a light in proportion to power, u_pos and u_dir uniform (five numbers).
inline EmissionDraw unguided_emission(const RenderScene& scene, Rng& rng) {
  EmissionDraw e;
  if (scene.lights.empty()) return e;
  e.light = scene.light_distribution.sample(rng.uniform(), &e.light_pmf);
  e.u_pos = {rng.uniform(), rng.uniform()};
  e.u_dir = {rng.uniform(), rng.uniform()};
  return e;
}

// What a photon reports beside its hits: on_segment(const PhotonSegment&) for each straight piece
// of its path after at most `depth` scattering events (-1: none).
struct NoSegments {
  int depth = -1;
  void operator()(const PhotonSegment&) const {}
};

// The photon a light path starts with, emitted as `e` says: its ray, flux and medium. None where
// the light sends nothing.
// With `mis`, its products start there (PhotonMis::start).
inline std::optional<PathState> emit_photon(const RenderScene& scene, const WavelengthMaterials& wm,
                                            const EmissionDraw& e, Rng& rng,
                                            PhotonMis* mis = nullptr) {
  const Light& light = scene.lights[size_t(e.light)];
  auto le = light_sample_le(light, scene.light_shape(light), e.u_pos, e.u_dir, scene.bounds_info,
                            wm.wl, wm.light_spectrum(e.light));
  if (!le || le->flux.is_black()) return std::nullopt;
  if (mis) mis->start(scene, e.light, le->origin, le->n_light, le->direction);
  bool has_surface = length_squared(le->n_light) > 0;
  PathState s{
      Ray{has_surface ? offset_origin(le->origin, le->n_light, le->direction, le->origin_error)
                      : le->origin,
          le->direction, kInf},
      le->flux * (e.weight / e.light_pmf)};
  // An area light's photons leave to the medium on their side of its surface; another light's
  // start in the medium it sits in.
  if (const auto* area = std::get_if<AreaLight>(&light))
    s.medium = medium_toward(scene, area->object, le->n_light, le->direction,
                             scene.objects[size_t(area->object)].medium_outside);
  else
    s.medium = scene.medium_of_light(size_t(e.light));
  // From a light at infinity into a scattering medium, which then reaches past the scene: the
  // merges' alone (PhotonMis::stop).
  if (mis && light_is_infinite(light) && s.medium >= 0 && scene.media[size_t(s.medium)].scatters())
    mis->stop();
  s.rng = &rng;
  return s;
}

// Scatters a photon at the surface vertex v with the adjoint BSDF, Russian roulette on its change
// of power (pbrt-v4's SPPM photon pass). Returns whether the lobe sampled was traced (a caustic
// stays a caustic through it), or none where the photon ends.
// With `mis`, the photon's products follow it (PhotonMis::scatter; v is its bounces-th vertex).
inline std::optional<bool> scatter_photon_at_surface(const RenderScene& scene, const PathVertex& v,
                                                     Rng& rng, PathState& s,
                                                     PhotonMis* mis = nullptr, int k = 0) {
  if (v.wo_local.z == 0) return std::nullopt;
  keep_hero_wavelength_at(v, s);
  Vec2 u{rng.uniform(), rng.uniform()};  // drawn before uc
  float uc = rng.uniform();
  auto bs = sample_bsdf(v, uc, u, TransportMode::kImportance);
  if (!bs) return std::nullopt;
  Vec3 wi = v.frame.to_world(bs->wi);
  // Adjoint BSDF with shading normals (Veach 1997, 5.3): |wo.ns| |wi.ng| / (|wo.ng| |wi.ns|)
  // times the usual f |wi.ns| / pdf.
  float cos_o_g = std::fabs(dot(v.wo, v.sp.ng));
  if (cos_o_g == 0) return std::nullopt;
  Spectrum bnew =
      s.beta * bs->f *
      (std::fabs(v.wo_local.z) * std::fabs(dot(wi, v.sp.ng)) / (cos_o_g * bs->pdf_solid_angle));
  float q = std::fmax(0.0f, 1 - bnew.max_component() / s.beta.max_component());
  if (rng.uniform() < q) return std::nullopt;
  s.beta = bnew / (1 - q);
  if (s.beta.is_black() || !s.beta.is_finite()) return std::nullopt;
  if (mis) mis->scatter(v, *bs, wi, k);
  leave_vertex(scene, v, wi, s);
  return bs->is_traced() || v.on_curve;
}

// Scatters a photon at the medium point v: a phase-function sample (its weight is 1), Russian
// roulette on the change of power since the last vertex, beta_before (the medium's albedo).
// Returns false where the photon ends. With `mis`, its products follow it (v its k-th vertex).
inline bool scatter_photon_in_medium(const RenderScene& scene, const PathVertex& v,
                                     const Spectrum& beta_before, Rng& rng, PathState& s,
                                     PhotonMis* mis = nullptr, int k = 0) {
  const float q = std::fmax(0.0f, 1 - s.beta.max_component() / beta_before.max_component());
  if (rng.uniform() < q) return false;
  s.beta /= 1 - q;
  const Vec2 u{rng.uniform(), rng.uniform()};
  const float g = scene.media[size_t(v.medium)].g;
  const Vec3 wi = sample_henyey_greenstein(-v.wo, g, u);
  if (mis) mis->scatter_in_medium(henyey_greenstein(dot(-v.wo, wi), g), k);
  s.ray = Ray{v.sp.p, wi, kInf};
  return true;
}

// Traces one photon emitted as `e` says (unguided_emission, or an EmissionGuide's draw) at the
// wavelengths of wm; calls on_hit(const PhotonHit&) at each diffuse surface, and at each point
// where it scatters in a medium (PhotonHit::medium), where a further bounce could still make a path
// of at most max_depth scattering events with the `min_eye_vertices` the estimator adds on the
// camera side, and segments(const PhotonSegment&) for the pieces of its path that segments.depth
// asks for. The path stops when neither wants more. In a scattering medium the photon scatters
// where its free flight ends (by the phase function, a diffuse event), and on_beam(const
// PhotonBeam&) is called for each of its ways through the medium after at most the bounces of a hit
// reported. With `combine`, each hit carries its merge factor (PhotonHit::merge_factor,
// photons/merge_weights.h).
template <class OnHit, class OnSegment = NoSegments, class OnBeam = NoBeams>
void trace_light_path(const RenderScene& scene, const WavelengthMaterials& wm, int max_depth,
                      int min_eye_vertices, const EmissionDraw& e, Rng& rng,
                      LightCounters& counters, OnHit&& on_hit, OnSegment&& segments = {},
                      OnBeam&& on_beam = {}, bool combine = false) {
  ++counters.photons;
  if (scene.lights.empty() || max_depth < min_eye_vertices || e.light_pmf == 0 || e.weight == 0)
    return;
  PhotonMis mis_state;
  PhotonMis* mis = combine ? &mis_state : nullptr;
  std::optional<PathState> emitted = emit_photon(scene, wm, e, rng, mis);
  if (!emitted) return;
  PathState& s = *emitted;
  int bounces = 0;
  bool all_specular = true;
  const int hit_depth = max_depth - min_eye_vertices;  // the most bounces of a hit reported
  const int depth = std::max(hit_depth, std::min(segments.depth, max_depth));
  ++counters.light_rays;
  for (int guard = 0; guard < 10000; ++guard) {
    PathVertex v;
    const PhotonClass cls = bounces == 0
                                ? PhotonClass::kDirect
                                : (all_specular ? PhotonClass::kCaustic : PhotonClass::kIndirect);
    StepEnd end;
    const Spectrum beta_before = s.beta;
    auto beam = [&](const Ray& ray, float t_max, const Spectrum& flux) {
      if (bounces <= hit_depth)
        on_beam(PhotonBeam{ray, t_max, flux, s.medium, cls, bounces, s.hero_only});
    };
    if (bounces <= segments.depth) {
      // Each piece between the surfaces the photon passes (interfaces) with its flux at the start.
      Spectrum flux = s.beta;
      end = next_vertex(
          scene, wm, s, v, counters.light_rays, counters.observer,
          [&](const Hit& hit, const SurfacePoint& sp) {
            segments(PhotonSegment{s.ray, hit.t, sp.ng, flux, s.medium, cls, bounces, s.hero_only});
            flux = s.beta;
          },
          beam);
      if (end == StepEnd::kEscaped)
        segments(PhotonSegment{s.ray, kInf, Vec3(), flux, s.medium, cls, bounces, s.hero_only});
    } else {
      end = next_vertex(
          scene, wm, s, v, counters.light_rays, counters.observer,
          [](const Hit&, const SurfacePoint&) {}, beam);
    }
    if (end != StepEnd::kVertex && end != StepEnd::kMedium) break;
    const bool in_medium = end == StepEnd::kMedium;
    if (mis) mis->arrive(scene, v, bounces + 1, s.pass, wm.wl);
    // A surface with gathered lobes (BsdfPart), or a point in a medium: the photon's estimate
    // there sees those alone.
    if (bounces <= hit_depth && (in_medium || !vertex_all_traced(v))) {
      ++counters.diffuse_hits;
      on_hit(PhotonHit{in_medium ? -1 : v.object(), v.sp, v.wo, s.beta, cls, bounces, s.hero_only,
                       in_medium ? v.medium : -1, mis && !in_medium ? mis->merge_factor() : 0.0f,
                       mis && mis->on() && !in_medium ? mis : nullptr, s.medium});
    }
    if (bounces + 1 > depth) break;
    if (in_medium) {
      if (!scatter_photon_in_medium(scene, v, beta_before, rng, s, mis, bounces + 1)) break;
      all_specular = false;
    } else {
      const std::optional<bool> traced =
          scatter_photon_at_surface(scene, v, rng, s, mis, bounces + 1);
      if (!traced) break;
      // Through a traced lobe (delta, or glossy and sharp) a caustic stays a caustic.
      all_specular = all_specular && *traced;
    }
    ++bounces;
    ++counters.light_rays;
  }
}

}  // namespace bpm
